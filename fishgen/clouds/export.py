"""Export a particle cloud: build its scene (fishgen.clouds.scene) and write it by extension."""
from __future__ import annotations

import os
from pathlib import Path

from fishgen.clouds.model import Cloud
from fishgen.errors import FishgenError
from fishgen.exchange.registry import POINTS, extensions, formats, output_format

FORMATS = extensions(formats(writable=True, holding=[POINTS]))
BILLBOARD_FORMATS = (".glb", ".gltf")
"""Billboards need unlit, alpha-blended, vertex-coloured quads: only glTF says all of that."""


def check_output(path: str | os.PathLike, billboards: bool = False) -> str:
    """Return the output's format suffix, or raise FishgenError before any work is done."""
    output_format(path, [POINTS])
    suffix = Path(path).suffix.lower()
    if billboards and suffix not in BILLBOARD_FORMATS:
        raise FishgenError(f"expected a .glb or .gltf output with --billboards, found {suffix!r}",
                           path)
    return suffix


def export_cloud(cloud: Cloud, path: str | os.PathLike, *, billboards: bool = False) -> list[Path]:
    """Write ``cloud`` to ``path`` (.ply, .glb, .gltf, .csv or .npy), atomically."""
    from fishgen.clouds.scene import cloud_scene
    from fishgen.exchange import export

    check_output(path, billboards)
    if len(cloud) == 0:
        raise FishgenError("expected at least 1 particle to export, found 0", path)
    return export(cloud_scene(cloud, billboards=billboards), path)
