"""OpenVDB writer (.vdb): a cloud as FloatGrids ``density`` and ``light`` (``Tree_float_5_4_3``).

File format 224 (OpenVDB 6 and later read it), uncompressed, as ``openvdb::io::File::write``
lays it out: the header (magic, format and library versions, "has grid offsets", a 36-character
UUID), an empty file metadata map, the grid count, then per grid its descriptor (name, type,
instance parent, and the stream offsets of the grid, its leaf data and its end), compression 0,
its metadata (class "fog volume"), its transform (a ``UniformScaleTranslateMap``: index space
starts at the volume's first leaf, ``exchange.volumes.shifted``), the topology (root background
and children sorted by origin; each internal node's child and value masks and its values, all
background, behind the "all values" byte 6; each leaf's value mask) and then every leaf's mask
and 512 values in the same order. No maintained pip package writes .vdb here (docs/volumes.md),
so it is written from numpy.
"""
from __future__ import annotations

import hashlib
import struct
import uuid
from collections.abc import Callable
from pathlib import Path

import numpy as np

from fishgen.atomic import write_files
from fishgen.clouds.volume import DEFAULT_VOXEL_SIZE, Volume
from fishgen.exchange.volumes import shifted, tree
from fishgen.scene.model import Scene

MAGIC = 0x56444220
FILE_VERSION = 224
LIBRARY = (11, 0)
TREE_TYPE = "Tree_float_5_4_3"
ALL_VALUES = 6  # NO_MASK_AND_ALL_VALS: the node's every value follows, uncompressed
MAP = "UniformScaleTranslateMap"


def write_vdb(scene: Scene, path: Path, voxel_size: float = DEFAULT_VOXEL_SIZE,
              advance: Callable[[int], None] | None = None) -> list[Path]:
    from fishgen.exchange.volumes import scene_volume

    write_files({path: openvdb_bytes(scene_volume(scene, path, voxel_size, advance))})
    return [path]


def openvdb_bytes(volume: Volume) -> bytes:
    """The grids of ``volume`` as one OpenVDB file; its UUID is a hash of the grids, so the same
    volume gives the same bytes."""
    volume, translation = shifted(volume)
    grids = [_grid(volume, translation, name, values) for name, values in volume.grids]
    digest = hashlib.sha256(b"".join(body for _, body, _ in grids)).digest()[:16]
    header = (struct.pack("<qIIIB", MAGIC, FILE_VERSION, *LIBRARY, 1)
              + str(uuid.UUID(bytes=digest, version=4)).encode("ascii")
              + struct.pack("<I", 0)            # file metadata: none
              + struct.pack("<i", len(grids)))
    out = bytearray(header)
    for descriptor, body, leaf_data in grids:
        start = len(out) + len(descriptor) + 24  # the grid follows its three stream offsets
        out += descriptor
        out += struct.pack("<qqq", start, start + leaf_data, start + len(body))
        out += body
    return bytes(out)


def _string(text: str) -> bytes:
    data = text.encode("utf-8")
    return struct.pack("<I", len(data)) + data


def _grid(volume: Volume, translation: np.ndarray, name: str,
          values: np.ndarray) -> tuple[bytes, bytes, int]:
    """(descriptor without its stream offsets, the grid from its compression flags to its end,
    where its leaf data starts in that)."""
    t = tree(volume.origins, lambda uppers: np.lexsort(uppers.T[::-1]).argsort())
    active = volume.active[t.leaves].reshape(len(t.leaves), 512)
    masks = np.packbits(active, axis=1, bitorder="little")
    flat = values[t.leaves].reshape(len(t.leaves), 512).astype("<f4")
    vs = float(volume.voxel_size)
    meta = [("class", "string", b"fog volume"), ("name", "string", name.encode("utf-8"))]
    head = struct.pack("<I", 0)                     # compression: none
    head += struct.pack("<I", len(meta)) + b"".join(
        _string(key) + _string(kind) + struct.pack("<I", len(value)) + value for key, kind, value in meta)
    scale = np.array([vs] * 3)
    vectors = [translation, scale, scale, 1 / scale, 1 / scale ** 2, 0.5 / scale]
    head += _string(MAP) + np.concatenate(vectors).astype("<f8").tobytes()
    topology = [struct.pack("<i", 1), struct.pack("<f", 0.0), struct.pack("<II", 0, len(t.uppers))]
    lowers_of = np.split(np.arange(len(t.lowers)), np.flatnonzero(np.diff(t.lower_parent)) + 1)
    leaves_of = np.split(np.arange(len(t.leaves)), np.flatnonzero(np.diff(t.leaf_parent)) + 1)
    upper_zeros = b"\0" * 4096 + bytes([ALL_VALUES]) + b"\0" * (4 * 32768)
    lower_zeros = b"\0" * 512 + bytes([ALL_VALUES]) + b"\0" * (4 * 4096)
    for u, lowers in enumerate(lowers_of):
        topology.append(t.uppers[u].astype("<i4").tobytes())
        topology.append(_mask(t.lower_slot[lowers], 32768) + upper_zeros)
        for m in lowers:
            leaves = leaves_of[m]
            topology.append(_mask(t.leaf_slot[leaves], 4096) + lower_zeros)
            topology.append(masks[leaves].tobytes())
    buffers = np.zeros(len(t.leaves), np.dtype([("mask", "u1", 64), ("kind", "u1"), ("values", "<f4", 512)]))
    buffers["mask"], buffers["kind"], buffers["values"] = masks, ALL_VALUES, flat
    body = head + b"".join(topology)
    descriptor = _string(name) + _string(TREE_TYPE) + _string("")
    return descriptor, body + buffers.tobytes(), len(body)


def _mask(slots: np.ndarray, bits: int) -> bytes:
    on = np.zeros(bits, bool)
    on[slots] = True
    return np.packbits(on, bitorder="little").tobytes()
