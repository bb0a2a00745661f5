"""Binary little-endian PLY: x y z radius density red green blue (Blender, Open3D, plyfile)."""
from __future__ import annotations

import os

from fishgen.atomic import atomic_open
from fishgen.clouds.export.records import PARTICLE, record_chunks
from fishgen.clouds.model import Cloud

_TYPES = {"<f4": "float", "|u1": "uchar"}


def ply_header(count: int) -> bytes:
    lines = ["ply", "format binary_little_endian 1.0",
             "comment fishgen clouds: particle centre, radius, Gaussian density, colour",
             f"element vertex {count}"]
    lines += [f"property {_TYPES[PARTICLE[name].str]} {name}" for name in PARTICLE.names]
    lines.append("end_header")
    return ("\n".join(lines) + "\n").encode("ascii")


def write_ply(cloud: Cloud, path: str | os.PathLike) -> None:
    """Stream the cloud to ``path`` atomically, a chunk of records at a time."""
    with atomic_open(path) as handle:
        handle.write(ply_header(len(cloud)))
        for rec in record_chunks(cloud, PARTICLE):
            handle.write(memoryview(rec).cast("B"))
