"""Turn any preview input (species file, cube file, or asset) into a scene, through the format registry."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from fishgen.errors import FishgenError
from fishgen.exchange.registry import formats, input_format
from fishgen.scene.model import Scene


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
        raise FishgenError("expected an existing file, found none", path)
    scene = fmt.read(path, textures_dir=textures_dir, seed=seed, lighting=lighting)
    note = thin_particles(scene)
    if note:
        scene.note = f"{path}: {note}"
    return scene


def thin_particles(scene: Scene, most: int | None = None) -> str | None:
    """Keep at most ``most`` (``PREVIEW_PARTICLES``) of the scene's particles, every k-th of each
    point set, as a cube file is filled with at most that many: a 10^7-particle PLY drawn whole took
    over 8 minutes of CPU and 4.4 GB. The kept ones keep their size (widened to cover as much of the
    picture, they cost as much to draw as all of them). Returns what the preview then says, or None."""
    from dataclasses import replace

    import numpy as np

    from fishgen.clouds.pipeline import PREVIEW_PARTICLES

    most = PREVIEW_PARTICLES if most is None else most
    sets = [(mesh, k) for mesh in scene.meshes for k, prim in enumerate(mesh.primitives)
            if prim.mode == "POINTS"]
    total = sum(mesh.primitives[k].vertex_count for mesh, k in sets)
    if total <= most:
        return None
    step = -(-total // most)
    kept = 0
    for mesh, k in sets:
        prim = mesh.primitives[k]
        # copies, not views: the whole set is let go (260 MB at 10^7)
        attributes = {name: np.ascontiguousarray(values[::step]) for name, values in prim.attributes.items()}
        targets = [{name: np.ascontiguousarray(v[::step]) for name, v in t.items()} for t in prim.targets]
        mesh.primitives[k] = replace(prim, attributes=attributes, targets=targets)
        kept += mesh.primitives[k].vertex_count
    return f"previewing {kept:,} of its {total:,} particles"
