"""Particle records: packed a block of side-by-side columns at a time, the same bytes as field by field."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.exchange import particles
from fishgen.numeric import linear16_to_srgb8
from fishgen.scene.model import Primitive


def _field_by_field(prim: Primitive) -> bytes:
    columns = particles.particle_columns(prim)
    rec = np.empty(prim.vertex_count, np.dtype([(name, kind) for name, _, kind in columns]))
    for name, values, kind in columns:
        # 16-bit linear colour is written as its sRGB bytes
        rec[name] = linear16_to_srgb8()[values] if kind == "|u1" and values.dtype == np.uint16 else values
    return rec.tobytes()


def _points(n: int, layout: str) -> Primitive:
    rng = np.random.default_rng(3)
    wide = rng.random((n, 4), dtype=np.float32)
    attributes = {
        # a position that is its own (n, 3) array, or three columns of a wider one (not one block)
        "POSITION": wide[:, :3] if layout == "strided" else np.ascontiguousarray(wide[:, :3]),
        "COLOR_0": rng.integers(0, 65536, (n, 3)).astype(np.uint16),
        "_RADIUS": wide[:, 3] if layout == "strided" else wide[:, 3].copy(),
        "_DENSITY": rng.random(n).astype(np.float64),        # converted to float32 on the way
        "_CUBE": rng.integers(0, 1000, n).astype(np.float32),  # an integer in tables
    }
    if layout == "float colours":
        attributes["COLOR_0"] = rng.random((n, 4)).astype(np.float32)
    if layout == "rgba16":     # three channels of four: converted a column at a time
        attributes["COLOR_0"] = rng.integers(0, 65536, (n, 4)).astype(np.uint16)
    return Primitive(attributes, mode="POINTS")


@pytest.mark.parametrize("layout", ["contiguous", "strided", "float colours", "rgba16"])
def test_chunks_hold_the_columns_bytes_whatever_the_layout(layout, monkeypatch):
    monkeypatch.setattr(particles, "ROWS", 1000)    # several chunks, the last one short
    prim = _points(2500, layout)
    # each chunk is the same buffer refilled: copied as it comes
    chunks = [c.copy() for c in particles.particle_chunks(prim, particles.particle_columns(prim))]
    assert [len(c) for c in chunks] == [1000, 1000, 500]
    assert b"".join(c.tobytes() for c in chunks) == _field_by_field(prim)


def test_side_by_side_columns_are_one_block():
    prim = _points(10, "contiguous")
    columns = particles.particle_columns(prim)
    dtype = np.dtype([(name, kind) for name, _, kind in columns])
    widths = [(offset, kind.itemsize, kind.kind) for _, offset, kind in particles._blocks(columns, dtype, 10)]
    # x y z, radius, density (float64: converted), red green blue, cube (float32: converted)
    assert widths == [(0, 12, "V"), (12, 4, "V"), (16, 4, "f"), (20, 3, "V"), (23, 4, "i")]
    # x y z and the radius side by side in one (n, 4) array: one block of 16 bytes
    strided = _points(10, "strided")
    columns = particles.particle_columns(strided)
    first = particles._blocks(columns, dtype, 10)[0]
    assert (first[1], first[2].itemsize) == (0, 16)
    # side by side, but one declared of another type: converted, not copied as bytes
    wide = strided.attributes["POSITION"].base
    columns = [("a", wide[:, 0], "<f4"), ("b", wide[:, 1], "<i4"), ("c", wide[:, 2], "<f4"),
               ("d", wide[:, 3], "<f4")]
    dtype = np.dtype([(name, kind) for name, _, kind in columns])
    assert [kind.str for _, _, kind in particles._blocks(columns, dtype, 10)] == ["<f4", "<i4", "<f4", "<f4"]
