"""Where a school's target (or its predator) is at given times: built-in curves or timed points.

`path_positions(path, times)` is vectorised over times and returns (F, 3) metres, +Y up.
Curves are horizontal (XZ plane around `centre`) unless said otherwise:

- circle:  one lap of radius `radius` every `period` seconds, anticlockwise seen from above.
- figure8: a lemniscate of Gerono, `radius` wide each side, one full eight per `period`.
- spline:  a closed Catmull-Rom loop through 6 points drawn from `seed` (radius 0.5-1 x
           `radius`, height +-0.25 x `radius`), one lap per `period`.
- points:  (t, x, y, z) rows, piecewise linear in time, held at the first/last point outside.
- none:    stands still at `centre`.
"""
from __future__ import annotations

import numpy as np

from fishgen.school.model import TargetPath

SPLINE_POINTS = 6


def path_positions(path: TargetPath, times: np.ndarray) -> np.ndarray:
    """Positions (F, 3) of `path` at `times` (F,) seconds."""
    t = np.asarray(times, dtype=np.float64).reshape(-1)
    centre = np.asarray(path.centre, dtype=np.float64)
    out = np.empty((t.size, 3), dtype=np.float64)
    kind = path.kind
    if kind == "none":
        out[:] = centre
        return out
    if kind == "points":
        return _points(path, t)
    if not path.period > 0:
        raise ValueError(f"path period must be > 0, found {path.period}")
    phase = 2.0 * np.pi * t / path.period
    r = float(path.radius)
    if kind == "circle":
        out[:, 0] = r * np.cos(phase)
        out[:, 1] = 0.0
        out[:, 2] = r * np.sin(phase)
    elif kind == "figure8":
        out[:, 0] = r * np.sin(phase)
        out[:, 1] = 0.0
        out[:, 2] = r * np.sin(phase) * np.cos(phase)
    elif kind == "spline":
        out[:] = _closed_spline(path.seed, r, phase / (2.0 * np.pi))
    else:
        raise ValueError(f"unknown path kind {kind!r}")
    return out + centre


def _points(path: TargetPath, t: np.ndarray) -> np.ndarray:
    pts = np.asarray(path.points, dtype=np.float64).reshape(-1, 4)
    if pts.shape[0] == 0:
        raise ValueError("path kind 'points' needs at least one (t, x, y, z) point")
    if not np.all(np.isfinite(pts)):
        raise ValueError("path points must be finite")
    if np.any(np.diff(pts[:, 0]) < 0):
        raise ValueError("path point times must not decrease")
    out = np.empty((t.size, 3), dtype=np.float64)
    for axis in range(3):
        out[:, axis] = np.interp(t, pts[:, 0], pts[:, axis + 1])
    return out


def _closed_spline(seed: int, radius: float, laps: np.ndarray) -> np.ndarray:
    """A closed uniform Catmull-Rom loop; `laps` (F,) in laps (1.0 = once round)."""
    rng = np.random.default_rng(seed)
    n = SPLINE_POINTS
    angles = 2.0 * np.pi * (np.arange(n) + rng.uniform(-0.3, 0.3, n)) / n
    radii = radius * rng.uniform(0.5, 1.0, n)
    ctrl = np.stack([radii * np.cos(angles), radius * rng.uniform(-0.25, 0.25, n),
                     radii * np.sin(angles)], axis=1)
    u = np.mod(laps, 1.0) * n
    i = np.floor(u).astype(np.int64) % n
    s = (u - np.floor(u))[:, None]
    p0, p1, p2, p3 = (ctrl[(i + k) % n] for k in (-1, 0, 1, 2))
    return 0.5 * ((2.0 * p1) + (p2 - p0) * s + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * s**2
                  + (3.0 * p1 - p0 - 3.0 * p2 + p3) * s**3)
