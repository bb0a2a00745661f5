"""Nose, tail base and the body's outline under the fins, measured on a head-left silhouette.

Fins only ever add to the silhouette, so the body outline is what remains where
the outline does not stand out above the base species' own body shape. Where a
fin hides the body (a dorsal fin's base, the caudal fin over the body's tip),
the body is carried across by the base species' profile, scaled to the visible
parts on either side.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fishgen.authoring.photo import columns
from fishgen.authoring.photo.sideview import SideView, rasterize

#: How far in from the ends the tail base is looked for, as a share of the fish's length.
TAIL_SEARCH = 0.4
#: ...and never in the last this share of it: a neck there is a caudal lobe's 1-px thread (or a gap
#: in it) beside the other lobe, not the peduncle.
TAIL_END = 0.05
#: The snout, as a share of the body length from the nose: never taken for fin.
SNOUT = 0.1
#: An outline column stands out as fin when it exceeds the body model by this share (+ 1.5 px).
FIN_TOLERANCE = 0.04


@dataclass(frozen=True)
class Calibration:
    """The base species' own silhouette measured like the photo's, so the measures' biases cancel."""
    tail_base: float    # the tail base's x as a share of the body length
    tail_drop: float    # its centre's height below the body axis, per unit of nose-to-tail-base distance


def nose_and_tail_base(mask: np.ndarray, rows: np.ndarray | None = None,
                       drop: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(nose, tail base) as (x, y) frame points. ``rows``: the midline row per column, when known;
    then only the run through the midline counts, so a fin tip drifting above the tail is ignored.
    ``drop``: a calibrated tail-base centre lying off the axis (an asymmetric caudal fin) is moved
    back onto it."""
    top, bottom, has = columns.extent(mask)
    cols = np.flatnonzero(has)
    x0, x_end = int(cols[0]), int(cols[-1])
    length = x_end - x0 + 1
    if rows is None:
        thick = bottom - top
        centre = (top + bottom) / 2
    else:
        run_top, run_bottom = columns.run_through(mask, rows)
        thick = run_bottom - run_top
        centre = (run_top + run_bottom) / 2
    depth = columns.neck_depth(thick)
    lo = x0 + int(TAIL_SEARCH * length)
    depth[:lo] = 0.0
    depth[x_end + 1 - int(TAIL_END * length):] = 0.0
    ped = int(np.argmax(depth))
    tip = slice(x0, x0 + max(2, int(0.01 * length)))
    nose = np.array([float(x0), float(np.nanmean((top[tip] + bottom[tip]) / 2))])
    tail = np.array([ped + 0.5, float(centre[ped])])
    tail[1] -= drop * (tail[0] - nose[0])
    return nose, tail


def calibrate(view: SideView, length_px: float) -> Calibration:
    """Measure the base species' rasterised side view at about the photo's scale."""
    lo, hi = view.extent()
    ppu = max(length_px, 200.0) / max(hi[0] - lo[0], 1e-9)
    mask, origin = rasterize(view, ppu)
    rows = np.full(mask.shape[1], origin[1])   # the thesis axis is the midline
    nose, ped = nose_and_tail_base(mask, rows)
    return Calibration(float((ped[0] - origin[0]) / (view.length * ppu)),
                       float((ped[1] - origin[1]) / max(ped[0] - nose[0], 1.0)))


@dataclass(frozen=True)
class BodyOutline:
    """The body in the frame: x0 nose, x1 tail point, the midline, and half-heights per column."""
    x0: float
    x1: float
    y0: float                 # midline height at the nose
    slope: float              # midline dy/dx (about 0 once the frame is level)
    upper: np.ndarray         # (W,) body half-height above the midline, per column (NaN outside)
    lower: np.ndarray         # (W,) below
    fin_upper: np.ndarray     # (W,) bool: the top outline there is fin, not body
    fin_lower: np.ndarray
    y_scale: float            # frame pixels per thesis unit, vertically

    @property
    def x_scale(self) -> float:
        return self.x1 - self.x0   # frame pixels per body length

    def midline(self, x: np.ndarray) -> np.ndarray:
        return self.y0 + self.slope * (np.asarray(x, float) - self.x0)

    def half_heights(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        cols = np.arange(self.upper.size) + 0.5
        ok = ~np.isnan(self.upper)
        return (np.interp(x, cols[ok], self.upper[ok]), np.interp(x, cols[ok], self.lower[ok]))


def body_outline(mask: np.ndarray, view: SideView, cal: Calibration) -> BodyOutline:
    nose, ped = nose_and_tail_base(mask, drop=cal.tail_drop)
    slope = (ped[1] - nose[1]) / max(ped[0] - nose[0], 1.0)
    rows = nose[1] + slope * (np.arange(mask.shape[1]) + 0.5 - nose[0])
    nose, ped = nose_and_tail_base(mask, rows, cal.tail_drop)
    slope = (ped[1] - nose[1]) / max(ped[0] - nose[0], 1.0)
    u_ped = cal.tail_base
    x0 = nose[0]
    x1 = x0 + (ped[0] - x0) / u_ped
    xc = np.arange(mask.shape[1]) + 0.5
    mid = nose[1] + slope * (xc - x0)
    run_top, run_bottom = columns.run_through(mask, mid)
    seen_up, seen_down = mid - run_top, run_bottom - mid
    u = (xc - x0) / (x1 - x0)
    inside = (u >= 0) & (u <= 1)
    prior_up, prior_down = view.outline_at(np.clip(u, 0, 1) * view.length)
    prior_down = -prior_down
    x_scale = (x1 - x0) / view.length
    front = u < 0.5
    snout = u < SNOUT
    upper, fin_up, k_up = _body_side(seen_up, prior_up * x_scale, inside, front, snout)
    lower, fin_down, k_down = _body_side(seen_down, prior_down * x_scale, inside, front, snout)
    return BodyOutline(x0, x1, nose[1], slope, upper, lower, fin_up, fin_down,
                       x_scale * 0.5 * (k_up + k_down))


def _body_side(seen: np.ndarray, prior: np.ndarray, inside: np.ndarray, front: np.ndarray,
               snout: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Body half-height along one side: the outline where it is body, the base profile (scaled to
    the body's visible ratio on either side) where fins stand on it. Returns it, the fin flags
    and the median visible ratio of photo to base profile."""
    usable = inside & (prior > 0.2 * np.nanmax(np.where(inside, prior, np.nan))) & ~np.isnan(seen)
    ratio = np.full(seen.shape, np.nan)
    ratio[usable] = seen[usable] / prior[usable]
    k = float(np.nanpercentile(ratio, 30)) if usable.any() else 1.0
    fin = np.zeros(seen.shape, bool)
    for _ in range(4):
        fin = inside & ~np.isnan(seen) & (seen > prior * k * (1 + FIN_TOLERANCE) + 1.5)
        fin |= inside & np.isnan(seen)
        body_cols = usable & ~fin
        if body_cols.any():
            k = float(np.median(ratio[body_cols]))
    # Fins are wider at their base than where they stand clear of the body: widen each flag.
    from scipy import ndimage  # type: ignore[import-untyped]

    # No fin stands on the snout: a blunt head above a pointed base profile is still head.
    fin = ndimage.binary_dilation(fin, iterations=2) & inside & ~snout
    ok = usable & ~fin
    xs = np.flatnonzero(ok)
    ratio_everywhere = np.interp(np.arange(seen.size), xs, ratio[xs]) if xs.size else np.full(seen.shape, k)
    # Near the nose the outline is body (the profile is too thin there to scale by); near the
    # tail the caudal fin covers the body's tip, so the profile carries it.
    trust = ok | (front & ~fin & ~np.isnan(seen))
    body = np.where(trust, seen, ratio_everywhere * prior)
    body = np.where(inside, body, np.nan)
    return body, fin, k


def body_region(outline: BodyOutline, shape: tuple[int, int]) -> np.ndarray:
    """The body's pixels in the frame: between its outlines, from the nose to the tail point."""
    h, w = shape
    xc = np.arange(w) + 0.5
    mid = outline.midline(xc)
    up = np.nan_to_num(outline.upper, nan=0.0)
    down = np.nan_to_num(outline.lower, nan=0.0)
    rows = np.arange(h)[:, None] + 0.5
    return (rows >= (mid - up)[None, :]) & (rows <= (mid + down)[None, :])
