"""NanoVDB writer (.nvdb): a cloud as float fog-volume grids ``density`` and ``light``.

The grids are one uncompressed segment, as ``nanovdb::io::writeGrid`` writes a handle of several
grids: the 16-byte file header, each grid's 176-byte metadata and name, then each grid's buffer,
which is
the in-memory layout NanoVDB reads in place (``nanovdb/NanoVDB.h``, version 32.9; byte offsets as
``PNanoVDB.h`` lists them): grid, tree, root with its tiles sorted by key, then the upper, lower
and leaf nodes breadth first, every node 32-byte aligned, child pointers as byte offsets from
the parent. No checksum (all bits set: "disabled"), no blind data. The index space starts at the
volume's first leaf; the map's translation puts it back in the world.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from fishgen.atomic import write_files
from fishgen.clouds.volume import DEFAULT_VOXEL_SIZE, Volume
from fishgen.exchange.volumes import leaf_stats, node_boxes, scene_volume, shifted, stats, tree
from fishgen.scene.model import Scene

MAGIC = int.from_bytes(b"NanoVDB0", "little")
VERSION = 32 << 21 | 9 << 10 | 2
FLOAT, FOG_VOLUME = 1, 2
GRID_FLAGS = 2 | 4 | 8 | 16 | 32  # bbox, min/max, average, standard deviation, breadth first
NODE_HAS_BBOX, LEAF_HAS_STATS = 2, 16
NO_CHECKSUM = (1 << 64) - 1

HEADER = np.dtype([("magic", "<u8"), ("version", "<u4"), ("grids", "<u2"), ("codec", "<u2")])
META = np.dtype([("grid_size", "<u8"), ("file_size", "<u8"), ("name_key", "<u8"), ("voxels", "<u8"),
                 ("type", "<u4"), ("class", "<u4"), ("world_box", "<f8", 6), ("index_box", "<i4", 6),
                 ("voxel_size", "<f8", 3), ("name_size", "<u4"), ("nodes", "<u4", 4), ("tiles", "<u4", 3),
                 ("codec", "<u2"), ("blind", "<u2"), ("version", "<u4")])
GRID = np.dtype([("magic", "<u8"), ("checksum", "<u8"), ("version", "<u4"), ("flags", "<u4"),
                 ("index", "<u4"), ("count", "<u4"), ("size", "<u8"), ("name", "S256"),
                 ("matf", "<f4", 9), ("invmatf", "<f4", 9), ("vecf", "<f4", 3), ("taperf", "<f4"),
                 ("matd", "<f8", 9), ("invmatd", "<f8", 9), ("vecd", "<f8", 3), ("taperd", "<f8"),
                 ("world_box", "<f8", 6), ("voxel_size", "<f8", 3), ("class", "<u4"), ("type", "<u4"),
                 ("blind_offset", "<i8"), ("blind_count", "<u4"), ("data0", "<u4"), ("data1", "<u8"),
                 ("data2", "<u8")])
TREE = np.dtype([("offsets", "<i8", 4), ("nodes", "<u4", 3), ("tiles", "<u4", 3), ("voxels", "<u8")])
ROOT = np.dtype([("box", "<i4", 6), ("tiles", "<u4"), ("background", "<f4"), ("stats", "<f4", 4),
                 ("pad", "V16")])
TILE = np.dtype([("key", "<u8"), ("child", "<i8"), ("state", "<u4"), ("value", "<f4"), ("pad", "V8")])


def _internal(log2: int) -> np.dtype:
    mask = (1 << 3 * log2) // 8
    return np.dtype([("box", "<i4", 6), ("flags", "<u8"), ("values", "u1", mask), ("children", "u1", mask),
                     ("stats", "<f4", 4), ("pad", "V16"), ("table", "<i8", 1 << 3 * log2)])


UPPER_NODE, LOWER_NODE = _internal(5), _internal(4)
LEAF_NODE = np.dtype([("min", "<i4", 3), ("span", "u1", 3), ("flags", "u1"), ("mask", "u1", 64),
                      ("stats", "<f4", 4), ("values", "<f4", 512)])
assert (GRID.itemsize, TREE.itemsize, ROOT.itemsize, TILE.itemsize, UPPER_NODE.itemsize,
        LOWER_NODE.itemsize, LEAF_NODE.itemsize, META.itemsize) == (672, 64, 64, 32, 270400, 33856, 2144, 176)


def write_nvdb(scene: Scene, path: Path, voxel_size: float = DEFAULT_VOXEL_SIZE,
               advance: Callable[[int], None] | None = None) -> list[Path]:
    write_files({path: nanovdb_bytes(scene_volume(scene, path, voxel_size, advance))})
    return [path]


def nanovdb_bytes(volume: Volume) -> bytes:
    """The grids of ``volume`` as one uncompressed NanoVDB segment."""
    count = len(volume.grids)
    volume, translation = shifted(volume)
    grids = [_grid(volume, translation, name, values, k, count)
             for k, (name, values) in enumerate(volume.grids)]
    header = np.zeros(1, HEADER)
    header["magic"], header["version"], header["grids"] = MAGIC, VERSION, count
    return b"".join([header.tobytes(), *(meta for meta, _ in grids), *(buffer for _, buffer in grids)])


def root_key(origins: np.ndarray) -> np.ndarray:
    """NanoVDB's 64-bit root key of upper-node origins: 21 bits per axis of uint32(ijk) >> 12,
    x highest; the root's tiles are stored sorted by it."""
    u = (origins.astype(np.int64) & 0xFFFFFFFF).astype(np.uint64) >> np.uint64(12)
    return (u[:, 0] << np.uint64(42)) | (u[:, 1] << np.uint64(21)) | u[:, 2]


def _grid(volume: Volume, translation: np.ndarray, name: str, values: np.ndarray, index: int,
          count: int) -> tuple[bytes, bytes]:
    """(its metadata and name, its buffer) of grid number ``index`` of ``count``; index (i, j, k) is
    centred at ``translation + voxel_size x (i, j, k)``."""
    t = tree(volume.origins, root_key)
    n_up, n_low, n_leaf = len(t.uppers), len(t.lowers), len(t.leaves)
    root_at = GRID.itemsize + TREE.itemsize
    up_at = root_at + ROOT.itemsize + n_up * TILE.itemsize
    low_at = up_at + n_up * UPPER_NODE.itemsize
    leaf_at = low_at + n_low * LOWER_NODE.itemsize
    size = leaf_at + n_leaf * LEAF_NODE.itemsize
    active = volume.active[t.leaves].reshape(n_leaf, 512)
    flat = values[t.leaves].reshape(n_leaf, 512)
    upper_of_leaf = t.lower_parent[t.leaf_parent]
    leaf_lo, leaf_hi = node_boxes(_reordered(volume, t.leaves), np.arange(n_leaf), n_leaf)
    low_lo, low_hi = node_boxes(_reordered(volume, t.leaves), t.leaf_parent, n_low)
    up_lo, up_hi = node_boxes(_reordered(volume, t.leaves), upper_of_leaf, n_up)
    everything = np.zeros(n_leaf, np.int64)
    box = np.concatenate([up_lo.min(0), up_hi.max(0)])

    leaves = np.zeros(n_leaf, LEAF_NODE)
    leaves["min"] = leaf_lo
    leaves["span"] = leaf_hi - leaf_lo
    leaves["flags"] = NODE_HAS_BBOX | LEAF_HAS_STATS
    leaves["mask"] = np.packbits(active, axis=1, bitorder="little")
    per_leaf = leaf_stats(flat, active)
    leaves["stats"] = stats(per_leaf, np.arange(n_leaf), n_leaf)
    leaves["values"] = flat

    lowers = np.zeros(n_low, LOWER_NODE)
    lowers["box"] = np.concatenate([low_lo, low_hi], axis=1)
    lowers["flags"] = NODE_HAS_BBOX
    lowers["stats"] = stats(per_leaf, t.leaf_parent, n_low)
    leaf_addresses = leaf_at + np.arange(n_leaf) * LEAF_NODE.itemsize
    parents = low_at + t.leaf_parent * LOWER_NODE.itemsize
    lowers["table"][t.leaf_parent, t.leaf_slot] = leaf_addresses - parents
    lowers["children"] = _mask(t.leaf_parent, t.leaf_slot, n_low, 4096)

    uppers = np.zeros(n_up, UPPER_NODE)
    uppers["box"] = np.concatenate([up_lo, up_hi], axis=1)
    uppers["flags"] = NODE_HAS_BBOX
    uppers["stats"] = stats(per_leaf, upper_of_leaf, n_up)
    low_addresses = low_at + np.arange(n_low) * LOWER_NODE.itemsize
    parents = up_at + t.lower_parent * UPPER_NODE.itemsize
    uppers["table"][t.lower_parent, t.lower_slot] = low_addresses - parents
    uppers["children"] = _mask(t.lower_parent, t.lower_slot, n_up, 32768)

    tiles = np.zeros(n_up, TILE)
    tiles["key"] = root_key(t.uppers)
    tiles["child"] = up_at + np.arange(n_up) * UPPER_NODE.itemsize - root_at
    root = np.zeros(1, ROOT)
    root["box"] = box
    root["tiles"] = n_up
    root["stats"] = stats(per_leaf, everything, 1)

    head = np.zeros(1, TREE)
    head["offsets"] = [x - GRID.itemsize for x in (leaf_at, low_at, up_at, root_at)]
    head["nodes"] = [n_leaf, n_low, n_up]
    head["voxels"] = int(active.sum())

    vs = volume.voxel_size
    world = np.concatenate([translation + box[:3] * vs, translation + (box[3:] + 1) * vs])
    grid = np.zeros(1, GRID)
    grid["magic"], grid["checksum"], grid["version"], grid["flags"] = MAGIC, NO_CHECKSUM, VERSION, GRID_FLAGS
    grid["index"], grid["count"], grid["size"], grid["name"] = index, count, size, name.encode("ascii")
    grid["matf"] = grid["matd"] = np.diag([vs] * 3).reshape(-1)
    grid["invmatf"] = grid["invmatd"] = np.diag([1 / vs] * 3).reshape(-1)
    grid["vecf"] = grid["vecd"] = translation
    grid["taperf"] = grid["taperd"] = 1.0
    grid["world_box"], grid["voxel_size"] = world, [vs] * 3
    grid["class"], grid["type"] = FOG_VOLUME, FLOAT

    name_bytes = name.encode("ascii") + b"\0"
    meta = np.zeros(1, META)
    meta["grid_size"] = meta["file_size"] = size
    meta["voxels"] = head["voxels"]
    meta["type"], meta["class"] = FLOAT, FOG_VOLUME
    meta["world_box"], meta["index_box"], meta["voxel_size"] = world, box, [vs] * 3
    meta["name_size"] = len(name_bytes)
    meta["nodes"] = [n_leaf, n_low, n_up, 1]
    meta["version"] = VERSION
    parts = (grid, head, root, tiles, uppers, lowers, leaves)
    return meta.tobytes() + name_bytes, b"".join(p.tobytes() for p in parts)


def _reordered(volume: Volume, order: np.ndarray) -> Volume:
    return Volume(volume.voxel_size, volume.origins[order], volume.active[order], ())


def _mask(parent: np.ndarray, slot: np.ndarray, count: int, bits: int) -> np.ndarray:
    """(count, bits/8) bytes: each parent's bit ``slot`` set for its children (little-endian words)."""
    on = np.zeros((count, bits), bool)
    on[parent, slot] = True
    return np.packbits(on, axis=1, bitorder="little")
