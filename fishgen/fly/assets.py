"""What a fly-through shows, as binary glTF: a sky of a mode, cube files made into clouds, any glb.

* no input and a mode: a sky of that mode (``fishgen sky``'s, with the seed);
* cube files (.awn, .awa) and a mode: a sky of that mode drawn from them;
* cube files without a mode: each file one cloud as `fishgen clouds` fills it (input i with seed
  + i), side by side along +x, lit together, each its own node with its lower level;
* .glb files as they are (a sky, a fish school, anything: the page flies through it), after
  fishgen's glTF reader has checked them; .gltf files through that reader into one glb.

Several assets stand side by side along +x in the page.
"""
from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from fishgen.clouds.lighting import Lighting
from fishgen.clouds.model import DEFAULT_MAX_PARTICLES
from fishgen.errors import FishgenError, UsageError, not_a_file
from fishgen.file_names import name_text

MAX_ASSET_BYTES = 1 << 30
"""Most bytes of glb the page is handed (a browser tab holds about this much; a thick sky is 41 MB)."""
GAP = 0.25
"""Cube files stand this share of the wider one apart."""


@dataclass(frozen=True)
class Asset:
    """One binary glTF the page loads, and where it came from."""

    name: str
    data: bytes
    source: str                 # "sky", "cubes" or "glb"

    def __repr__(self) -> str:  # not the bytes
        return f"Asset({self.name!r}, {len(self.data):,} bytes, {self.source})"


CUBES = (".awn", ".awa")
GLTF = (".glb", ".gltf")


def prepare_assets(inputs: Sequence[str | os.PathLike], *, mode: str | None = None, seed: int = 0,
                   lighting: Lighting | None = None, textures_dir: str | os.PathLike | None = None,
                   max_particles: int = DEFAULT_MAX_PARTICLES) -> tuple[list[Asset], list[Path]]:
    """The page's assets for these inputs, and every file read (cube files, their textures, glbs)."""
    from fishgen.exchange.gltf import glb_bytes
    from fishgen.sky.build import build_sky

    paths = [Path(p) for p in inputs]
    for path in paths:
        if path.is_dir():
            raise FishgenError("expected a file, found a directory", path)
        if path.suffix.lower() not in CUBES + GLTF:
            raise FishgenError(f"expected a cube file (.awn, .awa) or a glTF asset (.glb, .gltf), found "
                               f"{path.suffix or 'no extension'!r}", path)
    cubes = [p for p in paths if p.suffix.lower() in CUBES]
    assets = [p for p in paths if p.suffix.lower() in GLTF]
    if mode is not None and assets:
        raise UsageError(f"expected cube files (or none) with --mode, found {assets[0]}: a glTF asset is "
                         "flown as it is")
    if mode is None and not paths:
        raise UsageError("expected INPUT... (cube files, .awa, .glb) or --mode thin|medium|thick, found "
                         "neither")
    out: list[Asset] = []
    read: list[Path] = []
    if mode is not None:
        sky = build_sky(mode, seed=seed, models=cubes, lighting=lighting, textures_dir=textures_dir,
                        max_particles=max_particles)
        out.append(Asset(f"{mode} sky", glb_bytes(sky.scene), "sky"))
        read += [*sky.models, *sky.textures]
    elif cubes:
        scene, files = cube_files_scene(cubes, seed=seed, lighting=lighting, textures_dir=textures_dir,
                                        max_particles=max_particles)
        out.append(Asset(", ".join(name_text(p.name) for p in cubes), glb_bytes(scene), "cubes"))
        read += files
    for path in assets:
        out.append(Asset(name_text(path.name), _glb(path), "glb"))   # shown on the page, as text
        read.append(path)
    return out, read


def _glb(path: Path) -> bytes:
    """A .glb's bytes as they are, once fishgen's reader has checked them; a .gltf (and its side
    files, only from its folder) read and written as one glb."""
    from fishgen.exchange.gltf import glb_bytes
    from fishgen.exchange.gltf_container import unpack
    from fishgen.exchange.gltf_reader import read_gltf

    if not path.is_file():
        raise not_a_file("an asset file", path)
    size = path.stat().st_size
    if size > MAX_ASSET_BYTES:
        raise FishgenError(f"expected at most {MAX_ASSET_BYTES >> 20} MiB of glTF to fly through, found "
                           f"{size / 2**20:.0f} MiB", path)
    data = path.read_bytes()       # read once: checked, looked into, and handed on as it is
    scene = read_gltf(path, data=data)     # refuses what is not glTF, before the page sees it
    # A valid asset may show nothing: with no `scenes` three.js has no scene to add, and a scene of
    # empty nodes gives the camera's path no point to aim at (the page failed with a stack trace).
    if not unpack(data)[0].get("scenes"):
        raise FishgenError("expected a glTF asset with a scene to show, found no scenes", path)
    if not any(prim.vertex_count for _, prim in scene.drawn()):
        raise FishgenError("expected a glTF asset whose scene draws something, found none", path)
    return data if path.suffix.lower() == ".glb" else glb_bytes(scene, path)


def cube_files_scene(paths: Sequence[Path], *, seed: int = 0, lighting: Lighting | None = None,
                     textures_dir: str | os.PathLike | None = None,
                     max_particles: int = DEFAULT_MAX_PARTICLES):
    """Each cube file one cloud (input i filled with seed + i), side by side along +x, lit together
    (clouds shadow clouds), each its own node with a lower level: the scene and the files read."""
    from fishgen.clouds.memory import check_fits
    from fishgen.clouds.pipeline import cube_clouds, read_cube_files
    from fishgen.sky.compose import Placement, SkyCloud, model_box
    from fishgen.sky.light import light_sky
    from fishgen.sky.scene import sky_scene

    files = [Path(p) for p in paths]
    models = read_cube_files(files, max_particles=max_particles, textures_dir=textures_dir,
                             raise_with="--max-particles")
    # as `fishgen sky` builds it (levels of detail, a texture cloud's billboards), refused before any
    # is filled: 40 million particles took 5 GB before the system refused the next array
    billboards = any(c.texture for m in models for c in m.cubes)
    check_fits(sum(m.total for m in models), ".glb", billboards, sky=True)
    # filled each in its own frame (no offsets) and lit as a sky: each cloud on its own shadow map
    made = cube_clouds(models, seed=seed, light=False, max_particles=max_particles)
    clouds, edge = [], None
    for i, (model, cloud, path) in enumerate(zip(made.models, made.clouds, files, strict=True)):
        lo, hi = model_box(model)
        shift = 0.0 if edge is None else edge - float(lo[0]) + GAP * float(hi[0] - lo[0])
        placement = Placement(name=path.stem, source=i, scale=(1.0, 1.0, 1.0), yaw=0.0,
                              position=(shift, 0.0, 0.0), particles=model.total, seed=seed + i)
        clouds.append(SkyCloud(placement, cloud))
        edge = shift + float(hi[0])
    lit = light_sky(clouds, lighting or Lighting())
    scene, _ = sky_scene(None, lit, [p.name for p in files])
    return scene, [*files, *made.textures]
