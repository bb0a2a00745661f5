"""A particle set's columns as packed records, shared by the PLY, NPY and CSV writers."""
from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from fishgen.errors import FishgenError
from fishgen.numeric import linear16_to_srgb8, linear_to_srgb, to_linear_float
from fishgen.scene.model import Primitive, Scene

ROWS = 1 << 18
"""Particles packed per write: keeps the packing buffer a few MB whatever the cloud size."""


def only_points(scene: Scene, where) -> Primitive:
    """The one particle set a table format holds."""
    drawn = [prim for _, prim in scene.drawn()]
    if len(drawn) != 1 or drawn[0].mode != "POINTS":
        raise FishgenError(f"expected one particle set for a {where.suffix} file, found "
                           f"{len(drawn)} primitive(s) of {sorted({p.mode.lower() for p in drawn})}", where)
    return drawn[0]


def particle_columns(prim: Primitive) -> list[tuple[str, np.ndarray, str]]:
    """(name, per-particle array, little-endian type) of every column a particle table holds."""
    a = prim.attributes
    pos = a["POSITION"]
    cols = [(axis, pos[:, k], "<f4") for k, axis in enumerate("xyz")]
    cols += [(name[1:].lower(), a[name], "<f4") for name in ("_RADIUS", "_DENSITY") if name in a]
    if "COLOR_0" in a:
        rgb = a["COLOR_0"][:, :3]
        # fishgen's clouds keep 16-bit linear colour, which maps back to the exact sRGB bytes
        srgb = (linear16_to_srgb8()[rgb] if rgb.dtype == np.uint16 else
                np.round(linear_to_srgb(to_linear_float(rgb)[:, :3]) * 255).astype(np.uint8))
        cols += [(name, srgb[:, k], "|u1") for k, name in enumerate(("red", "green", "blue"))]
    if "_CUBE" in a:
        cols.append(("cube", a["_CUBE"], "<i4"))  # float32 in glTF, an integer in tables
    return cols


def particle_chunks(prim: Primitive, columns: list[tuple[str, np.ndarray, str]]) -> Iterator[np.ndarray]:
    """The particles as packed structured arrays of at most ``ROWS`` rows."""
    dtype = np.dtype([(name, kind) for name, _, kind in columns])
    n = prim.vertex_count
    buffer = np.empty(min(ROWS, n), dtype)
    for start in range(0, n, ROWS):
        stop = min(start + ROWS, n)
        rec = buffer[: stop - start]
        for name, values, _ in columns:
            rec[name] = values[start:stop]
        yield rec


