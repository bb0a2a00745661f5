"""--fit-shape's refinement: a pattern search on the overlap (IoU) of the species' side view with
the silhouette, drawn at about 360 px in the fish's frame: the body's length and axis, then each
fin's sections, lengths, angles and proportion. Moves that would break the fish (a fin off its
body's span, a caudal fin pointing forward, angles past the vertical) are refused (:func:`valid`).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from fishgen.authoring.photo.draw import Drawer, Placement, draw, redrawn, shape_score, with_fin
from fishgen.authoring.photo.measure import MAX_PELVIC_SPAN, PLACES, SPECK, Body, body_species
from fishgen.species.model import CaudalFin, Species, VerticalFin

MAX_SWEEPS = 10
MIN_STEP = 0.25


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


def refine(sp: Species, work: np.ndarray, body: Body,
            place: Placement) -> tuple[Species, Placement, float, float]:
    """Pattern search on the side view's overlap with the silhouette: keep a step while it pays,
    else halve it. The body (length, depth, axis) first, then each fin's parameters."""
    depth = 1.0
    score = shape_score(work)
    drawer = Drawer(sp, place, work.shape)
    best = score(drawer.whole())
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
                trial = body_species(sp, body, p2, depth2)
                if not valid(trial):
                    continue
                trial_drawer = Drawer(trial, p2, work.shape)
                value = score(trial_drawer.whole())
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
                trial = with_fin(sp, record, replace(getattr(sp, record), **{name: new_value}))
                kept, best = better(drawer, score, sp, best, trial, record)
                improved |= kept is not sp
                sp = kept
        if not improved:
            scale /= 2
            if scale < MIN_STEP:
                break
    return sp, place, depth, best


def better(drawer: Drawer, score, sp: Species, best: float, trial: Species,
           record: str) -> tuple[Species, float]:
    """``trial`` (``sp`` with fin ``record`` moved) and its score when it is valid and scores over
    ``best`` (``drawer`` then keeps its layers); else ``sp`` and ``best``."""
    if not valid(trial):
        return sp, best
    changed = redrawn(drawer, trial, record)
    value = score(drawer.whole(changed))
    if not value > best + 1e-4:
        return sp, best
    drawer.layers.update(changed)
    return trial, value


def drop_hidden(sp: Species, work: np.ndarray, place: Placement) -> Species:
    """A vertical fin the refinement shrank into the body (it adds under 0.2 % to the fish) goes."""
    whole = draw(sp, place, work.shape)
    for name in ("adipose", "dorsal", "anal"):
        fin: VerticalFin = getattr(sp, name)
        if not fin.present:
            continue
        without = with_fin(sp, name, replace(fin, start_length=0.0, end_length=0.0))
        if np.count_nonzero(whole & ~draw(without, place, work.shape)) < SPECK * np.count_nonzero(work):
            sp = without
    return sp
