"""--fit-shape's first reading: the body and every fin measured on the levelled silhouette.

Fins only add to a silhouette and a fishgen body is symmetric about its axis, so the body is no
deeper than the nearer outline at each column; a smooth hump (:func:`_hump`) fitted under those
depths bridges where fins stand on both sides, and its half-depth at every BodySection becomes a
FishShapeSpline control point there (:func:`body_species`). Pixels outside the drawn body are fin:
behind the tail base the caudal fin (its lobe tips and fork), above the back the dorsal and
adipose fins, under the belly the pelvic and anal fins (:func:`measured`). :func:`holds` says
whether a species' BodySections can carry what was measured.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import ndimage  # type: ignore[import-untyped]

from fishgen.authoring.photo import columns
from fishgen.authoring.photo.draw import Placement, body_mask, iou, reach, surface_row, with_fin
from fishgen.species.model import PelvicFin, Species, VerticalFin

#: Where the tail base (the deepest neck) falls on a built fish, as a share of its body length.
TAIL_BASE = 0.965
#: A tail base found this close to the fish's end (share of its length) is a lobe tip, not a neck.
TAIL_TIP = 0.05
#: The fish's nose-to-tail-base length in the working frame, in pixels.
WORK_LENGTH = 360
#: A column stands out as fin when the outline is this far past the body (share of body length).
FIN_MARGIN = 0.012
#: Runs of fin smaller than this share of the fish's area are specks.
SPECK = 0.002
#: LOD: the body outline must be matched at least this well by the sections, else more are used.
BODY_IOU = 0.97
#: Where fins may stand, as shares of the body: (first, last) section share.
PLACES = {"dorsal": (0.08, 0.97), "adipose": (0.3, 0.97), "anal": (0.3, 0.97), "pelvic": (0.1, 0.75)}
MAX_PELVIC_SPAN = 0.35
#: Fin runs under the belly part where the fin pixels per column fall under this share of the
#: peaks on both sides (:func:`_valleys_out`).
VALLEY = 0.25


@dataclass(frozen=True)
class Body:
    """The fin-free body measured on the working mask: half-depth and centre per column."""
    half: np.ndarray           # (W,) NaN outside the fish
    centre: np.ndarray
    nose: float                # first column
    tail_base: float           # the deepest neck's column
    area: int


def working_mask(frame_mask: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    """The levelled silhouette scaled so the fish is about WORK_LENGTH long, with a margin of half
    its size all round (a fin grown past the photo's edge must still count against the fit); and
    (scale, offset) taking working pixels back to the frame's: frame = work * scale + offset."""
    from PIL import Image

    ys, xs = np.nonzero(frame_mask)
    crop = frame_mask[ys.min():ys.max() + 1, xs.min():xs.max() + 1]
    w, h = max(1, round(WORK_LENGTH)), max(1, round(crop.shape[0] * WORK_LENGTH / max(crop.shape[1], 1)))
    small = np.asarray(Image.fromarray(crop.astype(np.uint8) * 255).resize((w, h), Image.Resampling.BILINEAR))
    pad_y, pad_x = max(h, 40) // 2 + 8, w // 2
    kx, ky = crop.shape[1] / w, crop.shape[0] / h
    scale = 0.5 * (kx + ky)
    offset = np.array([xs.min() - pad_x * kx, ys.min() - pad_y * ky])
    return np.pad(small >= 128, ((pad_y, pad_y), (pad_x, pad_x))), scale, offset


def measure_body(work: np.ndarray) -> Body:
    """The body's half-depth along the fish, fins taken off.

    The body is a rotated profile, symmetric about its axis (the nose-to-tail-base line), and
    fins only add to the silhouette: so at each column the body is no deeper than the nearer of
    the two outlines. Where fins stand on both sides that is still too deep; there the body is a
    hump (rising to one peak, then falling: a fish's body has no waist before its tail) fitted by
    least squares to the columns it does not undercut by more than a tolerance, four times."""
    from fishgen.authoring.photo.anatomy import nose_and_tail_base

    nose, ped = nose_and_tail_base(work)
    cols = np.flatnonzero(work.any(axis=0))
    if cols[-1] + 1 - ped[0] < TAIL_TIP * (cols[-1] + 1 - cols[0]):
        # A "neck" at the very end is a caudal lobe's tip beyond the other's (a turned fish in
        # perspective): the run through the nose's row, which lobes do not widen, finds the real one.
        nose, ped = nose_and_tail_base(work, np.full(work.shape[1], nose[1]))
    y0 = float(ped[1])
    top, bottom = columns.run_through(work, np.full(work.shape[1], y0))
    length = max(ped[0] - nose[0], 1.0)
    xc = np.arange(work.shape[1]) + 0.5
    inside = (xc >= nose[0]) & (xc <= ped[0]) & ~np.isnan(top)
    cols = np.flatnonzero(inside)
    # Fins only add: the body is no deeper than the side without a fin; where fins stand on both
    # sides it is a smooth hump through the columns it does not undercut.
    seen = np.minimum(y0 - top[cols], bottom[cols] - y0)
    u = (xc[cols] - nose[0]) / (length / TAIL_BASE)
    half = np.full(work.shape[1], np.nan)
    half[cols] = _hump(u, seen)
    centre = np.where(inside, y0, np.nan)
    return Body(half, centre, float(nose[0]), float(ped[0]), int(work.sum()))


def _hump(u: np.ndarray, seen: np.ndarray) -> np.ndarray:
    """log h = a + p log u + q log(1 - u) + c u + d u^2 (a smooth body: blunt or pointed head, one hump,
    tapering tail), fitted by least squares reweighted so that columns standing above the fit
    (fins) barely count and columns under it count fully."""
    ok = seen > 0.5
    uu = np.clip(u[ok], 1e-3, 0.999)
    design = np.stack([np.ones_like(uu), np.log(uu), np.log1p(-uu), uu, uu * uu], axis=1)
    target = np.log(seen[ok])
    weight = np.ones(uu.size)
    coef = np.zeros(5)
    for _ in range(8):
        coef, *_ = np.linalg.lstsq(design * weight[:, None], target * weight, rcond=None)
        resid = target - design @ coef
        weight = np.where(resid > 0.02, 0.05, 1.0)
    uc = np.clip(u, 1e-3, 0.999)
    return np.exp(np.stack([np.ones_like(uc), np.log(uc), np.log1p(-uc), uc, uc * uc], axis=1) @ coef)


def body_species(sp: Species, body: Body, place: Placement, depth: float) -> Species:
    """``sp`` with a FishShapeSpline through the measured half-depth at each section, for
    ``place``; ``depth`` scales it (the refinement's one body parameter)."""
    b = sp.body_sections
    sx = sp.scale[0]
    u = np.arange(1, b - 1) / (b - 1)
    x = place.x0 + u * sx * place.s
    cols = np.arange(body.half.size) + 0.5
    ok = ~np.isnan(body.half)
    half = np.interp(x, cols[ok], body.half[ok], left=0.0, right=0.0)
    # Behind the tail base the caudal fin hides the body: it tapers to the tail point there.
    end = place.x0 + sx * place.s
    at_base = float(np.interp(body.tail_base, cols[ok], body.half[ok]))
    behind = x > body.tail_base
    if end > body.tail_base:
        half = np.where(behind, at_base * np.clip((end - x) / (end - body.tail_base), 0, 1), half)
    half = np.maximum(half * depth, 0.25)   # px: a body never pinches to nothing inside
    radius = half / (reach(sp.circle_sections) * place.s)      # thesis units (r * scaleY)
    sy = float(radius.max() / 0.5)
    r = np.clip(radius / sy, 1e-3, 10.0)
    params = tuple(round(float(v), 5) for pair in zip(u, r, strict=True) for v in pair)
    width = sp.scale[2] / sp.scale[1]
    return replace(sp, shape_class="FishShapeSpline", shape_params=params,
                   scale=(sx, round(sy, 6), round(sy * width, 6)))


def measured(base: Species, work: np.ndarray, body: Body) -> tuple[Species, Placement]:
    """The body and every fin read off the silhouette, before any refinement."""
    sx = base.scale[0]
    length_px = (body.tail_base - body.nose) / TAIL_BASE   # the tail point lies just behind it
    y0 = float(np.nanmedian(body.centre))
    place = Placement(body.nose, y0, length_px / sx)
    sp = body_species(base, body, place, 1.0)
    return _measured_fins(sp, work, body, place), place


def _section_of(x_px: float, sp: Species, place: Placement) -> float:
    return (x_px - place.x0) / (sp.scale[0] * place.s) * (sp.body_sections - 1)


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """[start, end) of every run of True."""
    d = np.diff(np.r_[0, flags.astype(np.int8), 0])
    return list(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist(), strict=True))


def _measured_fins(sp: Species, work: np.ndarray, body: Body, place: Placement) -> Species:
    """Every fin's place and size read off the silhouette outside the body."""
    h, w = work.shape
    drawn_body = body_mask(sp, place, work.shape)
    outside = work & ~drawn_body
    length = sp.scale[0] * place.s
    rows = np.arange(h)[:, None] + 0.5
    xc = np.arange(w) + 0.5
    above = outside & (rows < place.y0)
    below = outside & (rows >= place.y0)
    tol = max(1.5, FIN_MARGIN * length)
    sp = _caudal_from(sp, outside, body, place)
    span = (xc > place.x0 + 0.06 * length) & (xc < body.tail_base - 0.01 * length)
    up = np.where(span, above.sum(axis=0), 0)
    down = np.where(span, below.sum(axis=0), 0)
    runs_up = [r for r in _runs(up > tol) if up[r[0]:r[1]].sum() >= SPECK * body.area]
    runs_down = [r for r in _runs(_valleys_out(down, down > tol))
                 if down[r[0]:r[1]].sum() >= SPECK * body.area]
    # A long pelvic fin swept back under the anal fin's front shares its columns: no valley parts
    # them, so each run is parted into the separate fins it holds (:func:`_parted`).
    pieces = [p for r in runs_down for p in _parted(r, below, drawn_body, tol, SPECK * body.area)]
    runs_up.sort(key=lambda r: -int(up[r[0]:r[1]].sum()))
    dorsal = runs_up[0] if runs_up else None
    adipose = next((r for r in runs_up[1:] if dorsal is not None and r[0] > dorsal[1]), None)
    sp = _vertical_from(sp, "dorsal", dorsal, above, place, 1.0)
    sp = _vertical_from(sp, "adipose", adipose, above, place, 1.0)
    pieces.sort(key=lambda p: p[0])
    def centre(p: tuple[int, int, np.ndarray]) -> float:
        return ((p[0] + p[1]) / 2 - place.x0) / length

    def size(p: tuple[int, int, np.ndarray]) -> int:
        return int(p[2][:, p[0]:p[1]].sum())

    front = [p for p in pieces if centre(p) < 0.55]
    pelvic = max(front, key=size) if front else None
    back = [p for p in pieces if centre(p) > 0.45 and p is not pelvic]
    anal = max(back, key=size) if back else None
    sp = _vertical_from(sp, "anal", anal[:2] if anal else None, anal[2] if anal else below, place, -1.0)
    sp = _pelvic_from(sp, pelvic[:2] if pelvic else None, pelvic[2] if pelvic else below, place)
    return sp


def _parted(run: tuple[int, int], below: np.ndarray, drawn_body: np.ndarray, tol: float,
            least: float) -> list[tuple[int, int, np.ndarray]]:
    """The fins in one run of columns under the belly, each as (first column, end column, its
    pixels). Clear of the body (``tol`` px off it: the belly strip a body measured a little short
    leaves) two fins are two separate parts even where their columns overlap, as a long pelvic fin
    swept back under the anal fin's front is (301, 401, 701: one fin read, the other left out).
    With two parts of ``least`` pixels or more every pixel of the run goes to the nearest of them;
    otherwise the run is one fin, all of ``below`` in its columns."""
    a, b = run
    sub = np.zeros_like(below)
    sub[:, a:b] = below[:, a:b]
    clear = sub & ~ndimage.binary_dilation(drawn_body, iterations=int(np.ceil(tol)))
    lab, n = ndimage.label(clear, structure=np.ones((3, 3), bool))
    sizes = np.bincount(lab.ravel(), minlength=n + 1)
    sizes[0] = 0
    big = np.flatnonzero(sizes >= least)
    if big.size < 2:
        return [(a, b, below)]
    seeds = np.isin(lab, big)
    _, (iy, ix) = ndimage.distance_transform_edt(~seeds, return_indices=True)
    owner = lab[iy, ix]
    out = []
    for k in big.tolist():
        part = sub & (owner == k)
        cols = np.flatnonzero(part.any(axis=0))
        out.append((int(cols[0]), int(cols[-1]) + 1, part))
    return out


def _valleys_out(counts: np.ndarray, flags: np.ndarray) -> np.ndarray:
    """``flags`` without the columns of a valley: fin pixels under VALLEY x the lower of the
    highest counts on either side. Where the measured body falls a few pixels short of the
    photo's, a strip of its belly joins the pelvic fin to the anal fin in one run of columns; the
    valley between their peaks parts them. A fin falling away to its end has no peak behind it,
    and keeps its low part."""
    out = flags.copy()
    for a, b in _runs(flags):
        seg = counts[a:b].astype(float)
        peaks = np.minimum(np.maximum.accumulate(seg), np.maximum.accumulate(seg[::-1])[::-1])
        out[a:b] &= ~(seg < VALLEY * peaks)
    return out


def _caudal_from(sp: Species, outside: np.ndarray, body: Body, place: Placement) -> Species:
    """The caudal fin's lines and angles from its lobe tips and fork, seen behind the tail base."""
    c = sp.caudal
    sy = sp.scale[1]
    origin = place.to_frame(np.array([[c.connection[0] * sp.scale[0], 0.0]]))[0]
    tail = outside.copy()
    tail[:, :int(body.tail_base)] = False
    lab, _ = ndimage.label(tail, structure=np.ones((3, 3), bool))
    near = lab[:, int(body.tail_base):int(body.tail_base) + 4]
    keep = np.unique(near[near > 0])
    tail = np.isin(lab, keep) if keep.size else tail
    ys, xs = np.nonzero(tail)
    if xs.size < 4:
        return sp
    pts = np.stack([xs + 0.5, ys + 0.5], 1) - origin
    upper, lower = pts[pts[:, 1] < 0], pts[pts[:, 1] >= 0]
    length = sp.scale[0] * place.s

    def tip(p: np.ndarray) -> np.ndarray | None:
        if len(p) == 0:
            return None
        return p[np.argmax(np.hypot(p[:, 0], p[:, 1]))]

    top, bottom = tip(upper), tip(lower)
    axis_row = np.abs(pts[:, 1]) <= 1.0
    middle = float(pts[axis_row, 0].max()) if axis_row.any() else 0.1 * length
    unit = place.s * sy

    def line(v: np.ndarray | None, fallback: float) -> tuple[float, float]:
        if v is None:
            return 0.05, fallback
        angle = np.degrees(np.arctan2(abs(v[1]), max(v[0], 1e-6)))
        return float(np.hypot(*v) / unit), float(np.clip(angle, 5, 85))

    top_line, top_angle = line(top, c.top_angle)
    bottom_line, bottom_angle = line(bottom, c.bottom_angle)
    middle_line = float(np.clip(middle / unit, 0.02, 20))
    return replace(sp, caudal=replace(c, top_line=min(top_line, 20.0), top_angle=top_angle,
                                      bottom_line=min(bottom_line, 20.0), bottom_angle=bottom_angle,
                                      middle_line=middle_line, rotation_angle=0.0))


def _vertical_from(sp: Species, name: str, run: tuple[int, int] | None, side_mask: np.ndarray,
                   place: Placement, side: float) -> Species:
    fin: VerticalFin = getattr(sp, name)
    b = sp.body_sections
    if run is None:
        return with_fin(sp, name, replace(fin, start_length=0.0, end_length=0.0))
    lo, hi = PLACES[name]
    s0 = int(np.clip(round(_section_of(run[0], sp, place)), max(1, np.ceil(lo * (b - 1))), b - 3))
    s1 = int(np.clip(round(_section_of(run[1], sp, place)), s0 + 1, min(b - 2, np.floor(hi * (b - 1)))))
    s1 = max(s1, s0 + 1)
    rows, cols = np.nonzero(side_mask[:, run[0]:run[1]])
    xs, ys = cols + run[0] + 0.5, rows + 0.5
    far = np.argmax(np.abs(ys - place.y0))
    apex = np.array([xs[far], ys[far]])
    unit = place.s * sp.scale[1]
    base_x = place.x0 + s0 / (b - 1) * sp.scale[0] * place.s
    base_y = surface_row(sp, place, s0, side)
    dx, dy = apex[0] - base_x, abs(apex[1] - base_y)
    angle = float(np.clip(np.degrees(np.arctan2(dy, dx)), 15, 135))
    start = float(np.hypot(dx, dy) / unit)
    end_col = min(int(run[1]) - 1, side_mask.shape[1] - 1)
    col = np.flatnonzero(side_mask[:, end_col])
    end = float((np.abs(col + 0.5 - place.y0).max() - abs(base_y - place.y0)) / unit) if col.size else 0.02
    return with_fin(sp, name, replace(fin, start_section=s0, end_section=s1, start_length=max(start, 0.02),
                                   end_length=float(np.clip(end, 0.0, start)),
                                   start_angle=angle if side > 0 else -angle))


def _pelvic_from(sp: Species, run: tuple[int, int] | None, below: np.ndarray, place: Placement) -> Species:
    p: PelvicFin = sp.pelvic
    b = sp.body_sections
    if run is None:
        return replace(sp, pelvic=replace(p, start_length=0.0, end_length=0.0))
    lo, hi = PLACES["pelvic"]
    s0 = int(np.clip(round(_section_of(run[0], sp, place)), np.ceil(lo * (b - 1)), b - 3))
    rear = _section_of(run[1], sp, place)
    s1 = int(np.clip(round(s0 + 0.4 * (rear - s0)), s0 + 1, s0 + max(1, int(MAX_PELVIC_SPAN * (b - 1)))))
    rows, cols = np.nonzero(below[:, run[0]:run[1]])
    xs, ys = cols + run[0] + 0.5, rows + 0.5
    unit = place.s * sp.scale[1]
    far = np.argmax(ys + 0.3 * xs)
    tip = np.array([xs[far], ys[far]])
    base_x = place.x0 + s1 / (b - 1) * sp.scale[0] * place.s
    base_y = surface_row(sp, place, s1, -1.0)
    dx, dy = tip[0] - base_x, tip[1] - base_y
    angle = float(np.clip(np.degrees(np.arctan2(dy, max(dx, 1e-6))), 10, 100))
    front = below[:, run[0]:min(run[0] + 3, below.shape[1])]
    start = float(front.sum(axis=0).max() / unit) if front.size else 0.1
    return replace(sp, pelvic=replace(p, start_section=s0, end_section=s1, start_length=max(start, 0.02),
                                      end_length=float(max(np.hypot(dx, dy) / unit, 0.02)), end_angle=angle))


def holds(sp: Species, place: Placement, work: np.ndarray, body: Body) -> bool:
    """Whether these sections hold the photographed body: its outline drawn at these sections
    against the measured one, and every vertical fin the photo shows on two sections or more."""
    bare = body_mask(sp, place, work.shape)
    xc = np.arange(work.shape[1]) + 0.5
    rows = np.arange(work.shape[0])[:, None] + 0.5
    ok = ~np.isnan(body.half)
    half = np.where(ok, body.half, 0.0)
    centre = np.where(ok, body.centre, 0.0)
    measured = ok[None, :] & (np.abs(rows - centre[None, :]) <= half[None, :])
    span = (xc >= body.nose) & (xc <= body.tail_base)
    if iou(bare[:, span], measured[:, span]) < BODY_IOU:
        return False
    return all(getattr(sp, n).end_section - getattr(sp, n).start_section >= 2
               for n in ("dorsal", "anal") if getattr(sp, n).present)
