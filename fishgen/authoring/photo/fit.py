"""--fit-shape: a species whose side view is the photographed fish's, built on any base species.

Measured first (:mod:`.measure`), then refined (:mod:`.optimise`), each drawing the species as
the photo shows it (:mod:`.draw`); this module runs the steps and settles the result:

1. **Frame and body.** The silhouette is levelled head-left (:mod:`.frame`). Fins only add to a
   silhouette and a fishgen body is symmetric about its axis, so the body is no deeper than the
   nearer outline at each column; a smooth hump (:func:`.measure._hump`) fitted under those depths
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
from typing import TYPE_CHECKING

import numpy as np

from fishgen.authoring.photo.checks import attachment_problems, height_problems
from fishgen.authoring.photo.draw import (
    FIN_RECORDS,
    Drawer,
    Placement,
    draw,
    parts,
    shape_score,
    with_fin,
)
from fishgen.authoring.photo.measure import Body, holds, measure_body, measured, working_mask
from fishgen.authoring.photo.optimise import PARAMETERS, better, drop_hidden, refine, valid
from fishgen.authoring.photo.sideview import with_counts
from fishgen.species.model import Species

if TYPE_CHECKING:
    from fishgen.authoring.photo.frame import Frame

#: BodySections tried, in order, when the base's cannot hold the photographed body and fins.
LODS = (8, 12, 16, 20, 24, 32)
#: settled_tips: relative steps of a fin length, halved from the first down to the last
TIP_STEPS = (0.04, 0.005)
#: ...and of a fin angle, in degrees per unit of those steps (2 degrees down to 0.25)
TIP_DEGREES = 50.0


@dataclass(frozen=True)
class ShapeFit:
    species: Species
    iou: float                 # side view against the silhouette, in the working frame
    placement: Placement       # where the species lies on ``work``
    notes: tuple[str, ...]     # what was left out or changed, one line each
    #: the levelled silhouette the fit was made on (working scale)
    work: np.ndarray = field(repr=False, default_factory=lambda: np.zeros((1, 1), bool))
    frame: Frame | None = field(default=None, repr=False)     # the levelled frame
    frame_map: tuple[float, float, float, float] | None = None   # thesis -> frame: x0, y0, x scale, y scale
    turn: float = 0.0          # degrees the measured level was turned before fitting


def fit_shape(base: Species, mask: np.ndarray) -> Species:
    """The fitted species alone (see :func:`fit_species`)."""
    return fit_species(base, mask).species


def fit_species(base: Species, mask: np.ndarray, sections_fixed: bool = False, turn: float = 0.0,
                level: Frame | None = None) -> ShapeFit:
    """Fit ``base``'s geometry to the silhouette ``mask`` (any orientation; it is levelled here, or
    as the frame ``level`` of it says (:func:`.frame.fish_frame`, once for every level a caller
    tries, or :func:`.frame.other_level`), then turned ``turn`` degrees further: see
    :data:`.run.TURNS`)."""
    from fishgen.authoring.photo.frame import fish_frame, turned

    frame = turned(mask, level if level is not None else fish_frame(mask), turn)
    work, to_frame, offset = working_mask(frame.mask)
    body = measure_body(work)
    base = replace(base, texture_points=None, colour_texture=None, mask_texture=None)
    counts = [base.body_sections] if sections_fixed else \
        [base.body_sections] + [b for b in LODS if b > base.body_sections]
    # The level of detail is chosen on the measured fish, before the (slower) refinement.
    for b in counts:
        start = with_counts(base, b, None)
        first, place = measured(start, work, body)
        if holds(first, place, work, body):
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



def _fit_at(first: Species, place: Placement, work: np.ndarray, body: Body) -> ShapeFit:
    sp, place, _, score = refine(first, work, body, place)
    sp = drop_hidden(sp, work, place)
    return ShapeFit(sp, score, place, ())


#: Length fields of each fin record, shortened together when a fin stands past the photo's fish.
LENGTHS = {"caudal": ("top_line", "bottom_line", "middle_line"), "dorsal": ("start_length", "end_length"),
           "adipose": ("start_length", "end_length"), "anal": ("start_length", "end_length"),
           "pelvic": ("start_length", "end_length"), "pectoral": ("start_length",)}


def _attached(fit: ShapeFit) -> tuple[ShapeFit, list[str]]:
    """Keep the paired fins on the body while it swims. Each is hinged on the line from its first
    to its last base point, so a base curving round a deep body lifts its middle off the flank as
    it swings: the pectoral fin then spans one CircleSection less, the pelvic fin one BodySection
    less, and as a last resort the fin swings less (angle and step together: the same cycle)."""
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
            sp = with_fin(sp, name, replace(fin, movement_angle=fin.movement_angle * 0.6,
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


#: What the fin tips' searches move: every fin's lengths and angles but the pectoral's (never grown).
TIPS = [(r, n, kind) for r, n, kind in PARAMETERS if kind in ("length", "angle") and r != "pectoral"]


def _moved(sp: Species, record: str, name: str, kind: str, step: float) -> Species:
    """``sp`` with fin ``record``'s ``name`` (a length: x(1 + step); an angle: + step x TIP_DEGREES)."""
    fin = getattr(sp, record)
    value = getattr(fin, name)
    return with_fin(sp, record, replace(fin, **{
        name: value * (1.0 + step) if kind == "length" else value + step * TIP_DEGREES}))


def settled_tips(fit: ShapeFit, px_per_unit: float) -> ShapeFit:
    """``fit`` with its fin lengths searched again (a pattern search in steps of 4 % down to 0.5 %),
    the species drawn at ``px_per_unit`` pixels a thesis unit (the scale its render is measured
    at: :func:`.compare.render_scale`) against the levelled silhouette ``fit.frame.mask`` at its
    own scale, by the overlap the command reports. A fin this makes taller than the photographed
    fish keeps its length from before."""
    if fit.frame is None or fit.frame_map is None:
        return fit
    target = fit.frame.mask
    first = fit.species
    outline, fins = parts(first)
    pts = np.concatenate([outline, *[f for f, _ in fins]])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    margin = 0.25 * float((hi - lo).max()) * px_per_unit + 8   # room for fins to grow
    place = Placement(margin - lo[0] * px_per_unit, margin + hi[1] * px_per_unit, px_per_unit)
    shape = (int(np.ceil((hi[1] - lo[1]) * px_per_unit + 2 * margin)),
             int(np.ceil((hi[0] - lo[0]) * px_per_unit + 2 * margin)))
    score = shape_score(target)
    drawer = Drawer(first, place, shape)
    best = score(drawer.whole())
    sp, step = first, TIP_STEPS[0]
    while step >= TIP_STEPS[1]:
        improved = False
        for record, name, kind in TIPS:
            fin = getattr(sp, record)
            if record in ("dorsal", "anal", "adipose") and not fin.present:
                continue
            for k in (-step, step):
                trial = _moved(sp, record, name, kind, k)
                kept, best = better(drawer, score, sp, best, trial, record)
                improved |= kept is not sp
                sp = kept
        if not improved:
            step /= 2
    return _settled(fit, sp)


def _settled(fit: ShapeFit, sp: Species) -> ShapeFit:
    """``fit`` with its fins searched again into ``sp``, except a fin that then stands taller than
    the photographed fish (it keeps its size from before), and placed on the frame again."""
    first = fit.species
    if sp is first:
        return fit
    before = height_problems(first, fit.work, fit.placement)
    for problem in height_problems(sp, fit.work, fit.placement):
        tall = next((n for n in FIN_RECORDS if f" {n} fin " in problem), None)
        if problem not in before and tall is not None:
            sp = with_fin(sp, tall, getattr(first, tall))
    settled = replace(fit, species=sp, iou=shape_score(fit.work)(draw(sp, fit.placement, fit.work.shape)))
    assert fit.frame is not None   # fit_species sets it
    _, to_frame, offset = working_mask(fit.frame.mask)
    return replace(settled, frame_map=_frame_map(settled, to_frame, offset))


#: The perspective search's steps: fin lengths x(1 +- step), angles +- step x TIP_DEGREES.
PERSPECTIVE_STEPS = (0.08, 0.04, 0.02)


def settled_in_perspective(fit: ShapeFit, distance: float, size: tuple[int, int]) -> ShapeFit:
    """``fit`` with its fin lengths and angles searched again (not the pectoral's, which never
    grows) with the species rendered from ``distance`` fish lengths, as the photo was taken, against
    the levelled silhouette by the overlap the command reports. Seen from near, a paired fin that
    stands out towards the camera looks longer and lower than side-on: a fit drawn side-on takes
    that into the fin, and the fish then looks wrong from the photo's own camera (a 50 mm photo:
    0.84 against 0.94 side-on, in Blender)."""
    from fishgen.authoring.photo.compare import DRAWN_ALPHA, render_side, silhouette_iou
    from fishgen.preview.render import Renderer

    if fit.frame is None or fit.frame_map is None:
        return fit
    target = fit.frame.mask
    renderer = Renderer(*size)
    scores: dict[Species, float] = {}
    try:
        def score(species: Species) -> float:
            # a step that pays sends the search round again past trials it has already drawn
            # (about a fifth of them): each species is drawn once
            if species not in scores:
                drawn = render_side(species, *size, distance, renderer, coverage=True)
                scores[species] = silhouette_iou(target, drawn >= DRAWN_ALPHA)
            return scores[species]

        sp = fit.species
        best = score(sp)
        for step in PERSPECTIVE_STEPS:
            improved = True
            while improved:
                improved = False
                for record, name, kind in TIPS:
                    if record in ("dorsal", "anal", "adipose") and not getattr(sp, record).present:
                        continue
                    for k in (-step, step):
                        trial = _moved(sp, record, name, kind, k)
                        if valid(trial) and (value_ := score(trial)) > best + 1e-4:
                            sp, best, improved = trial, value_, True
    finally:
        renderer.release()
    return _settled(fit, sp)


def _trimmed(fit: ShapeFit) -> ShapeFit:
    """Shorten (x0.92 a step, at most 12 steps) any fin that stands past the photographed fish: the
    overlap may favour a fin tip over the line, but a fin taller than the fish is a broken fish."""
    sp = fit.species
    for _ in range(12):
        found = height_problems(sp, fit.work, fit.placement)
        tall = [n for n in FIN_RECORDS if any(f" {n} fin " in p for p in found)]
        if not tall:
            break
        for name in tall:
            fin = getattr(sp, name)
            sp = with_fin(sp, name, replace(fin, **{k: getattr(fin, k) * 0.92 for k in LENGTHS[name]}))
    if sp is fit.species:
        return fit
    return replace(fit, species=sp, iou=shape_score(fit.work)(draw(sp, fit.placement, fit.work.shape)))


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
