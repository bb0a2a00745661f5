"""Body profile functions (the thesis' FishShapeFunction subclasses).

A profile gives the body radius r(x) for x in [0, 1] (nose at 0, tail at 1),
before scaling. Classes are selected by the name in the species file.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from fishgen.shape_names import SHAPE_NAMES

Profile = Callable[[np.ndarray], np.ndarray]


def sin_profile(params: Sequence[float] = ()) -> Profile:
    """FishShapeSin: r = 0.5 sin(pi x), closed at both ends (see docs/decisions.md)."""
    return lambda x: 0.5 * np.sin(np.pi * np.asarray(x, dtype=np.float64))


def pchip(xk: np.ndarray, yk: np.ndarray) -> Profile:
    """Monotone cubic (PCHIP) interpolant: never overshoots, so radii stay >= 0."""
    h = np.diff(xk)
    delta = np.diff(yk) / h
    d = np.zeros_like(yk)
    same_sign = delta[:-1] * delta[1:] > 0
    w1 = 2 * h[1:] + h[:-1]
    w2 = h[1:] + 2 * h[:-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        inner = (w1 + w2) / (w1 / delta[:-1] + w2 / delta[1:])
    d[1:-1] = np.where(same_sign, inner, 0.0)
    d[0] = _end_slope(h[0], h[1] if len(h) > 1 else h[0], delta[0], delta[1] if len(delta) > 1 else delta[0])
    d[-1] = _end_slope(h[-1], h[-2] if len(h) > 1 else h[-1], delta[-1],
                       delta[-2] if len(delta) > 1 else delta[-1])

    def profile(x):
        x = np.clip(np.asarray(x, dtype=np.float64), xk[0], xk[-1])
        k = np.clip(np.searchsorted(xk, x, side="right") - 1, 0, len(h) - 1)
        t = (x - xk[k]) / h[k]
        t2, t3 = t * t, t * t * t
        return ((2 * t3 - 3 * t2 + 1) * yk[k] + (t3 - 2 * t2 + t) * h[k] * d[k]
                + (-2 * t3 + 3 * t2) * yk[k + 1] + (t3 - t2) * h[k] * d[k + 1])

    return profile


def _end_slope(h0, h1, d0, d1):
    slope = ((2 * h0 + h1) * d0 - h0 * d1) / (h0 + h1)
    if np.sign(slope) != np.sign(d0):
        return 0.0
    if np.sign(d0) != np.sign(d1) and abs(slope) > abs(3 * d0):
        return 3 * d0
    return slope


def spline_profile(params: Sequence[float]) -> Profile:
    """FishShapeSpline: a smooth profile through (x, r) control points given after the
    shape flags; the ends (0, 0) and (1, 0) are added so the body closes."""
    pts = np.asarray(params, dtype=np.float64).reshape(-1, 2)
    xk = np.concatenate([[0.0], pts[:, 0], [1.0]])
    yk = np.concatenate([[0.0], pts[:, 1], [0.0]])
    return pchip(xk, yk)


# Preset spline profiles after the thesis' Figures 4.1 (hawk fish: long, low, blunt
# head) and 4.2 (angel fish: a tall disc). Values are (x, r) pairs.
HAWK = (0.04, 0.16, 0.12, 0.27, 0.25, 0.33, 0.45, 0.31, 0.70, 0.22, 0.90, 0.10)
ANGEL = (0.05, 0.28, 0.15, 0.52, 0.35, 0.68, 0.55, 0.62, 0.78, 0.38, 0.93, 0.14)

SHAPES: dict[str, Callable[[Sequence[float]], Profile]] = {
    "FishShapeSin": sin_profile,
    "FishShapeSpline": spline_profile,
    "FishShapeHawk": lambda params: spline_profile(HAWK),
    "FishShapeAngel": lambda params: spline_profile(ANGEL),
}
if tuple(SHAPES) != SHAPE_NAMES:  # the parser accepts SHAPE_NAMES: each needs a profile
    raise ImportError(f"fishgen.geometry.shapes: profiles {tuple(SHAPES)} != shape names {SHAPE_NAMES}")


def profile_for(name: str, params: Sequence[float] = ()) -> Profile:
    return SHAPES[name](params)
