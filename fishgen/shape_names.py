"""Body shape class names and the rule for their extra parameters.

A leaf module (no numpy, no fishgen imports) shared by the species parser, which
checks a file's shape record, and :mod:`fishgen.geometry.shapes`, which builds the
profiles. Keeping it here means neither package has to import the other.
"""
from __future__ import annotations

from collections.abc import Sequence

#: The thesis' FishShapeFunction subclasses a species file may name.
SHAPE_NAMES: tuple[str, ...] = ("FishShapeSin", "FishShapeSpline", "FishShapeHawk", "FishShapeAngel")


def check_shape_params(name: str, params: Sequence[float]) -> str | None:
    """Return what was expected if ``params`` do not suit shape class ``name``."""
    if name != "FishShapeSpline":
        return None if not params else f"no values after the flags for {name}"
    if len(params) < 2 or len(params) % 2:
        return "FishShapeSpline control points `x r` pairs after the flags (at least one pair)"
    xs = params[0::2]
    rs = params[1::2]
    if not all(a < b for a, b in zip((0.0, *xs), (*xs, 1.0), strict=True)) or min(rs) <= 0 or max(rs) > 10:
        return "FishShapeSpline control points with 0 < x increasing < 1 and 0 < r <= 10"
    return None


def shape_params_found(name: str, params: Sequence[float]) -> str:
    """What a file gave that :func:`check_shape_params` refused: for a spline, its first control
    point out of order or range (``found 10 extra values`` named none of them)."""
    if name != "FishShapeSpline" or len(params) < 2 or len(params) % 2:
        return f"{len(params)} extra values"
    pairs = list(zip(params[0::2], params[1::2], strict=True))
    before = 0.0
    for k, (x, r) in enumerate(pairs):
        if not before < x < 1 or not 0 < r <= 10:
            return f"control point {k + 1} of {len(pairs)} at x {x:g}, r {r:g}" + (
                f" (after x {before:g})" if k and not before < x else "")
        before = x
    return f"{len(params)} extra values"
