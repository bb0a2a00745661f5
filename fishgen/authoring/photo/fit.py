"""--fit-shape: the base species' body profile, proportions and fins fitted to the photo's
silhouette, so the 3D fish has the photographed fish's outline.

Only what a side view shows is fitted: the profile (as FishShapeSpline control
points), the depth-to-length ratio (scaleY; scaleZ keeps the base's width-to-
depth ratio), and where the dorsal, anal and pelvic fins stand, every fin's
lengths and angles (:mod:`.finfit`). Triangle counts, motion and behaviour stay
the base species'.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from fishgen.authoring.photo.sideview import circle_sines
from fishgen.species.model import Species

#: Where the fitted spline's control points sit along the body (nose 0, tail 1).
CONTROL_X = (0.04, 0.12, 0.25, 0.4, 0.55, 0.7, 0.82, 0.93)
ROUNDS = 2
FIN_ROUNDS = 2
#: Radius of the disk that opens fins off the body, as a share of the body's half depth.
OPENING = 0.5


def fit_shape(base: Species, mask: np.ndarray) -> Species:
    from fishgen.authoring.photo.run import analyse

    # Round 0 takes the body's outline from the silhouette opened by a disk (fins are thinner
    # than the body), not from the base profile, which may be nothing like this fish's.
    fitted = _fit_body(base, _opened_outline(analyse(mask, base)))
    for _ in range(ROUNDS):   # each round's profile is a better prior for the body under the fins
        seen = analyse(mask, fitted)
        fitted = _fit_body(fitted, seen.outline)
    # Then the fins: where they stand, their lengths and angles, by the overlap of the side
    # views; the body is refitted once more under the new fins (they move the tail point).
    from fishgen.authoring.photo.finfit import fit_fins

    for _ in range(FIN_ROUNDS):
        seen = analyse(mask, fitted)
        fitted, _ = fit_fins(fitted, seen.outline, seen.frame.mask)
        fitted = _fit_body(fitted, analyse(mask, fitted).outline)
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
