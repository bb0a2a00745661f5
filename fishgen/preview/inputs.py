"""Turn any preview input (species, cube file, or asset) into a ``Scene``."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from fishgen.errors import FishgenError
from fishgen.preview.scene import PointPart, Scene, srgb_to_linear

ASSETS = (".glb", ".gltf", ".obj", ".ply")
KINDS = (".txt", ".awn") + ASSETS


def load_input(path: str | Path, *, textures_dir: str | Path | None = None, seed: int = 0) -> Scene:
    """Load a species file (.txt), a cube file (.awn) or an asset (glb, gltf, obj, ply)."""
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in KINDS:
        raise FishgenError(f"expected an input ending in {', '.join(KINDS)}, found {path.name!r}")
    if not path.is_file():
        raise FishgenError("expected an existing file, found none", path)
    if ext == ".txt":
        return species_scene(path, textures_dir)
    if ext == ".awn":
        return cloud_scene(path, seed)
    if ext in (".glb", ".gltf"):
        from fishgen.preview.gltf_reader import read_gltf
        return read_gltf(path)
    from fishgen.preview.mesh_reader import read_mesh_file
    return read_mesh_file(path)


def species_scene(path: Path, textures_dir=None) -> Scene:
    """Build the fish in memory and read its GLB, so the preview shows exactly what `build` writes."""
    import fishgen
    from fishgen.exchange.gltf import glb_bytes
    from fishgen.preview.gltf_reader import read_gltf

    asset = fishgen.build_fish(fishgen.load_species(path, textures_dir=textures_dir))
    return read_gltf(data=glb_bytes(asset), label=path.stem)


def cloud_scene(path: Path, seed: int = 0) -> Scene:
    """Fill the cube file as `fishgen clouds` does; density fades the thin edges."""
    from fishgen.clouds import fill_cloud, load_cubes

    cloud = fill_cloud(load_cubes(path), seed=seed)
    rgba = np.empty((len(cloud), 4), np.float32)
    rgba[:, :3] = srgb_to_linear(cloud.colors.astype(np.float32) / 255.0)
    rgba[:, 3] = np.clip(cloud.density, 0.0, 1.0)
    return Scene(label=path.stem, points=[PointPart(cloud.centers.astype(np.float32),
                                                    cloud.radii.astype(np.float32), rgba)])
