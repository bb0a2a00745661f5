"""Fin layout fitted to the photo's silhouette: where each fin stands, how long and at what angle.

Coordinate descent on the overlap (IoU) of the species' side view, drawn at a
reduced scale in the fish's frame, with the photo's silhouette. Each step tries
a few moves of one parameter (sections by +-1..3, lengths by x0.7..1.4, angles
by +-5..20 degrees) and keeps the best; the moves shrink each sweep. A side view
is drawn in a few milliseconds, so a few hundred tries take seconds.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from fishgen.authoring.photo.anatomy import BodyOutline
from fishgen.authoring.photo.points import thesis_to_frame
from fishgen.authoring.photo.sideview import side_view
from fishgen.species.model import Species

#: Longest side of the drawings compared, in pixels.
WORK_SIDE = 320
SWEEPS = 3
LENGTH_STEPS = (0.7, 0.85, 1.15, 1.4)
ANGLE_STEPS = (-20.0, -10.0, -5.0, 5.0, 10.0, 20.0)
SECTION_STEPS = (-3, -2, -1, 1, 2, 3)

# (record, field, kind) of every fitted parameter; kinds: length, angle, section, share
PARAMETERS = (
    ("caudal", "top_line", "length"), ("caudal", "bottom_line", "length"),
    ("caudal", "middle_line", "length"),
    ("caudal", "top_angle", "angle"), ("caudal", "bottom_angle", "angle"),
    ("dorsal", "start_section", "section"), ("dorsal", "end_section", "section"),
    ("dorsal", "start_length", "length"), ("dorsal", "end_length", "length"),
    ("dorsal", "start_angle", "angle"), ("dorsal", "proportion", "share"),
    ("anal", "start_section", "section"), ("anal", "end_section", "section"),
    ("anal", "start_length", "length"), ("anal", "end_length", "length"),
    ("anal", "start_angle", "angle"), ("anal", "proportion", "share"),
    ("pelvic", "start_section", "section"), ("pelvic", "end_section", "section"),
    ("pelvic", "start_length", "length"), ("pelvic", "end_length", "length"),
    ("pelvic", "end_angle", "angle"),
)


def _valid(sp: Species) -> bool:
    b = sp.body_sections
    for name in ("dorsal", "anal", "adipose"):
        f = getattr(sp, name)
        if not 0 <= f.start_section < f.end_section <= b - 1:
            return False
        if not 0 < f.proportion <= 1:
            return False
    p = sp.pelvic
    return 0 <= p.start_section < p.end_section <= b - 1 and all(
        0 < v <= 20 for v in (sp.caudal.top_line, sp.caudal.bottom_line, sp.caudal.middle_line))


def _moves(value: float, kind: str, shrink: float) -> list[float]:
    if kind == "section":
        return [value + s for s in SECTION_STEPS if abs(s) <= max(1, round(3 * shrink))]
    if kind == "angle":
        return [value + s * shrink for s in ANGLE_STEPS]
    if kind == "share":
        return [min(1.0, value + s * shrink) for s in (-0.15, -0.05, 0.05)]
    return [value * (1 + (s - 1) * shrink) for s in LENGTH_STEPS]


def silhouette_score(outline: BodyOutline, target: np.ndarray, k: float) -> Callable[[Species], float]:
    """IoU of a species' side view with ``target`` (the frame mask drawn at ``k`` x scale)."""
    from PIL import Image, ImageDraw

    h, w = target.shape

    def score(sp: Species) -> float:
        view = side_view(sp)
        img = Image.new("L", (w, h), 0)
        draw = ImageDraw.Draw(img)
        xs = view.section_x()
        body = np.concatenate([np.stack([xs, view.top], 1), np.stack([xs, view.bottom], 1)[::-1]])
        draw.polygon([tuple(p) for p in (thesis_to_frame(outline, view, body) * k).tolist()], fill=255)
        for name, pts in view.fins.items():
            px = thesis_to_frame(outline, view, pts) * k
            for tri in view.fin_faces[name]:
                draw.polygon([tuple(p) for p in px[tri].tolist()], fill=255)
        drawn = np.asarray(img) >= 128
        union = (drawn | target).sum()
        return float((drawn & target).sum() / union) if union else 0.0

    return score


def fit_fins(species: Species, outline: BodyOutline, frame_mask: np.ndarray) -> tuple[Species, float]:
    """The fin layout whose side view best overlaps ``frame_mask``; returns it and its IoU."""
    from PIL import Image

    h, w = frame_mask.shape
    k = min(1.0, WORK_SIDE / max(h, w))
    small = np.asarray(Image.fromarray(frame_mask.astype(np.uint8) * 255).resize(
        (max(1, round(w * k)), max(1, round(h * k))), Image.Resampling.BILINEAR)) >= 128
    score = silhouette_score(outline, small, k)
    best, best_score = species, score(species)
    for sweep in range(SWEEPS):
        shrink = 1.0 / (1 + sweep)
        for record, name, kind in PARAMETERS:
            fin = getattr(best, record)
            if record in ("dorsal", "anal") and not fin.present:
                continue
            current = getattr(fin, name)
            for value in _moves(float(current), kind, shrink):
                new_value = int(value) if kind == "section" else value
                trial = replace(best, **{record: replace(fin, **{name: new_value})})
                if not _valid(trial):
                    continue
                s = score(trial)
                if s > best_score + 1e-4:
                    best, best_score = trial, s
                    fin = getattr(best, record)
    return best, best_score
