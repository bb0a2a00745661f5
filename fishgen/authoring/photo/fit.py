"""--fit-shape: a species whose side view is the photographed fish's, built on any base species.

Measured first, then refined:

1. **Frame and body.** The silhouette is levelled head-left (:mod:`.frame`). Fins only add to a
   silhouette and a fishgen body is symmetric about its axis, so the body is no deeper than the
   nearer outline at each column; a smooth hump (:func:`_hump`) fitted under those depths
   bridges where fins stand on both sides. Its half-depth at every BodySection becomes a
   FishShapeSpline control point there, so the built body's outline (straight between sections)
   is the measured one. The body ends a little behind the tail base (the deepest neck).
2. **Fins from what is left.** Pixels outside the body are fin. Behind the tail base they are
   the caudal fin: its lobe tips and fork give the top, bottom and middle lines and angles.
   Runs above the back are the dorsal fin (the largest) and the adipose fin (a second one
   behind it); runs under the belly the pelvic fin (in front) and the anal fin (behind). A fin
   the photo does not show is left out (or, for the paired fins, which a file cannot omit,
   made zero-sized) and the caller says so.
3. **Refinement.** A pattern search on the overlap (IoU) of the species' side view with the
   silhouette, drawn at about 360 px in the fish's frame: the body's length, depth and axis,
   each fin's sections, lengths, angles and proportion. Moves that would break the fish (a fin
   off its body's span, a caudal fin pointing forward, angles past the vertical) are refused.
4. **Fin tips at the measuring scale** (:func:`settled_tips`). A thin fin tip narrower than a
   pixel is no longer drawn (a renderer fills the pixels whose centres it covers), so a
   silhouette's tips already end short, and the rebuilt fish, rendered again, loses them once
   more; the tips that bound the fish (the dorsal's thread, the pelvic's point) then shift every
   outline in the bounding-box overlap by pixels. So the fin lengths are settled last, drawn at
   the scale the rebuilt fish is rendered at and compared with the silhouette at its own.
5. **Level of detail.** When the base's BodySections cannot hold the body or place the fins
   (the measured body outline is matched with IoU under 0.97, or a fin would span under two
   sections), more sections are used (up to 32) unless the caller fixed them.

The body's width keeps the base's width-to-depth ratio; triangle counts, motion and behaviour
stay the base's. Everything here is pure numpy/scipy on masks and plain numbers.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from scipy import ndimage  # type: ignore[import-untyped]

from fishgen.authoring.photo import columns
from fishgen.authoring.photo.sideview import circle_sines
from fishgen.species.model import CaudalFin, PelvicFin, Species, VerticalFin

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
LODS = (8, 12, 16, 20, 24, 32)
MAX_SWEEPS = 10
MIN_STEP = 0.25
#: Where fins may stand, as shares of the body: (first, last) section share.
PLACES = {"dorsal": (0.08, 0.97), "adipose": (0.3, 0.97), "anal": (0.3, 0.97), "pelvic": (0.1, 0.75)}
MAX_PELVIC_SPAN = 0.35
#: Fin runs under the belly part where the fin pixels per column fall under this share of the
#: peaks on both sides (:func:`_valleys_out`).
VALLEY = 0.25
#: settled_tips: relative steps of a fin length, halved from the first down to the last
TIP_STEPS = (0.04, 0.005)
#: ...and of a fin angle, in degrees per unit of those steps (2 degrees down to 0.25)
TIP_DEGREES = 50.0


@dataclass(frozen=True)
class Placement:
    """Thesis units -> frame pixels: the nose at (x0, y0), the axis along row y0, ``s`` px per unit."""
    x0: float
    y0: float
    s: float

    def to_frame(self, xy: np.ndarray) -> np.ndarray:
        xy = np.asarray(xy, float)
        return np.stack([self.x0 + xy[:, 0] * self.s, self.y0 - xy[:, 1] * self.s], axis=1)


@dataclass(frozen=True)
class ShapeFit:
    species: Species
    iou: float                 # side view against the silhouette, in the working frame
    placement: Placement       # where the species lies on ``work``
    notes: tuple[str, ...]     # what was left out or changed, one line each
    #: the levelled silhouette the fit was made on (working scale)
    work: np.ndarray = field(repr=False, default_factory=lambda: np.zeros((1, 1), bool))
    frame: Any = field(default=None, repr=False)              # the levelled frame (:class:`.frame.Frame`)
    frame_map: tuple[float, float, float, float] | None = None   # thesis -> frame: x0, y0, x scale, y scale
    turn: float = 0.0          # degrees the measured level was turned before fitting


@dataclass(frozen=True)
class _Body:
    """The fin-free body measured on the working mask: half-depth and centre per column."""
    half: np.ndarray           # (W,) NaN outside the fish
    centre: np.ndarray
    nose: float                # first column
    tail_base: float           # the deepest neck's column
    area: int


def fit_shape(base: Species, mask: np.ndarray) -> Species:
    """The fitted species alone (see :func:`fit_species`)."""
    return fit_species(base, mask).species


def fit_species(base: Species, mask: np.ndarray, sections_fixed: bool = False, turn: float = 0.0) -> ShapeFit:
    """Fit ``base``'s geometry to the silhouette ``mask`` (any orientation; it is levelled here,
    then turned ``turn`` degrees further: see :data:`.run.TURNS`)."""
    from fishgen.authoring.photo.frame import fish_frame, turned

    frame = turned(mask, fish_frame(mask), turn)
    work, to_frame, offset = _working_mask(frame.mask)
    body = _measure_body(work)
    base = replace(base, texture_points=None, colour_texture=None, mask_texture=None)
    counts = [base.body_sections] if sections_fixed else \
        [base.body_sections] + [b for b in LODS if b > base.body_sections]
    # The level of detail is chosen on the measured fish, before the (slower) refinement.
    for b in counts:
        start = base if b == base.body_sections else _with_sections(base, b)
        first, place = _measured(start, work, body)
        if _holds(first, place, work, body):
            break
    fit = replace(_fit_at(first, place, work, body), work=work, frame=frame)
    fit = _trimmed(fit)
    fit, notes = _attached(fit)
    fit = replace(fit, frame_map=_frame_map(fit, to_frame, offset))
    for name in ("dorsal", "anal"):
        if getattr(base, name).present and not getattr(fit.species, name).present:
            notes.append(f"no {name} fin in the photo: left out")
    p = fit.species.pelvic
    if p.start_length == 0 and p.end_length == 0 and (base.pelvic.start_length or base.pelvic.end_length):
        notes.append("no pelvic fin in the photo: kept at zero size (a species file cannot leave it out)")
    fit = replace(fit, notes=tuple(notes), turn=turn)
    if fit.species.body_sections != base.body_sections:
        fit = replace(fit, notes=fit.notes + (
            f"BodySections {base.body_sections} -> {fit.species.body_sections}: the base's rings "
            "could not hold the photographed body and fins",))
    return fit


#: Length fields of each fin record, shortened together when a fin stands past the photo's fish.
LENGTHS = {"caudal": ("top_line", "bottom_line", "middle_line"), "dorsal": ("start_length", "end_length"),
           "adipose": ("start_length", "end_length"), "anal": ("start_length", "end_length"),
           "pelvic": ("start_length", "end_length"), "pectoral": ("start_length",)}


def _attached(fit: ShapeFit) -> tuple[ShapeFit, list[str]]:
    """Keep the paired fins on the body while it swims. Each is hinged on the line from its first
    to its last base point, so a base curving round a deep body lifts its middle off the flank as
    it swings: the pectoral fin then spans one CircleSection less, the pelvic fin one BodySection
    less, and as a last resort the fin swings less (angle and step together: the same cycle)."""
    from fishgen.authoring.photo.checks import attachment_problems

    sp = fit.species
    for _ in range(8):
        problems = attachment_problems(sp)
        if not problems:
            break
        q, p = sp.pectoral, sp.pelvic
        if "pectoral" in problems[0] and q.triangles > 1:
            sp = replace(sp, pectoral=replace(q, triangles=q.triangles - 1))
        elif "pelvic" in problems[0] and p.end_section - p.start_section > 1:
            sp = replace(sp, pelvic=replace(p, end_section=p.end_section - 1))
        else:
            name = "pectoral" if "pectoral" in problems[0] else "pelvic"
            fin = getattr(sp, name)
            sp = _with(sp, name, replace(fin, movement_angle=fin.movement_angle * 0.6,
                                         step_size=fin.step_size * 0.6))
    if sp is fit.species:
        return fit, []
    was, notes = fit.species, []
    if sp.pectoral.triangles != was.pectoral.triangles:
        notes.append(f"the pectoral fin spans {sp.pectoral.triangles} CircleSections, not "
                     f"{was.pectoral.triangles}, to stay on the body while swimming")
    if sp.pelvic.end_section != was.pelvic.end_section:
        notes.append(f"the pelvic fin ends on BodySection {sp.pelvic.end_section}, not "
                     f"{was.pelvic.end_section}, to stay on the body while swimming")
    for name in ("pectoral", "pelvic"):
        before, after = getattr(was, name).movement_angle, getattr(sp, name).movement_angle
        if after != before:
            notes.append(f"the {name} fin swings {after:.3g} degrees, not {before:.3g}, to stay on the body")
    return replace(fit, species=sp), notes


def settled_tips(fit: ShapeFit, px_per_unit: float) -> ShapeFit:
    """``fit`` with its fin lengths searched again (a pattern search in steps of 4 % down to 0.5 %),
    the species drawn at ``px_per_unit`` pixels a thesis unit (the scale its render is measured
    at: :func:`.compare.render_scale`) against the levelled silhouette ``fit.frame.mask`` at its
    own scale, by the overlap the command reports. A fin this makes taller than the photographed
    fish keeps its length from before."""
    from fishgen.authoring.photo.checks import height_problems

    if fit.frame is None or fit.frame_map is None:
        return fit
    target = fit.frame.mask
    first = fit.species
    outline, fins = _parts(first)
    pts = np.concatenate([outline, *[f for f, _ in fins]])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    margin = 0.25 * float((hi - lo).max()) * px_per_unit + 8   # room for fins to grow
    place = Placement(margin - lo[0] * px_per_unit, margin + hi[1] * px_per_unit, px_per_unit)
    shape = (int(np.ceil((hi[1] - lo[1]) * px_per_unit + 2 * margin)),
             int(np.ceil((hi[0] - lo[0]) * px_per_unit + 2 * margin)))
    score = _shape_score(target)
    drawer = _Drawer(first, place, shape)
    best = score(drawer.whole())
    sp, step = first, TIP_STEPS[0]
    tuned = [(r, n, kind) for r, n, kind in PARAMETERS if kind in ("length", "angle") and r != "pectoral"]
    while step >= TIP_STEPS[1]:
        improved = False
        for record, name, kind in tuned:
            fin = getattr(sp, record)
            if record in ("dorsal", "anal", "adipose") and not fin.present:
                continue
            for k in (-step, step):
                value = getattr(fin, name)
                trial = _with(sp, record, replace(fin, **{
                    name: value * (1.0 + k) if kind == "length" else value + k * TIP_DEGREES}))
                if not valid(trial):
                    continue
                changed = _redrawn(drawer, trial, record)
                value = score(drawer.whole(changed))
                if value > best + 1e-4:
                    sp, best, improved = trial, value, True
                    drawer.layers.update(changed)
                    fin = getattr(sp, record)
        if not improved:
            step /= 2
    if sp is first:
        return fit
    before = height_problems(first, fit.work, fit.placement)
    for problem in height_problems(sp, fit.work, fit.placement):
        tall = next((n for n in FIN_RECORDS if f" {n} fin " in problem), None)
        if problem not in before and tall is not None:
            sp = _with(sp, tall, getattr(first, tall))
    settled = replace(fit, species=sp, iou=_shape_score(fit.work)(draw(sp, fit.placement, fit.work.shape)))
    _, to_frame, offset = _working_mask(target)
    return replace(settled, frame_map=_frame_map(settled, to_frame, offset))


def _trimmed(fit: ShapeFit) -> ShapeFit:
    """Shorten (x0.92 a step, at most 12 steps) any fin that stands past the photographed fish: the
    overlap may favour a fin tip over the line, but a fin taller than the fish is a broken fish."""
    from fishgen.authoring.photo.checks import height_problems

    sp = fit.species
    for _ in range(12):
        found = height_problems(sp, fit.work, fit.placement)
        tall = [n for n in FIN_RECORDS if any(f" {n} fin " in p for p in found)]
        if not tall:
            break
        for name in tall:
            fin = getattr(sp, name)
            sp = _with(sp, name, replace(fin, **{k: getattr(fin, k) * 0.92 for k in LENGTHS[name]}))
    if sp is fit.species:
        return fit
    return replace(fit, species=sp, iou=_shape_score(fit.work)(draw(sp, fit.placement, fit.work.shape)))


def _frame_map(fit: ShapeFit, to_frame: float, offset: np.ndarray) -> tuple[float, float, float, float]:
    """Where the fitted fish lies on the frame. The overlap compares bounding boxes, so the fit
    pins proportions, not place and size: the drawing's box is mapped onto the silhouette's (as
    the overlap maps it), then the working pixels onto the frame's."""
    drawn = draw(fit.species, fit.placement, fit.work.shape)
    d_rows, d_cols = np.flatnonzero(drawn.any(axis=1)), np.flatnonzero(drawn.any(axis=0))
    t_rows, t_cols = np.flatnonzero(fit.work.any(axis=1)), np.flatnonzero(fit.work.any(axis=0))
    ax = (t_cols[-1] + 1 - t_cols[0]) / (d_cols[-1] + 1 - d_cols[0])
    ay = (t_rows[-1] + 1 - t_rows[0]) / (d_rows[-1] + 1 - d_rows[0])
    p = fit.placement
    x0 = t_cols[0] + (p.x0 - d_cols[0]) * ax
    y0 = t_rows[0] + (p.y0 - d_rows[0]) * ay
    return (float(x0 * to_frame + offset[0]), float(y0 * to_frame + offset[1]),
            float(p.s * ax * to_frame), float(p.s * ay * to_frame))


def body_outline(fit: ShapeFit, width: int):
    """The fitted body as :mod:`.anatomy` describes one (:class:`.anatomy.BodyOutline`) in the
    frame's pixels, so Fixel's points are measured where the fitted fish lies on the photo."""
    from fishgen.authoring.photo.anatomy import BodyOutline
    from fishgen.geometry.body import ring_positions
    from fishgen.geometry.shapes import profile_for

    sp = fit.species
    assert fit.frame_map is not None
    x0, y0, kx, ky = fit.frame_map
    rings, _ = ring_positions(profile_for(sp.shape_class, sp.shape_params), sp.body_sections,
                              sp.circle_sections, sp.scale)
    xs = x0 + rings[:, 0, 0] * kx
    cols = np.arange(width) + 0.5
    inside = (cols >= xs[0]) & (cols <= xs[-1])
    upper = np.where(inside, np.interp(cols, xs, rings[:, :, 1].max(axis=1) * ky), np.nan)
    lower = np.where(inside, np.interp(cols, xs, -rings[:, :, 1].min(axis=1) * ky), np.nan)
    none = np.zeros(width, bool)
    return BodyOutline(float(xs[0]), float(xs[-1]), y0, 0.0, upper, lower, none, none.copy(), ky)


def _with(sp: Species, record: str, fin: Any) -> Species:
    """``sp`` with fin record ``record`` replaced."""
    changes: dict[str, Any] = {record: fin}
    return replace(sp, **changes)


def _with_sections(base: Species, sections: int) -> Species:
    from fishgen.authoring.photo.run import with_counts

    return with_counts(base, sections, None)


def _working_mask(frame_mask: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
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


def _measure_body(work: np.ndarray) -> _Body:
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
    return _Body(half, centre, float(nose[0]), float(ped[0]), int(work.sum()))


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


# ----------------------------------------------------------------------------- geometry


def _reach(circles: int) -> float:
    s = circle_sines(circles)
    return float(0.5 * (s.max() - s.min()))


def _body_species(sp: Species, body: _Body, place: Placement, depth: float) -> Species:
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
    radius = half / (_reach(sp.circle_sections) * place.s)      # thesis units (r * scaleY)
    sy = float(radius.max() / 0.5)
    r = np.clip(radius / sy, 1e-3, 10.0)
    params = tuple(round(float(v), 5) for pair in zip(u, r, strict=True) for v in pair)
    width = sp.scale[2] / sp.scale[1]
    return replace(sp, shape_class="FishShapeSpline", shape_params=params,
                   scale=(sx, round(sy, 6), round(sy * width, 6)))


def _parts(sp: Species) -> tuple[np.ndarray, list[tuple[np.ndarray, np.ndarray]]]:
    """(body outline polygon, [(fin vertices, faces)]) of the built fish's side view, thesis units."""
    from fishgen.assembly.fins import build_fins
    from fishgen.geometry.body import ring_positions
    from fishgen.geometry.shapes import profile_for

    rings, _ = ring_positions(profile_for(sp.shape_class, sp.shape_params), sp.body_sections,
                              sp.circle_sections, sp.scale)
    xs = rings[:, 0, 0]
    outline = np.concatenate([np.stack([xs, rings[:, :, 1].max(axis=1)], 1),
                              np.stack([xs, rings[:, :, 1].min(axis=1)], 1)[::-1]])
    built = build_fins(replace(sp, texture_points=None), rings)
    fins = [(f.mesh.positions[:, :2], f.mesh.faces) for f in built]
    return outline, fins


def draw(sp: Species, place: Placement, shape: tuple[int, int]) -> np.ndarray:
    """The built fish's side view as a mask of ``shape`` (rows down) in the working frame."""
    from PIL import Image, ImageDraw

    outline, fins = _parts(sp)
    img = Image.new("L", (shape[1], shape[0]), 0)
    pen = ImageDraw.Draw(img)
    pen.polygon([tuple(p) for p in place.to_frame(outline).tolist()], fill=255)
    for pts, faces in fins:
        px = place.to_frame(pts)
        for tri in faces:
            pen.polygon([tuple(p) for p in px[tri].tolist()], fill=255)
    return np.asarray(img) >= 128


def _iou(a: np.ndarray, b: np.ndarray) -> float:
    union = np.count_nonzero(a | b)
    return float(np.count_nonzero(a & b) / union) if union else 0.0


def _shape_score(target: np.ndarray):
    """The overlap the command reports (:func:`.compare.silhouette_iou`: each silhouette cropped to
    its bounding box, the drawing scaled onto the target's), for drawings against ``target``."""
    from PIL import Image

    ys, xs = np.nonzero(target)
    crop = target[ys.min():ys.max() + 1, xs.min():xs.max() + 1]
    size = (crop.shape[1], crop.shape[0])

    def score(drawn: np.ndarray) -> float:
        rows, cols = np.flatnonzero(drawn.any(axis=1)), np.flatnonzero(drawn.any(axis=0))
        if rows.size == 0:
            return 0.0
        part = drawn[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1]
        img = Image.fromarray(part.astype(np.uint8) * 255).resize(size, Image.Resampling.BILINEAR)
        return _iou(crop, np.asarray(img) >= 128)

    return score


# ----------------------------------------------------------------------------- measuring fins


def _measured(base: Species, work: np.ndarray, body: _Body) -> tuple[Species, Placement]:
    """The body and every fin read off the silhouette, before any refinement."""
    sx = base.scale[0]
    length_px = (body.tail_base - body.nose) / TAIL_BASE   # the tail point lies just behind it
    y0 = float(np.nanmedian(body.centre))
    place = Placement(body.nose, y0, length_px / sx)
    sp = _body_species(base, body, place, 1.0)
    return _measured_fins(sp, work, body, place), place


def _fit_at(first: Species, place: Placement, work: np.ndarray, body: _Body) -> ShapeFit:
    sp, place, _, score = _refine(first, work, body, place)
    sp = _drop_hidden(sp, work, place)
    return ShapeFit(sp, score, place, ())


def _section_of(x_px: float, sp: Species, place: Placement) -> float:
    return (x_px - place.x0) / (sp.scale[0] * place.s) * (sp.body_sections - 1)


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """[start, end) of every run of True."""
    d = np.diff(np.r_[0, flags.astype(np.int8), 0])
    return list(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist(), strict=True))


def _measured_fins(sp: Species, work: np.ndarray, body: _Body, place: Placement) -> Species:
    """Every fin's place and size read off the silhouette outside the body."""
    h, w = work.shape
    drawn_body = _body_mask(sp, place, work.shape)
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
    runs_up.sort(key=lambda r: -int(up[r[0]:r[1]].sum()))
    dorsal = runs_up[0] if runs_up else None
    adipose = next((r for r in runs_up[1:] if dorsal is not None and r[0] > dorsal[1]), None)
    sp = _vertical_from(sp, "dorsal", dorsal, above, place, 1.0)
    sp = _vertical_from(sp, "adipose", adipose, above, place, 1.0)
    runs_down.sort(key=lambda r: r[0])
    def centre(r: tuple[int, int]) -> float:
        return ((r[0] + r[1]) / 2 - place.x0) / length

    def size(r: tuple[int, int]) -> int:
        return int(down[r[0]:r[1]].sum())

    front = [r for r in runs_down if centre(r) < 0.55]
    pelvic = max(front, key=size) if front else None
    back = [r for r in runs_down if centre(r) > 0.45 and r is not pelvic]
    anal = max(back, key=size) if back else None
    sp = _vertical_from(sp, "anal", anal, below, place, -1.0)
    sp = _pelvic_from(sp, pelvic, below, place)
    return sp


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


def _body_mask(sp: Species, place: Placement, shape: tuple[int, int]) -> np.ndarray:
    from PIL import Image, ImageDraw

    no_tail = replace(sp.caudal, top_line=0.0, bottom_line=0.0, middle_line=0.0)
    outline, _ = _parts(replace(sp, caudal=no_tail))
    img = Image.new("L", (shape[1], shape[0]), 0)
    ImageDraw.Draw(img).polygon([tuple(p) for p in place.to_frame(outline).tolist()], fill=255)
    return np.asarray(img) >= 128


def _caudal_from(sp: Species, outside: np.ndarray, body: _Body, place: Placement) -> Species:
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
        return _with(sp, name, replace(fin, start_length=0.0, end_length=0.0))
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
    base_y = _surface_row(sp, place, s0, side)
    dx, dy = apex[0] - base_x, abs(apex[1] - base_y)
    angle = float(np.clip(np.degrees(np.arctan2(dy, dx)), 15, 135))
    start = float(np.hypot(dx, dy) / unit)
    end_col = min(int(run[1]) - 1, side_mask.shape[1] - 1)
    col = np.flatnonzero(side_mask[:, end_col])
    end = float((np.abs(col + 0.5 - place.y0).max() - abs(base_y - place.y0)) / unit) if col.size else 0.02
    return _with(sp, name, replace(fin, start_section=s0, end_section=s1, start_length=max(start, 0.02),
                                   end_length=float(np.clip(end, 0.0, start)),
                                   start_angle=angle if side > 0 else -angle))


def _surface_row(sp: Species, place: Placement, section: int, side: float) -> float:
    from fishgen.geometry.shapes import profile_for

    r = float(profile_for(sp.shape_class, sp.shape_params)(np.array([section / (sp.body_sections - 1)]))[0])
    return place.y0 - side * r * sp.scale[1] * _reach(sp.circle_sections) * place.s


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
    base_y = _surface_row(sp, place, s1, -1.0)
    dx, dy = tip[0] - base_x, tip[1] - base_y
    angle = float(np.clip(np.degrees(np.arctan2(dy, max(dx, 1e-6))), 10, 100))
    front = below[:, run[0]:min(run[0] + 3, below.shape[1])]
    start = float(front.sum(axis=0).max() / unit) if front.size else 0.1
    return replace(sp, pelvic=replace(p, start_section=s0, end_section=s1, start_length=max(start, 0.02),
                                      end_length=float(max(np.hypot(dx, dy) / unit, 0.02)), end_angle=angle))


# ----------------------------------------------------------------------------- refinement

# (record, field, kind) of every refined fin parameter; kinds: length, angle, section, share
PARAMETERS = (
    ("caudal", "top_line", "length"), ("caudal", "bottom_line", "length"),
    ("caudal", "middle_line", "length"),
    ("caudal", "top_angle", "angle"), ("caudal", "bottom_angle", "angle"),
    ("dorsal", "start_section", "section"), ("dorsal", "end_section", "section"),
    ("dorsal", "start_length", "length"), ("dorsal", "end_length", "length"),
    ("dorsal", "start_angle", "angle"), ("dorsal", "proportion", "share"),
    ("adipose", "start_section", "section"), ("adipose", "end_section", "section"),
    ("adipose", "start_length", "length"), ("adipose", "end_length", "length"),
    ("adipose", "start_angle", "angle"),
    ("anal", "start_section", "section"), ("anal", "end_section", "section"),
    ("anal", "start_length", "length"), ("anal", "end_length", "length"),
    ("anal", "start_angle", "angle"), ("anal", "proportion", "share"),
    ("pelvic", "start_section", "section"), ("pelvic", "end_section", "section"),
    ("pelvic", "start_length", "length"), ("pelvic", "end_length", "length"),
    ("pelvic", "end_angle", "angle"),
    ("pectoral", "start_length", "length"), ("pectoral", "start_angle", "angle"),
)
LENGTH_STEPS = (0.7, 0.85, 1.15, 1.4)
ANGLE_STEPS = (-20.0, -8.0, 8.0, 20.0)
SECTION_STEPS = (-3, -2, -1, 1, 2, 3)


def _moves(value: float, kind: str, shrink: float) -> list[float]:
    if kind == "section":
        return [value + s for s in SECTION_STEPS if abs(s) <= max(1, round(3 * shrink))]
    if kind == "angle":
        return [value + s * shrink for s in ANGLE_STEPS]
    if kind == "share":
        return [min(1.0, value + s * shrink) for s in (-0.15, -0.05, 0.05)]
    return [value * (1 + (s - 1) * shrink) for s in LENGTH_STEPS]


def valid(sp: Species) -> bool:
    """Whether a fitted species keeps every fin on its body and pointing the way it should."""
    b = sp.body_sections

    def share(k: int) -> float:
        return k / (b - 1)

    for name in ("dorsal", "adipose", "anal"):
        f: VerticalFin = getattr(sp, name)
        if not f.present:
            continue
        lo, hi = PLACES[name]
        if not (1 <= f.start_section < f.end_section <= b - 2 and lo <= share(f.start_section)
                and share(f.end_section) <= hi and 0.3 <= f.proportion <= 1
                and 10 <= abs(f.start_angle) <= 140
                and f.end_length <= max(f.start_length, 0.05) * 1.5):
            return False
    p = sp.pelvic
    lo, hi = PLACES["pelvic"]
    if not (1 <= p.start_section < p.end_section <= b - 2 and lo <= share(p.start_section)
            and share(p.end_section) <= hi and share(p.end_section - p.start_section) <= MAX_PELVIC_SPAN
            and 0 <= p.end_angle <= 120):
        return False
    c: CaudalFin = sp.caudal
    if not (all(0 < v <= 20 for v in (c.top_line, c.bottom_line, c.middle_line))
            and 3 <= c.top_angle <= 88 and 3 <= c.bottom_angle <= 88):
        return False
    q = sp.pectoral
    return 0 <= q.start_length <= 20 and -45 <= q.start_angle <= 70


class _Drawer:
    """Draws a species' side view part by part, so a move of one fin redraws only that fin."""

    def __init__(self, sp: Species, place: Placement, shape: tuple[int, int]):
        from fishgen.geometry.body import ring_positions
        from fishgen.geometry.shapes import profile_for

        self.place, self.shape = place, shape
        self.rings, _ = ring_positions(profile_for(sp.shape_class, sp.shape_params), sp.body_sections,
                                       sp.circle_sections, sp.scale)
        xs = self.rings[:, 0, 0]
        outline = np.concatenate([np.stack([xs, self.rings[:, :, 1].max(axis=1)], 1),
                                  np.stack([xs, self.rings[:, :, 1].min(axis=1)], 1)[::-1]])
        self.body = self._polygons([outline])
        self.layers: dict[str, np.ndarray] = {}
        self.sp = sp
        for name in FIN_RECORDS:
            self.layers[name] = self.fin(sp, name)

    def _polygons(self, polys: list[np.ndarray]) -> np.ndarray:
        from PIL import Image, ImageDraw

        img = Image.new("L", (self.shape[1], self.shape[0]), 0)
        pen = ImageDraw.Draw(img)
        for poly in polys:
            pen.polygon([tuple(p) for p in self.place.to_frame(poly).tolist()], fill=255)
        return np.asarray(img) >= 128

    def _triangles(self, parts: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
        from PIL import Image, ImageDraw

        img = Image.new("L", (self.shape[1], self.shape[0]), 0)
        pen = ImageDraw.Draw(img)
        for pts, faces in parts:
            px = self.place.to_frame(pts).tolist()
            for a, b, c in faces.tolist():
                pen.polygon([tuple(px[a]), tuple(px[b]), tuple(px[c])], fill=255)
        return np.asarray(img) >= 128

    def fin(self, sp: Species, name: str) -> np.ndarray:
        """One fin's layer, built as :func:`fishgen.assembly.fins.build_fins` builds it."""
        from fishgen.assembly.fins import caudal_params, pectoral_params, pelvic_params, vertical_params
        from fishgen.geometry.fins import caudal_fin, pectoral_fin, pelvic_fin, vertical_fin

        s = np.asarray(sp.scale, float)
        rings = self.rings
        built = []
        if name in ("caudal", "dorsal", "adipose", "anal"):
            caudal = caudal_fin(caudal_params(sp.caudal), s, None, tail_x=float(rings[-1, :, 0].max()))
            if name == "caudal":
                built = [caudal]
            elif getattr(sp, name).present:
                # as build_fins does: a vertical fin ends on the last section in front of the caudal fin
                params = vertical_params(getattr(sp, name))
                side = -1.0 if name == "anal" else 1.0
                front = float(caudal.mesh.positions[:, 0].min()) if len(caudal.mesh.faces) else np.inf
                fin = vertical_fin(name, params, rings, s, side)
                while (fin.mesh.positions[:, 0].max() > front + 1e-9
                       and params.end_section > params.start_section + 1):
                    params = replace(params, end_section=params.end_section - 1)
                    fin = vertical_fin(name, params, rings, s, side)
                if fin.mesh.positions[:, 0].max() <= front + 1e-9:
                    built = [fin]
        elif name == "pectoral":
            built = [pectoral_fin(pectoral_params(sp.pectoral), rings, s)]
        else:
            built = [pelvic_fin(pelvic_params(sp.pelvic), rings, s)]
        return self._triangles([(f.mesh.positions[:, :2], f.mesh.faces) for f in built])

    def whole(self, replaced: dict[str, np.ndarray] | None = None) -> np.ndarray:
        out = self.body.copy()
        for name, layer in self.layers.items():
            out |= (replaced or {}).get(name, layer)
        return out


FIN_RECORDS = ("caudal", "dorsal", "adipose", "anal", "pectoral", "pelvic")


def _refine(sp: Species, work: np.ndarray, body: _Body,
            place: Placement) -> tuple[Species, Placement, float, float]:
    """Pattern search on the side view's overlap with the silhouette: keep a step while it pays,
    else halve it. The body (length, depth, axis) first, then each fin's parameters."""
    depth = 1.0
    shape_score = _shape_score(work)
    drawer = _Drawer(sp, place, work.shape)
    best = shape_score(drawer.whole())
    scale = 1.0
    for _ in range(MAX_SWEEPS):
        improved = False
        # (no overall depth: the overlap is measured between bounding boxes, blind to the aspect,
        # which the measured body already has right)
        for kind in ("length", "axis"):
            for step in (-1.0, 1.0):
                d = step * scale
                p2, depth2 = place, depth
                if kind == "length":
                    p2 = replace(place, s=place.s * (1 + 0.02 * d))
                elif kind == "depth":
                    depth2 = depth * (1 + 0.04 * d)
                else:
                    p2 = replace(place, y0=place.y0 + 0.004 * d * place.s * sp.scale[0])
                trial = _body_species(sp, body, p2, depth2)
                if not valid(trial):
                    continue
                trial_drawer = _Drawer(trial, p2, work.shape)
                value = shape_score(trial_drawer.whole())
                if value > best + 1e-4:
                    sp, place, depth, best, improved, drawer = trial, p2, depth2, value, True, trial_drawer
        for record, name, kind in PARAMETERS:
            fin = getattr(sp, record)
            if record in ("dorsal", "anal", "adipose") and not fin.present:
                continue
            if record == "pelvic" and fin.start_length == 0 and fin.end_length == 0:
                continue
            current = getattr(fin, name)
            for value in _moves(float(current), kind, scale):
                if record == "pectoral" and name == "start_length" and value > current:
                    continue   # it lies over the flank: never grown to stand in for something else
                new_value = int(value) if kind == "section" else value
                if kind == "angle" and name == "start_angle" and current < 0:
                    new_value = min(value, -1e-3)
                trial = _with(sp, record, replace(fin, **{name: new_value}))
                if not valid(trial):
                    continue
                changed = _redrawn(drawer, trial, record)
                s = shape_score(drawer.whole(changed))
                if s > best + 1e-4:
                    sp, best, improved = trial, s, True
                    drawer.layers.update(changed)
                    fin = getattr(sp, record)
        if not improved:
            scale /= 2
            if scale < MIN_STEP:
                break
    return sp, place, depth, best


def _redrawn(drawer: _Drawer, trial: Species, record: str) -> dict[str, np.ndarray]:
    """The layers a change to fin ``record`` redraws: the caudal fin's moves the vertical fins too,
    which end in front of it."""
    changed = {record: drawer.fin(trial, record)}
    if record == "caudal":
        changed.update({n: drawer.fin(trial, n) for n in ("dorsal", "adipose", "anal")})
    return changed


def _drop_hidden(sp: Species, work: np.ndarray, place: Placement) -> Species:
    """A vertical fin the refinement shrank into the body (it adds under 0.2 % to the fish) goes."""
    whole = draw(sp, place, work.shape)
    for name in ("adipose", "dorsal", "anal"):
        fin: VerticalFin = getattr(sp, name)
        if not fin.present:
            continue
        without = _with(sp, name, replace(fin, start_length=0.0, end_length=0.0))
        if np.count_nonzero(whole & ~draw(without, place, work.shape)) < SPECK * np.count_nonzero(work):
            sp = without
    return sp


def _holds(sp: Species, place: Placement, work: np.ndarray, body: _Body) -> bool:
    """Whether these sections hold the photographed body: its outline drawn at these sections
    against the measured one, and every vertical fin the photo shows on two sections or more."""
    bare = _body_mask(sp, place, work.shape)
    xc = np.arange(work.shape[1]) + 0.5
    rows = np.arange(work.shape[0])[:, None] + 0.5
    ok = ~np.isnan(body.half)
    half = np.where(ok, body.half, 0.0)
    centre = np.where(ok, body.centre, 0.0)
    measured = ok[None, :] & (np.abs(rows - centre[None, :]) <= half[None, :])
    span = (xc >= body.nose) & (xc <= body.tail_base)
    if _iou(bare[:, span], measured[:, span]) < BODY_IOU:
        return False
    return all(getattr(sp, n).end_section - getattr(sp, n).start_section >= 2
               for n in ("dorsal", "anal") if getattr(sp, n).present)
