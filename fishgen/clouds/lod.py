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
* its cube is its cell's first particle's; a texture cloud's particles merge only with particles
  of the same texture.

Pure numpy over the whole cloud: one ``np.unique`` of the cell keys per searched cell size, then
weighted sums by ``np.bincount``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from fishgen.clouds.model import Cloud
from fishgen.clouds.sprite import SIGMA

SEARCH_STEPS = 8
"""Most tries of the cell size; the count usually lands within TOLERANCE of the target in 3 or 4."""
TOLERANCE = 0.04


def coarsen(cloud: Cloud, ratio: float) -> Cloud:
    """``cloud`` with about ``len(cloud) / ratio`` particles (at least 1), merged by grid cell."""
    merged = merge_particles(cloud.centers, cloud.radii, cloud.density, ratio, _texture_group(cloud))
    if merged is None:
        return cloud
    light = None
    colors = cloud.colors[merged.first]
    if cloud.light is not None and cloud.lighting is not None:
        from fishgen.clouds.light import lit_colors

        light = merged.mean(cloud.light).astype(np.float32)
        colors = lit_colors(light, cloud.lighting)
    return replace(cloud, centers=merged.centers, radii=merged.radii, density=merged.density,
                   colors=colors, cube_index=cloud.cube_index[merged.first], light=light)


@dataclass(frozen=True)
class Merged:
    """Particles merged by grid cell: what each merged particle keeps (float32), each cell's first
    particle (``first``, for what is taken, not averaged) and the cell of each input particle."""

    centers: np.ndarray
    radii: np.ndarray
    density: np.ndarray
    first: np.ndarray
    inverse: np.ndarray
    mass: np.ndarray       # per input particle: density x radius^2, the weight of its values
    weight: np.ndarray     # per merged particle: its mass, 1 where it is 0 (a safe divisor)
    spread: np.ndarray     # per merged particle: its positions' variance per axis over their mean
                           # sprite width squared; under 1 they overlapped, far over it lay apart

    def mean(self, values: np.ndarray) -> np.ndarray:
        """Per merged particle, the mass-weighted mean of ``values`` (one row per input particle;
        float64)."""
        count = len(self.weight)
        if values.ndim == 1:
            return np.bincount(self.inverse, self.mass * values, minlength=count) / self.weight
        return np.stack([self.mean(values[:, k]) for k in range(values.shape[1])], axis=1)


def merge_particles(centers: np.ndarray, radii: np.ndarray, density: np.ndarray, ratio: float,
                    group: np.ndarray | None = None) -> Merged | None:
    """About ``len(centers) / ratio`` particles (at least 1) merged by grid cell from these (only
    particles of one ``group`` share a cell); None when that would merge nothing."""
    if not ratio >= 1:
        raise ValueError(f"ratio must be 1 or more, not {ratio}")
    n = len(centers)
    target = max(1, int(round(n / ratio)))
    if n == 0 or target >= n:
        return None
    columns = [np.ascontiguousarray(centers[:, k], np.float64) for k in range(3)]
    lo = np.array([c.min() for c in columns])
    span = np.array([c.max() for c in columns]) - lo
    extent = float(span.max())
    if not extent > 0:  # every particle at one point: one particle
        return _merge(columns, radii, density, np.zeros(n, np.intp), 1, np.zeros(1, np.intp))
    # the occupied cells fall as the cell grows, about as its size to a power between -3 (a solid
    # cloud) and -1 (a sheet): secant steps on log(count) against log(cell), from a solid guess
    cell = float(np.prod(np.maximum(span, extent * 1e-3)) / target) ** (1 / 3)
    best: tuple[np.ndarray, int, np.ndarray] | None = None
    previous: tuple[float, int] | None = None
    for _ in range(SEARCH_STEPS):
        inverse, count, first = _cells(columns, lo, span, cell, group)
        if best is None or abs(count - target) < abs(best[1] - target):
            best = (inverse, count, first)
        if abs(count - target) <= TOLERANCE * target:
            break
        slope = -2.5
        if previous is not None and previous[1] != count and previous[0] != cell:
            slope = math.log(count / previous[1]) / math.log(cell / previous[0])
        slope = min(-0.75, max(-3.5, slope))
        previous = (cell, count)
        cell *= (target / count) ** (1 / slope)
    assert best is not None
    inverse, count, first = best
    return _merge(columns, radii, density, inverse, count, first)


def _texture_group(cloud: Cloud) -> np.ndarray | None:
    """Per particle, its texture's number (a texture cloud), else None."""
    if not cloud.textures:
        return None
    names = {t: k for k, t in enumerate(dict.fromkeys(cloud.textures))}
    per_cube = np.array([names[t] for t in cloud.textures], np.int64)
    return per_cube[cloud.cube_index]


def _cells(columns: list[np.ndarray], lo: np.ndarray, span: np.ndarray, cell: float,
           group: np.ndarray | None) -> tuple[np.ndarray, int, np.ndarray]:
    """Each particle's occupied-cell number (0..count-1, in key order), the count, and each cell's
    first particle."""
    sides = np.floor(span / cell).astype(np.int64) + 1
    key = np.zeros(len(columns[0]), np.int64)
    for k in range(3):     # column by column: an (n, 3) reduction along axis 0 is strided and slow
        index = ((columns[k] - lo[k]) * (1 / cell)).astype(np.int64)
        np.minimum(index, sides[k] - 1, out=index)
        key *= sides[k]
        key += index
    if group is not None:
        key = key * (int(group.max()) + 1) + group
    unique, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    return inverse.ravel(), len(unique), first


def _merge(columns: list[np.ndarray], radii: np.ndarray, density: np.ndarray, inverse: np.ndarray,
           count: int, first: np.ndarray) -> Merged:
    r = radii.astype(np.float64)
    mass = density.astype(np.float64) * r * r
    weight = np.bincount(inverse, mass, minlength=count)
    safe = np.where(weight > 0, weight, 1.0)
    mean = [np.bincount(inverse, mass * c, minlength=count) / safe for c in columns]
    spread = sum(np.bincount(inverse, mass * c * c, minlength=count) / safe - m * m
                 for c, m in zip(columns, mean, strict=True))
    variance = np.maximum(spread, 0) / 3             # per axis
    width2 = np.bincount(inverse, mass * (SIGMA * r) ** 2, minlength=count) / safe
    radius = np.sqrt(width2 + variance) / SIGMA
    merged = np.minimum(1.0, weight / np.maximum(radius * radius, np.finfo(np.float64).tiny))
    return Merged(centers=np.stack(mean, axis=1).astype(np.float32), radii=radius.astype(np.float32),
                  density=np.maximum(merged, np.finfo(np.float32).tiny).astype(np.float32),
                  first=first, inverse=inverse, mass=mass, weight=safe,
                  spread=variance / np.maximum(width2, np.finfo(np.float64).tiny))
