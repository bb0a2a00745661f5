"""A cloud's lower level of detail: fewer, larger particles, for clouds seen from far away.

Particles are merged by cell of a cubic grid whose cell is sized so that about ``1 / ratio`` of the
particles remain, within a few % (the cell is searched: clumped clouds occupy fewer cells than their
box suggests).
Each occupied cell becomes one particle, and what it keeps is what a distant viewer sees:

* its centre is the weighted mean of the merged centres, the weights being each particle's optical
  mass ``density x radius^2`` (what its sprite adds to the picture);
* its sprite's width covers the merged sprites and their spread: ``(SIGMA R)^2 = mean((SIGMA r)^2) +
  the positions' variance per axis``, both weighted (a sum of Gaussians has that variance);
* its density keeps the optical mass, ``D R^2 = sum(d r^2)``, clipped to 1 (a cell of opaque
  particles that overlap stays opaque, and loses the mass hidden behind the front ones);
* its light is the weighted mean of the merged particles' light, its colour what that light gives;
* its cube is the heaviest merged particle's; a texture cloud's particles merge only with particles
  of the same texture.

Pure numpy over the whole cloud: one ``np.unique`` of the cell keys per searched cell size, then
weighted sums by ``np.bincount``.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from fishgen.clouds.model import Cloud
from fishgen.clouds.sprite import SIGMA

SEARCH_STEPS = 8
"""Most tries of the cell size; the count usually lands within TOLERANCE of the target in 3 or 4."""
TOLERANCE = 0.04


def coarsen(cloud: Cloud, ratio: float) -> Cloud:
    """``cloud`` with about ``len(cloud) / ratio`` particles (at least 1), merged by grid cell."""
    if not ratio >= 1:
        raise ValueError(f"ratio must be 1 or more, not {ratio}")
    n = len(cloud)
    target = max(1, int(round(n / ratio)))
    if n == 0 or target >= n:
        return cloud
    centers = np.asarray(cloud.centers, np.float64)
    group = _texture_group(cloud)
    lo = centers.min(axis=0)
    extent = float(np.max(centers.max(axis=0) - lo))
    if not extent > 0:  # every particle at one point: one particle
        return _merge(cloud, np.zeros(n, np.intp), 1)
    # the occupied cells fall as the cell grows, about as its size to a power between -3 (a solid
    # cloud) and -1 (a sheet): secant steps on log(count) against log(cell), from a solid guess
    span = centers.max(axis=0) - lo
    cell = float(np.prod(np.maximum(span, extent * 1e-3)) / target) ** (1 / 3)
    best: tuple[int, np.ndarray, int] | None = None
    previous: tuple[float, int] | None = None
    for _ in range(SEARCH_STEPS):
        inverse, count = _cells(centers, lo, cell, group)
        if best is None or abs(count - target) < abs(best[2] - target):
            best = (0, inverse, count)
        if abs(count - target) <= TOLERANCE * target:
            break
        slope = -2.5
        if previous is not None and previous[1] != count and previous[0] != cell:
            slope = math.log(count / previous[1]) / math.log(cell / previous[0])
        slope = min(-0.75, max(-3.5, slope))
        previous = (cell, count)
        cell *= (target / count) ** (1 / slope)
    assert best is not None
    _, inverse, count = best
    return _merge(cloud, inverse, count)


def _texture_group(cloud: Cloud) -> np.ndarray | None:
    """Per particle, its texture's number (a texture cloud), else None."""
    if not cloud.textures:
        return None
    names = {t: k for k, t in enumerate(dict.fromkeys(cloud.textures))}
    per_cube = np.array([names[t] for t in cloud.textures], np.int64)
    return per_cube[cloud.cube_index]


def _cells(centers: np.ndarray, lo: np.ndarray, cell: float,
           group: np.ndarray | None) -> tuple[np.ndarray, int]:
    """Each particle's occupied-cell number (0..count-1, in key order) and the count."""
    ijk = np.floor((centers - lo) / cell).astype(np.int64)
    span = ijk.max(axis=0) + 1
    key = (ijk[:, 0] * span[1] + ijk[:, 1]) * span[2] + ijk[:, 2]
    if group is not None:
        key = key * (int(group.max()) + 1) + group
    unique, inverse = np.unique(key, return_inverse=True)
    return inverse.ravel(), len(unique)


def _merge(cloud: Cloud, inverse: np.ndarray, count: int) -> Cloud:
    r = cloud.radii.astype(np.float64)
    d = cloud.density.astype(np.float64)
    mass = d * r * r
    weight = np.bincount(inverse, mass, minlength=count)
    safe = np.where(weight > 0, weight, 1.0)
    centers = np.asarray(cloud.centers, np.float64)
    mean = np.stack([np.bincount(inverse, mass * centers[:, k], minlength=count) for k in range(3)],
                    axis=1) / safe[:, None]
    spread = centers - mean[inverse]
    variance = np.bincount(inverse, mass * (spread * spread).sum(axis=1) / 3, minlength=count) / safe
    width2 = np.bincount(inverse, mass * (SIGMA * r) ** 2, minlength=count) / safe
    radius = np.sqrt(width2 + variance) / SIGMA
    density = np.minimum(1.0, weight / np.maximum(radius * radius, np.finfo(np.float64).tiny))
    # the heaviest particle of each cell names its cube (a stable choice: first of equal masses)
    order = np.lexsort((-mass, inverse))
    first = order[np.r_[0, np.flatnonzero(np.diff(inverse[order])) + 1]]
    light = None
    colors = cloud.colors[first]
    if cloud.light is not None and cloud.lighting is not None:
        from fishgen.clouds.light import lit_colors

        light = (np.bincount(inverse, mass * cloud.light, minlength=count) / safe).astype(np.float32)
        colors = lit_colors(light, cloud.lighting)
    return replace(cloud, centers=mean.astype(np.float32), radii=radius.astype(np.float32),
                   density=np.maximum(density, np.finfo(np.float32).tiny).astype(np.float32),
                   colors=colors, cube_index=cloud.cube_index[first], light=light)
