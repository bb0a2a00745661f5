"""Turn any preview input (species file, cube file, or asset) into a scene, through the format registry."""
from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

from fishgen.errors import FishgenError, not_a_file
from fishgen.exchange.registry import formats, input_format
from fishgen.scene.model import Primitive, Scene


def input_formats():
    """Everything a preview reads: every registered format with a reader."""
    return formats(readable=True)


def load_input(path: str | os.PathLike, *, textures_dir: str | os.PathLike | None = None,
               seed: int = 0, lighting: Any = None) -> Scene:
    """Load a species file, a cube file or an asset; species and cube files are built in memory."""
    path = Path(path)
    fmt = input_format(path, kinds=input_formats(), command="preview")
    if path.is_dir():
        raise FishgenError("expected a file, found a directory", path)
    if not path.is_file():
        raise not_a_file("an input file", path)
    scene = fmt.read(path, textures_dir=textures_dir, seed=seed, lighting=lighting)
    if not any(prim.triangle_count or (prim.mode == "POINTS" and prim.vertex_count)
               for _, prim in scene.drawn()):
        # lines, empty meshes, nodes without meshes: the picture was blank, and nothing said why
        raise FishgenError("expected triangles or points to draw (a preview draws no lines), found none",
                           path)
    note = thin_particles(scene)
    if note:
        scene.note = f"{path}: {note}"
    return scene


def thin_particles(scene: Scene, most: int | None = None) -> str | None:
    """Draw at most ``most`` (``PREVIEW_PARTICLES``) of the scene's particles: a 10^7-particle PLY
    drawn whole took over 8 minutes of CPU and 4.4 GB. Each drawn point set is merged by grid cell
    as a cloud's lower level of detail is (``fishgen.clouds.lod``): fewer, wider particles that
    keep its cover, optical mass, light and colour, so the picture looks like the whole. Keeping
    every k-th particle instead let the eye through to the grey inside of a dense cloud: the thick
    sky's picture was RMS 8.5 sRGB levels off the whole one, merged 3.3 (docs/decisions.md). A set
    that moves (morph targets, a skin) keeps every k-th particle. Returns what the preview then
    says, or None."""
    from fishgen.clouds.lod import TOLERANCE
    from fishgen.clouds.pipeline import PREVIEW_PARTICLES

    most = PREVIEW_PARTICLES if most is None else most
    drawn = [prim for _, prim in scene.drawn() if prim.mode == "POINTS"]
    total = sum(prim.vertex_count for prim in drawn)
    if total <= most:
        return None
    # a few % under the cap: a merge lands within its tolerance of the count asked for
    ratio = total / most * (1 + TOLERANCE)
    step = -(-total // most)
    ids = {id(prim) for prim in drawn}
    thinned: dict[int, Primitive] = {}
    for mesh in scene.meshes:
        for k, prim in enumerate(mesh.primitives):
            if id(prim) in ids:
                if id(prim) not in thinned:
                    thinned[id(prim)] = _merged(prim, ratio) or _every(prim, step)
                mesh.primitives[k] = thinned[id(prim)]
    kept = sum(thinned[id(prim)].vertex_count for prim in drawn)
    return f"previewing its {total:,} particles as {kept:,}"


def _every(prim: Primitive, step: int) -> Primitive:
    """Every ``step``-th particle, each at its own size; copies, not views, so the whole set is let go
    (260 MB at 10^7)."""
    from dataclasses import replace

    import numpy as np

    attributes = {name: np.ascontiguousarray(values[::step]) for name, values in prim.attributes.items()}
    targets = [{name: np.ascontiguousarray(v[::step]) for name, v in t.items()} for t in prim.targets]
    return replace(prim, attributes=attributes, targets=targets)


SAMPLED = 8
"""A set is merged from at most this many times the particles it is merged into."""
MERGES = 4
"""Most merges of one set: each further one (a lower level of the one before) shrinks what it draws."""
SHRINK = 0.9
"""A further merge is kept only if it draws at most this share of the sprite area the one before did."""
APART = 16.0
"""A cell whose particles lie farther apart than this (``Merged.spread``: their positions' variance
per axis over their sprites' Gaussian sigma squared, so 4 sigmas, 1.6 radii) keeps its first
particle as it is: merged, dots that do not overlap became one wide blob over the gaps between
them. Chosen on fourteen assets and checked on three held out (docs/decisions.md): 1 left dense
point clouds of small dots unmerged (RMS 20 against 10 for 16), 4 fell between, 16 and 64 did
the same."""


def _merged(prim: Primitive, ratio: float) -> Primitive | None:
    """The set merged by grid cell into about ``vertex_count / ratio`` particles, or None for a set
    that moves. Where a cell's particles overlap they become one (as a cloud's lower level: light and
    colour are weighted means, other data its first particle's); where they lie apart its first
    particle stands for them, as every k-th would. Merged again while it draws more than every k-th
    particle would."""
    from dataclasses import replace

    import numpy as np

    from fishgen.clouds.lod import TOLERANCE, merge_particles
    from fishgen.numeric import to_linear_float
    from fishgen.preview.render import point_radii

    a = prim.attributes
    if prim.targets or "JOINTS_0" in a or "WEIGHTS_0" in a:
        return None
    tiny = np.finfo(np.float32).tiny
    radii = np.maximum(point_radii(prim), tiny)
    # past 1 a density draws stacked (the renderer's ``stacks``), so it is optical mass here too
    density = (np.ones(prim.vertex_count, np.float32) if "_DENSITY" not in a else
               np.maximum(np.nan_to_num(np.asarray(a["_DENSITY"], np.float32).ravel()), tiny))
    # what every k-th particle would draw: a CPU draws pixels, and merged particles are wider
    budget = float(np.square(radii, dtype=np.float64).sum()) / ratio
    # a huge set is merged from an even sample of it (sorting 10^7 cell keys took 6 s), each sampled
    # particle standing for k: its optical mass (density x radius^2) counted k times
    k = max(1, int(ratio // SAMPLED))
    values: dict[str, np.ndarray] = {name: v[::k] for name, v in a.items()}
    values.update(POSITION=np.asarray(a["POSITION"][::k], np.float32), _RADIUS=radii[::k],
                  _DENSITY=density[::k])
    if "COLOR_0" in values:
        values["COLOR_0"] = to_linear_float(values["COLOR_0"])
    if "_LIGHT" in values:
        values["_LIGHT"] = np.clip(np.nan_to_num(np.asarray(values["_LIGHT"], np.float32).ravel()), 0, 1)
    stands = np.full(len(values["POSITION"]), np.float32(k))
    step = ratio / k
    area = math.inf
    for merges in range(MERGES):
        merged = merge_particles(values["POSITION"], values["_RADIUS"], values["_DENSITY"] * stands,
                                 max(1.0, step))
        if merged is None:
            break
        apart = merged.spread > APART
        widths = np.where(apart, values["_RADIUS"][merged.first], merged.radii)
        drawn = float(np.square(widths, dtype=np.float64).sum())
        if merges and drawn > SHRINK * area:
            break   # points strung along a line or a sheet widen as fast as they thin: kept as they were
        area = drawn
        kept = {name: v[merged.first] for name, v in values.items()}
        made = {name: merged.mean(v).astype(np.float32) for name, v in values.items()
                if name in ("COLOR_0", "_LIGHT")}
        # its optical mass over its area, unclipped: past 1 the renderer draws it as that many stacked
        mass = merged.weight / np.square(merged.radii, dtype=np.float64)
        made.update(POSITION=merged.centers, _RADIUS=merged.radii, _DENSITY=mass.astype(np.float32))
        values = {name: np.where(apart.reshape(-1, *([1] * (v.ndim - 1))), v, made.get(name, v))
                  for name, v in kept.items()}
        stands = np.ones(len(apart), np.float32)  # what was sampled is merged or kept alone now
        # merged again, as a cloud's next lower level is, until it draws no more than the budget
        step = area / budget * (1 + TOLERANCE)
        if step <= 1 + TOLERANCE:
            break
    return replace(prim, attributes={name: np.ascontiguousarray(v) for name, v in values.items()})
