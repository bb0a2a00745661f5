"""What the volume writers (.nvdb, .vdb) share: a cloud scene's particles as a Volume, and its
leaves grouped into the tree both formats store (root -> 32^3 internal -> 16^3 internal -> 8^3
leaves, each internal node covering 4096 and 128 voxels a side)."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fishgen.clouds.volume import DEFAULT_VOXEL_SIZE, Volume
from fishgen.scene.model import Scene

UPPER, LOWER = 4096, 128
"""Voxels along the side of an upper (32^3 children) and a lower (16^3 children) internal node."""


def scene_volume(scene: Scene, path: Path, voxel_size: float = DEFAULT_VOXEL_SIZE,
                 advance: Callable[[int], None] | None = None) -> Volume:
    """The one particle set of ``scene`` (a cloud's points) splatted into density and light grids,
    with the extinction its lighting was baked with (the scene's extras; else the default);
    ``advance(k)`` as each k particles are splatted."""
    from fishgen.clouds.lighting import Lighting, from_extras
    from fishgen.clouds.volume import particle_volume
    from fishgen.errors import FishgenError
    from fishgen.exchange.particles import only_points

    prim = only_points(scene, path)
    missing = [name for name in ("_RADIUS", "_DENSITY") if name not in prim.attributes]
    if missing:
        raise FishgenError(f"expected particles with {' and '.join(missing)} for a volume, found none", path)
    a = prim.attributes
    lighting = from_extras(scene.extras) or Lighting()
    return particle_volume(a["POSITION"], a["_RADIUS"], a["_DENSITY"], a.get("_LIGHT"),
                           lighting.extinction, voxel_size, path, advance=advance)


def shifted(volume: Volume) -> tuple[Volume, np.ndarray]:
    """``volume`` with its index space moved so its first leaf starts at 0, and the world position
    of index 0 (the translation the files' transforms carry). A cloud around the world's origin
    straddles 8 upper and 8 lower nodes (each several kB to 270 kB); moved, one of each holds up to
    128 voxels a side."""
    shift = volume.origins.min(axis=0)
    moved = Volume(volume.voxel_size, (volume.origins - shift).astype(np.int32), volume.active, volume.grids)
    return moved, shift.astype(np.float64) * volume.voxel_size


@dataclass(frozen=True)
class Tree:
    """A volume's internal nodes and leaves in one stored order. ``uppers`` (U, 3) and ``lowers``
    (M, 3) are node origins; ``lower_parent`` (M,) and ``leaf_parent`` (L,) index the parent in
    that order, ``lower_slot``/``leaf_slot`` are the child's index in its parent's table, and
    ``leaves`` (L,) maps stored leaf order to the volume's leaves."""

    uppers: np.ndarray
    lowers: np.ndarray
    lower_parent: np.ndarray
    lower_slot: np.ndarray
    leaves: np.ndarray
    leaf_parent: np.ndarray
    leaf_slot: np.ndarray


def tree(origins: np.ndarray, upper_order) -> Tree:
    """Group leaf ``origins`` into internal nodes; uppers sorted by ``upper_order(uppers)`` (a sort
    key array), each node's children in table order (x, then y, then z: OpenVDB's and NanoVDB's)."""
    o = origins.astype(np.int64)
    upper_of = o & ~np.int64(UPPER - 1)
    lower_of = o & ~np.int64(LOWER - 1)
    uppers, upper_index = np.unique(upper_of, axis=0, return_inverse=True)
    rank = np.empty(len(uppers), np.int64)
    rank[np.argsort(upper_order(uppers), kind="stable")] = np.arange(len(uppers))
    lower_slot_all = _slot(lower_of, UPPER, LOWER)
    leaf_slot_all = _slot(o, LOWER, 8)
    # lowers: by their upper's rank, then slot in it
    lower_key = rank[upper_index.reshape(-1)] * (1 << 15) + lower_slot_all
    lower_keys, lower_index = np.unique(lower_key, return_inverse=True)
    lower_index = lower_index.reshape(-1)
    first_leaf = np.zeros(len(lower_keys), np.int64)
    first_leaf[lower_index[::-1]] = np.arange(len(o))[::-1]
    leaf_order = np.lexsort((leaf_slot_all, lower_index))
    return Tree(uppers=uppers[np.argsort(rank)].astype(np.int32),
                lowers=lower_of[first_leaf].astype(np.int32),
                lower_parent=lower_keys >> 15, lower_slot=lower_keys & ((1 << 15) - 1),
                leaves=leaf_order, leaf_parent=lower_index[leaf_order], leaf_slot=leaf_slot_all[leaf_order])


def _slot(origins: np.ndarray, parent: int, child: int) -> np.ndarray:
    """The index of a child node (origin ``origins``, side ``child`` voxels) in its parent's table."""
    per = parent // child
    bits = per.bit_length() - 1
    local = (origins & (parent - 1)) // child
    return (local[:, 0] << (2 * bits)) | (local[:, 1] << bits) | local[:, 2]


def node_boxes(volume: Volume, parent: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """(min, max) active voxel of each of ``count`` nodes whose leaves (volume order) have
    ``parent`` indices: the bounding boxes the formats store per node."""
    lo, hi = leaf_boxes(volume)
    node_lo = np.full((count, 3), np.iinfo(np.int32).max, np.int64)
    node_hi = np.full((count, 3), np.iinfo(np.int32).min, np.int64)
    np.minimum.at(node_lo, parent, lo)
    np.maximum.at(node_hi, parent, hi)
    return node_lo.astype(np.int32), node_hi.astype(np.int32)


def leaf_boxes(volume: Volume) -> tuple[np.ndarray, np.ndarray]:
    """(min, max) active voxel of every leaf, world index space, (L, 3) int64 each."""
    lo = np.empty((len(volume.origins), 3), np.int64)
    hi = np.empty_like(lo)
    for axis in range(3):
        other = tuple(a for a in (1, 2, 3) if a != axis + 1)
        along = np.asarray(np.any(volume.active, axis=other))        # (L, 8)
        lo[:, axis] = np.argmax(along, axis=1)
        hi[:, axis] = 7 - np.argmax(along[:, ::-1], axis=1)
    return lo + volume.origins, hi + volume.origins


def leaf_stats(values: np.ndarray, active: np.ndarray) -> np.ndarray:
    """(L, 5) float64 per leaf of its active ``values`` (L, 512): count, mean, sum of squared
    deviations, min and max (inf and -inf for none)."""
    v = values.astype(np.float64)
    n = active.sum(axis=1).astype(np.float64)
    mean = np.where(active, v, 0).sum(axis=1) / np.maximum(n, 1)
    squares = np.where(active, (v - mean[:, None]) ** 2, 0).sum(axis=1)
    return np.stack([n, mean, squares, np.where(active, v, np.inf).min(axis=1),
                     np.where(active, v, -np.inf).max(axis=1)], axis=1)


def stats(leaves: np.ndarray, groups: np.ndarray, count: int) -> np.ndarray:
    """(count, 4) float32 min, max, mean and standard deviation of the active values of the leaves
    in each of ``count`` groups (``groups``: each leaf's), pooled from ``leaf_stats`` (Chan et al.)."""
    n, mean, squares = leaves[:, 0], leaves[:, 1], leaves[:, 2]
    lo = np.full(count, np.inf)
    hi = np.full(count, -np.inf)
    np.minimum.at(lo, groups, leaves[:, 3])
    np.maximum.at(hi, groups, leaves[:, 4])
    total = np.bincount(groups, n, count)
    group_mean = np.bincount(groups, n * mean, count) / np.maximum(total, 1)
    spread = np.bincount(groups, squares + n * (mean - group_mean[groups]) ** 2, count)
    return np.stack([lo, hi, group_mean, np.sqrt(spread / np.maximum(total, 1))], axis=1).astype(np.float32)
