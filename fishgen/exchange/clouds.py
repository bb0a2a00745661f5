"""Export a particle cloud: build its scene (fishgen.clouds.scene) and write it by extension.

The writers' side of a cloud, above the cloud package: fishgen.clouds re-exports its names."""
from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from fishgen.clouds.model import DEFAULT_VOXEL_SIZE, Cloud
from fishgen.errors import FishgenError
from fishgen.exchange.registry import POINTS, extensions, formats, output_format

FORMATS = extensions(formats(writable=True, holding=[POINTS]))
VOLUME_FORMATS = tuple(ext for f in formats(writable=True, holding=[POINTS]) if "voxel_size" in f.writes_with
                       for ext in f.extensions)
"""Formats that hold the cloud as voxel grids (.nvdb, .vdb): they take a voxel size."""
BILLBOARD_FORMATS = (".glb", ".gltf")
"""Billboards need unlit, alpha-blended, vertex-coloured quads: only glTF says all of that."""


GLTF_HEADROOM = 1 << 20
"""Bytes kept for the JSON, the chunk headers and the sprite within glTF's 4 GiB buffer."""


def check_output(path: str | os.PathLike, billboards: bool = False, particles: int | None = None) -> str:
    """Return the output's format suffix, or raise FishgenError before any work is done.

    With ``particles``, a glTF output that could not hold that many (its buffer
    is at most 4 GiB) is refused before the cloud is filled.
    """
    output_format(path, [POINTS])
    suffix = Path(path).suffix.lower()
    if billboards and suffix not in BILLBOARD_FORMATS:
        raise FishgenError(f"expected a .glb or .gltf output with --billboards, found {suffix!r}",
                           path)
    if particles is not None and suffix in BILLBOARD_FORMATS:
        from fishgen.clouds.scene import BILLBOARD_BYTES, POINT_BYTES
        from fishgen.exchange.gltf import GLB_LIMIT

        most = (GLB_LIMIT - GLTF_HEADROOM) // (BILLBOARD_BYTES if billboards else POINT_BYTES)
        if particles > most:
            drawn = "billboards" if billboards else "points"   # asked for, or a texture cloud's
            raise FishgenError(f"expected at most {most:,} particles as {drawn} in glTF (4 GiB buffer "
                               f"limit), found {particles:,}; use .ply, .csv or .npy (the particles alone, "
                               "without pictures)", path)
    return suffix


def export_cloud(cloud: Cloud, path: str | os.PathLike, *, billboards: bool = False,
                 voxel_size: float = DEFAULT_VOXEL_SIZE,
                 advance: Callable[[int], None] | None = None) -> list[Path]:
    """Write ``cloud`` to ``path`` (.ply, .glb, .gltf, .csv, .npy, or as volume grids of
    ``voxel_size`` to .nvdb or .vdb), atomically; a volume calls ``advance(k)`` as each k particles
    are splatted."""
    from fishgen.clouds.scene import cloud_scene
    from fishgen.exchange import export

    suffix = check_output(path, billboards)
    if len(cloud) == 0:
        raise FishgenError("expected at least 1 particle to export, found 0", path)
    scene = cloud_scene(cloud, billboards=billboards)
    if suffix in VOLUME_FORMATS:
        return export(scene, path, voxel_size=voxel_size, advance=advance)
    return export(scene, path)
