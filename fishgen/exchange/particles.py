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
    """(name, per-particle array, little-endian type) of every column a particle table holds.

    A colour column of type ``|u1`` given as uint16 is 16-bit linear light (fishgen's clouds keep
    that, which maps back to the exact sRGB bytes): :func:`particle_chunks` packs its sRGB bytes,
    a chunk at a time."""
    a = prim.attributes
    pos = a["POSITION"]
    cols = [(axis, pos[:, k], "<f4") for k, axis in enumerate("xyz")]
    cols += [(name[1:].lower(), a[name], "<f4") for name in ("_RADIUS", "_DENSITY") if name in a]
    if "COLOR_0" in a:
        rgb = a["COLOR_0"][:, :3]
        srgb = (rgb if rgb.dtype == np.uint16 else
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
    blocks = _blocks(columns, dtype, n)
    view = buffer.view(np.dtype({"names": [f"b{k}" for k in range(len(blocks))],
                                 "formats": [kind for _, _, kind in blocks],
                                 "offsets": [offset for _, offset, _ in blocks],
                                 "itemsize": dtype.itemsize}))
    srgb = linear16_to_srgb8()
    for start in range(0, n, ROWS):
        stop = min(start + ROWS, n)
        rec = view[: stop - start]
        for k, (values, _, kind) in enumerate(blocks):
            part = values[start:stop]
            if part.dtype == np.uint16:                  # linear colour: its sRGB bytes
                part = srgb[part]
            rec[f"b{k}"] = part.view(kind).reshape(-1) if kind.kind == "V" else part
        yield buffer[: stop - start]


def _blocks(columns: list[tuple[str, np.ndarray, str]], dtype: np.dtype,
            n: int) -> list[tuple[np.ndarray, int, np.dtype]]:
    """How to pack ``columns``: (source, offset in the record, type). Columns side by side in one
    C-contiguous (n, w) array of their type (x y z of POSITION, an RGB's three colours) make one
    block copied as raw bytes, as does a contiguous column of its type: a few byte copies a chunk
    instead of a typed copy a column into the unaligned record. 16-bit linear colour counts as
    bytes (it is packed as sRGB bytes)."""
    blocks: list[tuple[np.ndarray, int, np.dtype]] = []
    offsets = {name: int(dtype.fields[name][1]) for name in dtype.names or ()} if dtype.fields else {}
    k = 0
    while k < len(columns):
        name, values, kind = columns[k]
        offset, size = offsets[name], np.dtype(kind).itemsize
        stored = np.dtype(np.uint16) if kind == "|u1" and values.dtype == np.uint16 else np.dtype(kind)
        base = values.base
        if isinstance(base, np.ndarray) and base.ndim == 2 and base.shape[0] == n and base.dtype == stored \
                and base.flags.c_contiguous and k + base.shape[1] <= len(columns) \
                and all(columns[k + j][2] == kind and _side_by_side(columns[k + j][1], base, j)
                        for j in range(base.shape[1])):
            blocks.append((base, offset, np.dtype((np.void, base.shape[1] * size))))
            k += base.shape[1]
            continue
        if values.dtype == kind and values.flags.c_contiguous:
            blocks.append((values, offset, np.dtype((np.void, size))))
        else:
            blocks.append((values, offset, np.dtype(kind)))
        k += 1
    return blocks


def _side_by_side(column: np.ndarray, base: np.ndarray, j: int) -> bool:
    """``column`` is ``base[:, j]``."""
    return column.base is base and column.strides == base.strides[:1] \
        and _address(column) == _address(base) + j * base.itemsize


def _address(array: np.ndarray) -> int:
    return int(array.__array_interface__["data"][0])
