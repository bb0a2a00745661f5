"""Export a particle cloud, format chosen by the output's extension."""
from __future__ import annotations

import os
from pathlib import Path

from fishgen.clouds.model import Cloud
from fishgen.errors import FishgenError

FORMATS = (".ply", ".glb", ".gltf", ".csv", ".npy")


def check_output(path: str | os.PathLike, billboards: bool = False) -> str:
    """Return the output's format suffix, or raise FishgenError before any work is done."""
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise FishgenError(f"expected an output ending in {', '.join(FORMATS)}, "
                           f"found {suffix or 'no extension'!r}", path)
    if billboards and suffix not in (".glb", ".gltf"):
        raise FishgenError(f"expected a .glb or .gltf output with --billboards, found {suffix!r}",
                           path)
    return suffix


def export_cloud(cloud: Cloud, path: str | os.PathLike, *, billboards: bool = False) -> None:
    """Write ``cloud`` to ``path`` (.ply, .glb, .gltf, .csv or .npy), atomically."""
    suffix = check_output(path, billboards)
    if suffix == ".ply":
        from fishgen.clouds.export.ply import write_ply
        write_ply(cloud, path)
    elif suffix in (".glb", ".gltf"):
        from fishgen.clouds.export.gltf import write_gltf
        write_gltf(cloud, path, billboards=billboards)
    elif suffix == ".csv":
        from fishgen.clouds.export.table import write_csv
        write_csv(cloud, path)
    else:
        from fishgen.clouds.export.table import write_npy
        write_npy(cloud, path)
