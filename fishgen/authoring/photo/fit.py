"""--fit-shape: the base species' body profile, proportions, fin places and fin sizes fitted to
the photo's silhouette, so the 3D fish has the photographed fish's outline.

Only what a side view shows is fitted: the profile (as FishShapeSpline control
points), the depth-to-length ratio (scaleY; scaleZ keeps the base's width-to-
depth ratio), the BodySections the dorsal, anal and pelvic fins span, and every
fin's length. Angles, triangle counts and motion stay the base species'.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from fishgen.authoring.photo.sideview import circle_sines
from fishgen.species.model import Species

#: Where the fitted spline's control points sit along the body (nose 0, tail 1).
CONTROL_X = (0.04, 0.12, 0.25, 0.4, 0.55, 0.7, 0.82, 0.93)
ROUNDS = 3
#: A fitted fin keeps between these multiples of the base species' fin length.
FIN_RANGE = (0.4, 2.5)


def fit_shape(base: Species, mask: np.ndarray, note: Callable[[str], None]) -> Species:
    from fishgen.authoring.photo.run import analyse

    fitted = base
    for _ in range(ROUNDS):   # each round's profile is a better prior for the body under the fins
        seen = analyse(mask, fitted)
        fitted = _fit_fin_places(_fit_body(fitted, seen.outline), seen.outline)
    seen = analyse(mask, fitted)
    fitted = _fit_fin_sizes(fitted, {n: r.reach for n, r in seen.fins.items() if r.seen})
    note(f"fitted shape: scaleY {fitted.scale[1]:.4g} (base {base.scale[1]:.4g}), "
         f"{len(fitted.shape_params) // 2} spline control points")
    return fitted


def _fit_body(base: Species, outline) -> Species:
    u = np.asarray(CONTROL_X)
    x = outline.x0 + u * outline.x_scale
    up, down = outline.half_heights(x)
    s = circle_sines(base.circle_sections)
    reach = 0.5 * (s.max() - s.min())          # a faceted ring's silhouette is a bit under its radius
    half = 0.5 * (up + down) / max(reach, 1e-6)    # radius in frame pixels
    radius_per_length = half / outline.x_scale  # radius / body length
    sx, sy, sz = base.scale
    # Keep the base's scaleY if the profile stays within (0, 1]; else rescale scaleY to fit.
    r = radius_per_length * sx / sy
    peak = float(r.max())
    if peak > 0.6 or peak < 0.2:
        sy_new = float(radius_per_length.max() * sx / 0.5)
        sz, sy = sz * sy_new / sy, sy_new
        r = radius_per_length * sx / sy
    r = np.clip(r, 1e-3, 10.0)
    params = tuple(float(v) for pair in zip(u, r, strict=True) for v in pair)
    return replace(base, shape_class="FishShapeSpline", shape_params=params, scale=(sx, sy, sz))


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    edges = np.diff(np.r_[0, flags.astype(np.int8), 0])
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1, strict=True))


def _fit_fin_places(sp: Species, outline) -> Species:
    """Dorsal and anal (and pelvic) fins over the BodySections where the outline is fin."""
    b = sp.body_sections

    def section(col: float) -> int:
        u = (col + 0.5 - outline.x0) / outline.x_scale
        return int(np.clip(round(u * (b - 1)), 1, b - 2))

    def nearest_run(flags: np.ndarray, start: int, end: int) -> tuple[int, int] | None:
        centre = outline.x0 + (start + end) / 2 / (b - 1) * outline.x_scale
        lo = outline.x0 + 0.08 * outline.x_scale
        hi = outline.x0 + 0.9 * outline.x_scale
        runs = [(a, z) for a, z in _runs(flags) if z > lo and a < hi and z - a >= 3]
        if not runs:
            return None
        a, z = min(runs, key=lambda az: abs((az[0] + az[1]) / 2 - centre))
        s, e = section(a), section(z)
        return (s, max(e, s + 1)) if e < b - 1 or s + 1 < b - 1 else None

    out = sp
    for name, flags in (("dorsal", outline.fin_upper), ("anal", outline.fin_lower)):
        fin = getattr(sp, name)
        if fin.present:
            found = nearest_run(flags, fin.start_section, fin.end_section)
            if found:
                out = replace(out, **{name: replace(fin, start_section=found[0], end_section=found[1])})
    return out


def _fit_fin_sizes(sp: Species, reach: dict[str, float]) -> Species:
    lo, hi = FIN_RANGE

    def k(name: str) -> float:
        return float(np.clip(reach.get(name, 1.0), lo, hi))

    c = sp.caudal
    kc = k("caudal")
    out = replace(sp, caudal=replace(c, top_line=c.top_line * kc, bottom_line=c.bottom_line * kc,
                                     middle_line=c.middle_line * kc))
    for name in ("dorsal", "adipose", "anal"):
        f = getattr(out, name)
        if f.present:
            out = replace(out, **{name: replace(f, start_length=f.start_length * k(name),
                                                end_length=f.end_length * k(name))})
    p = out.pelvic
    return replace(out, pelvic=replace(p, start_length=p.start_length * k("pelvic"),
                                       end_length=p.end_length * k("pelvic")))
