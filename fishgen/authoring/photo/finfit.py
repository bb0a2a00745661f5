"""Fin layout fitted to the photo's silhouette: where each fin stands, how long and at what angle.

Coordinate descent on the overlap (IoU) of the species' side view, drawn at a
reduced scale in the fish's frame, with the photo's silhouette. Each step tries
a few moves of one parameter (sections by +-1..3, lengths by x0.7..1.4, angles
by +-5..20 degrees) and keeps the best; the moves halve when a sweep finds nothing. A side view
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
MAX_SWEEPS = 8
MIN_STEP = 0.2
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
    ("pectoral", "start_length", "length"), ("pectoral", "start_angle", "angle"),
)


#: Where fins may stand, as shares of the body (the sampler's ranges, widened): without these the
#: descent would happily grow a pelvic fin under the head to stand in for a blunter profile.
PLACES = {"dorsal": (0.1, 0.95), "anal": (0.4, 0.97), "pelvic": (0.12, 0.7)}
MAX_PELVIC_SPAN = 0.3


def _valid(sp: Species) -> bool:
    b = sp.body_sections

    def share(k: int) -> float:
        return k / (b - 1)

    for name in ("dorsal", "anal", "adipose"):
        f = getattr(sp, name)
        if not 0 <= f.start_section < f.end_section <= b - 1 or not 0 < f.proportion <= 1:
            return False
        if name in PLACES and f.present:
            lo, hi = PLACES[name]
            if not (lo <= share(f.start_section) and share(f.end_section) <= hi):
                return False
    p = sp.pelvic
    lo, hi = PLACES["pelvic"]
    if not (0 <= p.start_section < p.end_section <= b - 1 and lo <= share(p.start_section)
            and share(p.end_section) <= hi and share(p.end_section - p.start_section) <= MAX_PELVIC_SPAN):
        return False
    return all(0 < v <= 20 for v in (sp.caudal.top_line, sp.caudal.bottom_line, sp.caudal.middle_line))


def _moves(value: float, kind: str, shrink: float) -> list[float]:
    if kind == "section":
        return [value + s for s in SECTION_STEPS if abs(s) <= max(1, round(3 * shrink))]
    if kind == "angle":
        return [value + s * shrink for s in ANGLE_STEPS]
    if kind == "share":
        return [min(1.0, value + s * shrink) for s in (-0.15, -0.05, 0.05)]
    return [value * (1 + (s - 1) * shrink) for s in LENGTH_STEPS]


def silhouette_score(outline: BodyOutline, target: np.ndarray, k: float,
                     pad: tuple[int, int]) -> Callable[[Species], float]:
    """IoU of a species' side view with ``target``: the frame mask drawn at ``k`` x scale inside a
    margin of ``pad`` (x, y) pixels, so a fin grown past the photo's edge still counts against it."""
    from PIL import Image, ImageDraw

    h, w = target.shape
    shift = np.array(pad, float)

    def score(sp: Species) -> float:
        view = side_view(sp)
        img = Image.new("L", (w, h), 0)
        draw = ImageDraw.Draw(img)
        xs = view.section_x()
        body = np.concatenate([np.stack([xs, view.top], 1), np.stack([xs, view.bottom], 1)[::-1]])
        outline_px = thesis_to_frame(outline, view, body) * k + shift
        draw.polygon([tuple(p) for p in outline_px.tolist()], fill=255)
        for name, pts in view.fins.items():
            px = thesis_to_frame(outline, view, pts) * k + shift
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
    pad = (small.shape[1] // 2, small.shape[0] // 2)
    score = silhouette_score(outline, np.pad(small, ((pad[1], pad[1]), (pad[0], pad[0]))), k, pad)
    best, best_score = species, score(species)
    scale = 1.0
    for _ in range(MAX_SWEEPS):   # pattern search: keep the step while it pays, else halve it
        improved = False
        for record, name, kind in PARAMETERS:
            fin = getattr(best, record)
            if record in ("dorsal", "anal") and not fin.present:
                continue
            current = getattr(fin, name)
            for value in _moves(float(current), kind, scale):
                new_value = int(value) if kind == "section" else value
                trial = replace(best, **{record: replace(fin, **{name: new_value})})
                if not _valid(trial):
                    continue
                s = score(trial)
                if s > best_score + 1e-4:
                    best, best_score, improved = trial, s, True
                    fin = getattr(best, record)
        if not improved:
            scale /= 2
            if scale < MIN_STEP:
                break
    return best, best_score
