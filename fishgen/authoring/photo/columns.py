"""Per-column measures of a silhouette mask (rows down): extents, runs and necks. All vectorised."""
from __future__ import annotations

import numpy as np


def extent(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(top row, bottom edge, has fish) of every column; top/bottom NaN in empty columns."""
    h = mask.shape[0]
    has = np.asarray(mask.any(axis=0))
    top = np.argmax(mask, axis=0).astype(float)
    bottom = (h - np.argmax(mask[::-1], axis=0)).astype(float)   # one past the last fish row
    top[~has], bottom[~has] = np.nan, np.nan
    return top, bottom, has


def run_through(mask: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(top row, bottom edge) of each column's run of fish pixels containing row ``rows[c]``.

    NaN where that pixel is background or ``rows[c]`` is NaN. A run is found with one running
    max and one running min over the whole mask rather than by walking columns.
    """
    h, w = mask.shape
    known = np.isfinite(rows)
    # a NaN row (a place no fin could be put) has no run; casting it to int is undefined
    r = np.clip(np.round(np.where(known, rows, 0.5) - 0.5).astype(int), 0, h - 1)
    k = np.arange(h)[:, None]
    above = np.zeros_like(mask)
    above[1:] = mask[:-1]
    below = np.zeros_like(mask)
    below[:-1] = mask[1:]
    starts = np.where(mask & ~above, k, -1)
    ends = np.where(mask & ~below, k, h)
    last_start = np.maximum.accumulate(starts, axis=0)
    next_end = np.minimum.accumulate(ends[::-1], axis=0)[::-1]
    cols = np.arange(w)
    inside = mask[r, cols] & known
    top = np.where(inside, last_start[r, cols], np.nan).astype(float)
    bottom = np.where(inside, next_end[r, cols] + 1, np.nan).astype(float)
    return top, bottom


def neck_depth(thickness: np.ndarray) -> np.ndarray:
    """How much wider the silhouette gets on both sides of each column: min(widest to the left,
    widest to the right) / own width. A tail's base (the peduncle) is the deepest neck."""
    t = np.nan_to_num(thickness, nan=0.0)
    left = np.maximum.accumulate(t)
    right = np.zeros_like(t)
    right[:-1] = np.maximum.accumulate(t[::-1])[::-1][1:]
    with np.errstate(divide="ignore", invalid="ignore"):
        depth = np.minimum(left, right) / t
    depth[~(t > 0)] = 0.0
    return depth


def tail_necks(mask: np.ndarray) -> tuple[float, float]:
    """(right, left): the deepest neck in each end's 45 % of the silhouette's columns. A caudal fin
    beyond a narrow peduncle makes the tail's end the deeper."""
    _, _, has = extent(mask)
    cols = np.flatnonzero(has)
    lo, hi = cols[0], cols[-1] + 1
    top, bottom, _ = extent(mask[:, lo:hi])
    e = bottom - top
    n = e.size
    reach = max(2, int(0.45 * n))
    return float(neck_depth(e)[n - reach:].max()), float(neck_depth(e[::-1])[n - reach:].max())

