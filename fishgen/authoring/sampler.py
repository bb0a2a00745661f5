"""Plausible new species by seed: every parameter drawn within the ranges the thesis' BonyBream
(Appendix A) and the three shipped designs span, widened a little (docs/decisions.md lists them).

Draws are independent where the thesis treats them so; where one value bounds
another (a fin's sections inside the body, a pectoral's triangles inside a
quarter ring, fin cycles that loop together) the dependent one is drawn inside
the bound, so every sample is a valid, buildable species.
"""
from __future__ import annotations

import colorsys
from dataclasses import dataclass

import numpy as np

from fishgen.authoring.painter import PATTERNS, Palette
from fishgen.species.model import Behaviour, CaudalFin, PectoralFin, PelvicFin, Species, VerticalFin

#: (low, high) of every drawn value; fractions of BodySections / CircleSections where marked.
RANGES: dict[str, tuple[float, float]] = {
    "world_scale": (15.0, 26.0),
    "scale_x": (0.12, 0.4),
    "depth_ratio": (0.3, 0.7),          # scaleY / scaleX
    "width_ratio": (0.35, 0.7),         # scaleZ / scaleY
    "profile_peak_x": (0.25, 0.5),      # where the spline body is deepest
    "profile_peak_r": (0.36, 0.5),
    "caudal_line": (0.4, 1.3),
    "caudal_middle": (0.13, 0.4),
    "caudal_angle": (28.0, 78.0),
    "caudal_connection": (0.92, 0.95),
    "dorsal_start": (0.2, 0.45),        # x BodySections
    "dorsal_end": (0.6, 0.8),
    "dorsal_length": (0.45, 1.3),
    "dorsal_end_length": (0.05, 0.15),
    "dorsal_angle": (62.0, 80.0),
    "dorsal_proportion": (0.7, 0.98),
    "anal_start": (0.55, 0.8),
    "anal_end": (0.8, 0.93),
    "anal_length": (0.18, 0.6),
    "anal_end_length": (0.01, 0.1),
    "anal_angle": (-70.0, -55.0),
    "anal_proportion": (0.85, 0.9),
    "pelvic_circle": (0.79, 0.92),      # x CircleSections: low on the left flank
    "pelvic_start": (0.25, 0.45),
    "pelvic_span": (0.09, 0.2),         # x BodySections, as BonyBream's 4-7 of 16 .. goldie's 6-8 of 24
    "pelvic_length": (0.1, 0.5),
    "pelvic_end_length": (0.3, 0.8),   # threadfin goldie's 1.1 filament read as a wing on deep bodies
    "pelvic_angle": (55.0, 90.0),
    "pectoral_start": (0.2, 0.33),
    "pectoral_circle": (0.04, 0.17),
    "pectoral_length": (0.45, 0.95),
    "pectoral_angle": (5.0, 12.0),
    "pectoral_proportion": (0.7, 0.75),
    "caudal_swing": (9.0, 15.0),        # degrees
    "paired_swing": (4.0, 10.0),
    "speed": (0.5, 0.9),
    "transparency": (0.6, 1.0),
}
BODY_SECTIONS = (8, 12, 16, 20, 24, 32)
CIRCLE_SECTIONS = (6, 8, 12, 16, 24)
SHAPES = ("FishShapeSpline", "FishShapeSpline", "FishShapeSpline", "FishShapeSin", "FishShapeHawk")
#: Frames of the caudal fin's beat; the paired fins beat at half, the same or twice its period,
#: so the swim clip loops after at most two caudal beats.
CAUDAL_PERIODS = (24, 32, 40, 48)


@dataclass(frozen=True)
class Sample:
    species: Species
    palette: Palette
    seed: int


def _u(rng: np.random.Generator, key: str) -> float:
    lo, hi = RANGES[key]
    return float(rng.uniform(lo, hi))


def _profile(rng: np.random.Generator) -> tuple[float, ...]:
    """Five FishShapeSpline control points: a rounded head, one hump, a tapering peduncle."""
    px, pr = _u(rng, "profile_peak_x"), _u(rng, "profile_peak_r")
    xs = np.array([0.06, px * 0.7, px, 0.5 * (px + 0.92) + 0.08, 0.92])
    xs[1] = max(xs[1], 0.1)
    xs[3] = min(xs[3], 0.85)
    rs = pr * np.array([rng.uniform(0.5, 0.75), rng.uniform(0.85, 0.98), 1.0,
                        rng.uniform(0.55, 0.8), rng.uniform(0.2, 0.3)])
    return tuple(round(float(v), 4) for pair in zip(xs, rs, strict=True) for v in pair)


def _section(rng: np.random.Generator, key: str, b: int) -> int:
    return int(np.clip(round(_u(rng, key) * (b - 1)), 1, b - 2))


def _palette(rng: np.random.Generator) -> Palette:
    hue = float(rng.uniform(0, 1))

    def rgb(h: float, s: float, v: float) -> tuple[int, int, int]:
        r, g, b = colorsys.hsv_to_rgb(h % 1.0, s, v)
        return int(r * 255), int(g * 255), int(b * 255)

    return Palette(back=rgb(hue, rng.uniform(0.5, 0.9), rng.uniform(0.3, 0.6)),
                   belly=rgb(hue + 0.05, rng.uniform(0.1, 0.4), rng.uniform(0.85, 1.0)),
                   fin=rgb(hue + rng.uniform(-0.1, 0.1), rng.uniform(0.4, 0.8), rng.uniform(0.7, 1.0)),
                   pattern=str(rng.choice(PATTERNS)),
                   accent=rgb(hue + rng.uniform(0.3, 0.7), rng.uniform(0.5, 1.0), rng.uniform(0.2, 0.7)))


def _swing(rng: np.random.Generator, key: str, period: int) -> tuple[float, float]:
    """(movement angle, step size) whose cycle of 4 x angle / step frames is exactly ``period``."""
    angle = float(round(_u(rng, key)))
    return angle, 4.0 * angle / period


def sample_species(seed: int, name: str | None = None) -> Sample:
    """One plausible species (texture points projected, see :func:`paint_sample`) from ``seed``."""
    from fishgen.authoring.texture_points import project_texture_points

    rng = np.random.default_rng(seed)
    b = int(rng.choice(BODY_SECTIONS))
    c = int(rng.choice(CIRCLE_SECTIONS))
    shape = str(rng.choice(SHAPES))
    sx = _u(rng, "scale_x")
    sy = sx * _u(rng, "depth_ratio")
    sz = sy * _u(rng, "width_ratio")
    period = int(rng.choice(CAUDAL_PERIODS))
    caudal_swing = _swing(rng, "caudal_swing", period)
    top_line, bottom_line = _u(rng, "caudal_line"), 0.0
    bottom_line = top_line * float(rng.uniform(0.9, 1.1))
    angle = _u(rng, "caudal_angle")
    triangles = int(rng.integers(2, 5))
    caudal = CaudalFin(top_line, _u(rng, "caudal_middle"), angle, triangles,
                       (_u(rng, "caudal_connection"), 0.0, 0.0), 0.0, bottom_line,
                       angle * float(rng.uniform(0.95, 1.05)), triangles, *caudal_swing)
    d0 = _section(rng, "dorsal_start", b)
    d1 = max(_section(rng, "dorsal_end", b), d0 + 1)
    dorsal = VerticalFin(d0, d1, _u(rng, "dorsal_length"), _u(rng, "dorsal_end_length"),
                         _u(rng, "dorsal_angle"), _u(rng, "dorsal_proportion"))
    a0 = max(_section(rng, "anal_start", b), d0 + 1)
    a1 = max(_section(rng, "anal_end", b), a0 + 1)
    anal = VerticalFin(a0, min(a1, b - 1), _u(rng, "anal_length"), _u(rng, "anal_end_length"),
                       _u(rng, "anal_angle"), _u(rng, "anal_proportion"))
    # An adipose fin (small, behind the dorsal) on about a third of the samples, as on BonyBream.
    has_adipose = rng.uniform() < 0.33 and d1 + 2 < b - 1
    ad0 = min(d1 + 2, b - 2)
    adipose = VerticalFin(ad0, min(ad0 + 2, b - 1), 0.06 if has_adipose else 0.0,
                          0.02 if has_adipose else 0.0, 30.0 if has_adipose else 0.0, 0.5)
    p0 = _section(rng, "pelvic_start", b)
    paired_period = period * int(rng.choice((1, 2))) // int(rng.choice((1, 2)))
    p1 = min(p0 + max(1, round(_u(rng, "pelvic_span") * (b - 1))), b - 2)
    pelvic = PelvicFin(int(round(_u(rng, "pelvic_circle") * c)) % c, p0, max(p1, p0),
                       _u(rng, "pelvic_length"), _u(rng, "pelvic_end_length"), _u(rng, "pelvic_angle"),
                       *_swing(rng, "paired_swing", paired_period))
    q_circle = max(1, int(round(_u(rng, "pectoral_circle") * c)))
    pectoral = PectoralFin(_section(rng, "pectoral_start", b), q_circle,
                           int(rng.integers(2, max(3, min(4, c // 4) + 1))), _u(rng, "pectoral_length"),
                           _u(rng, "pectoral_angle"), _u(rng, "pectoral_proportion"), 0.0,
                           *_swing(rng, "paired_swing", paired_period))
    palette = _palette(rng)
    r, g, bl = (v / 255 for v in palette.back)
    species = Species(
        name=name or f"sampled_{seed}", world_scale=_u(rng, "world_scale"), urge_factor=0.009,
        start_position=(float(rng.uniform(-4, 4)), float(rng.uniform(1, 6)), float(rng.uniform(-9, -3))),
        cube_size=10.0, colour=(round(r, 3), round(g, 3), round(bl, 3)), shape_class=shape,
        shape_params=_profile(rng) if shape == "FishShapeSpline" else (),
        body_sections=b, circle_sections=c, textured=True, masked=bool(rng.uniform() < 0.5),
        turn_test=False, catchfish_test=False, scale=(sx, sy, sz), caudal=caudal, adipose=adipose,
        dorsal=dorsal, pelvic=pelvic, anal=anal, pectoral=pectoral,
        transparency=round(_u(rng, "transparency"), 2),
        behaviour=Behaviour((0.000009, 0.0000075, 0.0000071), 0.04, 0.35, 0.01, 0.15,
                            round(_u(rng, "speed"), 3), 50.0, 0.0015, (0.04, 10.0)))
    from fishgen.authoring.painter import SIZE

    return Sample(project_texture_points(species, aspect=SIZE[0] / SIZE[1]), palette, seed)
