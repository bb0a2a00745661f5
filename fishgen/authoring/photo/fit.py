"""--fit-shape: the base species' body profile, proportions and fin sizes fitted to
the photo's silhouette, so the 3D fish has the photographed fish's outline.

Only what a side view shows is fitted: the profile (as FishShapeSpline control
points), the depth-to-length ratio (scaleY; scaleZ keeps the base's width-to-
depth ratio) and every fin's length. Where fins stand (their BodySections),
their angles, triangle counts and motion stay the base species': moving a fin
to where the outline bulges proved less reliable than the base's layout, so
pick a base species whose fins are laid out like the photographed fish's.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from fishgen.authoring.photo.sideview import circle_sines
from fishgen.species.model import Species

#: Where the fitted spline's control points sit along the body (nose 0, tail 1).
CONTROL_X = (0.04, 0.12, 0.25, 0.4, 0.55, 0.7, 0.82, 0.93)
ROUNDS = 2
DEAD_BAND = 0.2
MIN_FIN_AREA = 200
#: Radius of the disk that opens fins off the body, as a share of the body's half depth.
OPENING = 0.5
#: A fitted fin keeps between these multiples of the base species' fin length.
FIN_RANGE = (0.4, 2.5)


def fit_shape(base: Species, mask: np.ndarray) -> Species:
    from fishgen.authoring.photo.run import analyse

    # Round 0 takes the body's outline from the silhouette opened by a disk (fins are thinner
    # than the body), not from the base profile, which may be nothing like this fish's.
    fitted = _fit_body(base, _opened_outline(analyse(mask, base)))
    for _ in range(ROUNDS):   # each round's profile is a better prior for the body under the fins
        seen = analyse(mask, fitted)
        fitted = _fit_body(fitted, seen.outline)
    seen = analyse(mask, fitted)
    # A fin of a few pixels (BonyBream's adipose) has no reach worth measuring.
    reach = {n: r.reach for n, r in seen.fins.items() if r.seen and r.area >= MIN_FIN_AREA}
    fitted = _fit_fin_sizes(fitted, reach)
    # Then where the fins stand, their lengths and angles, by the overlap of the side views.
    from fishgen.authoring.photo.finfit import fit_fins

    seen = analyse(mask, fitted)
    fitted, _ = fit_fins(fitted, seen.outline, seen.frame.mask)
    return fitted


def _opened_outline(a):
    """The body outline with fins removed by a morphological opening (via distance transforms),
    the raw outline kept where the body is thinner than the disk (nose, tail base)."""
    from scipy import ndimage  # type: ignore[import-untyped]

    from fishgen.authoring.photo import columns

    o = a.outline
    mask = a.frame.mask
    xc = np.arange(mask.shape[1]) + 0.5
    mid = o.midline(xc)
    top, bottom = columns.run_through(mask, mid)
    depth = np.nanmax(bottom - top)
    radius = OPENING * depth / 2
    eroded = ndimage.distance_transform_edt(mask) > radius
    opened = ndimage.distance_transform_edt(~eroded) <= radius
    otop, obottom = columns.run_through(opened & mask, mid)
    up = np.where(np.isnan(otop), mid - top, mid - otop)
    down = np.where(np.isnan(obottom), bottom - mid, obottom - mid)
    inside = (xc >= o.x0) & (xc <= o.x0 + o.x_scale)
    return replace(o, upper=np.where(inside, up, np.nan), lower=np.where(inside, down, np.nan))


def _fit_body(base: Species, outline) -> Species:
    """FishShapeSpline control points through the measured half depth; scaleY rescaled only when
    the profile would leave the usual 0.2..0.6 peak radius."""
    u = np.asarray(CONTROL_X)
    x = outline.x0 + u * outline.x_scale
    up, down = outline.half_heights(x)
    s = circle_sines(base.circle_sections)
    reach = 0.5 * (s.max() - s.min())          # a faceted ring's silhouette is a bit under its radius
    half = 0.5 * (up + down) / max(reach, 1e-6)    # radius in frame pixels
    radius_per_length = half / outline.x_scale  # radius / body length
    sx, sy, sz = base.scale
    r = radius_per_length * sx / sy
    peak = float(r.max())
    if peak > 0.6 or peak < 0.2:
        sy_new = float(radius_per_length.max() * sx / 0.5)
        sz, sy = sz * sy_new / sy, sy_new
        r = radius_per_length * sx / sy
    r = np.clip(r, 1e-3, 10.0)
    params = tuple(float(v) for pair in zip(u, r, strict=True) for v in pair)
    return replace(base, shape_class="FishShapeSpline", shape_params=params, scale=(sx, sy, sz))


def _fit_fin_sizes(sp: Species, reach: dict[str, float]) -> Species:
    lo, hi = FIN_RANGE

    def k(name: str) -> float:
        # Within DEAD_BAND the base's fin stays: a masked photo's fins are rounded and eroded
        # a little by the mask, which is no reason to shrink the geometry.
        ratio = float(np.clip(reach.get(name, 1.0), lo, hi))
        return 1.0 if abs(ratio - 1.0) <= DEAD_BAND else ratio

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
