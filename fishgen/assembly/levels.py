"""Levels of detail: a species at another BodySections x CircleSections, fins and texture included.

The thesis sets a fish's level of detail by its two section counts (4.1) and measures 8x6 against
32x24 (8.1.1, 8.2.1). A species file describes its fins in its own sections: a vertical fin spans
BodySections, a pectoral fin starts on a CircleSection and spans a number of them. At another level
every section number moves to the section nearest the same place along (or around) the body, so
the fins sit on that level's own rings, and the texture points are resampled on the new grid:
the body's bilinearly over (section, circle), each fin's along its base and outer edge.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from fishgen.geometry.body import ring_offset
from fishgen.species.model import PectoralFin, PelvicFin, Species, TexturePoints, VerticalFin

Points = tuple[tuple[float, float], ...]


def _nearest(value: float) -> int:
    return math.floor(value + 0.5)  # half up, not Python's half-to-even


def at_level(species: Species, bodies: int, circles: int) -> Species:
    """``species`` built at ``bodies`` x ``circles``: the same fish at another level of detail."""
    b0, c0 = species.body_sections, species.circle_sections
    if (bodies, circles) == (b0, c0):
        return species

    def sec(k: int) -> int:
        return min(max(_nearest(k * (bodies - 1) / (b0 - 1)), 0), bodies - 1)

    def circ(k: int) -> int:
        return circle_at(k, c0, circles)

    def span(start: int, end: int) -> tuple[int, int]:
        """A fin's first and last section: at least one section's length. A fin whose ends meet
        on one ring spans the section its middle lies in (the one before, if the middle is on a
        ring: a pelvic fin's trailing edge reaches back past its last ring). Stretched to the next
        ring instead, a fin near the middle of a 3-ring fish reached the tail, and a pelvic fin's
        trailing edge hung past it (by 17 % of the body on one random species)."""
        first, last = sec(start), sec(end)
        if last > first:
            return min(first, bodies - 2), last
        middle = (start + end) / 2 * (bodies - 1) / (b0 - 1)
        first = min(max(math.ceil(middle) - 1, 0), bodies - 2)  # on a ring: the section before it
        return first, first + 1

    def vertical(f: VerticalFin) -> VerticalFin:
        start, end = span(f.start_section, f.end_section)
        return replace(f, start_section=start, end_section=end,
                       proportion=_per_step(f.proportion, f.end_section - f.start_section, end - start))

    p: PelvicFin = species.pelvic
    ps, pe = span(p.start_section, p.end_section)
    pelvic = replace(p, start_circle=circ(p.start_circle), start_section=ps, end_section=pe)
    q: PectoralFin = species.pectoral
    # the same arc of the ring: triangles span CircleSections
    triangles = min(max(_nearest(q.triangles * circles / c0), 1), max(circles // 2, 1))
    pectoral = replace(q, start_section=sec(q.start_section), start_circle=circ(q.start_circle),
                       triangles=triangles, proportion=_per_step(q.proportion, q.triangles, triangles))
    out = replace(species, body_sections=bodies, circle_sections=circles, dorsal=vertical(species.dorsal),
                  adipose=vertical(species.adipose), anal=vertical(species.anal), pelvic=pelvic,
                  pectoral=pectoral, texture_points=None)
    tp = species.texture_points
    if tp is None:
        return out
    return replace(out, texture_points=TexturePoints(
        body=_body_points(tp.body, (b0, c0), (bodies, circles)),
        caudal=tp.caudal,
        dorsal=_vertical_points(tp.dorsal, out.dorsal),
        adipose=_vertical_points(tp.adipose, out.adipose),
        anal=_vertical_points(tp.anal, out.anal),
        pectoral=_pectoral_points(tp.pectoral, pectoral.triangles),
        pelvic=_pelvic_points(tp.pelvic, pelvic.end_section - pelvic.start_section + 1)))


def circle_at(k: int, circles: int, new_circles: int) -> int:
    """The point of a ring of ``new_circles`` nearest the angle of point ``k`` of one of ``circles``
    (an odd ring is turned a quarter step: :func:`~fishgen.geometry.body.ring_offset`)."""
    at = (k + ring_offset(circles)) * new_circles / circles - ring_offset(new_circles)
    return _nearest(at) % new_circles


def _per_step(proportion: float, steps: int, new_steps: int) -> float:
    """A fin's ``proportion`` for ``new_steps`` over the span it had in ``steps``.

    Each top point lies ``proportion`` of the way up the triangle before (thesis 4.2), so the fin's
    edge falls by proportion^steps over its span: taken as it stands over twice the steps, the
    edge fell twice as fast, and BonyBream's pectoral fin at 32x24 had 68 % of its file's area,
    Centroberyx's dorsal at 64x48 half. The same fall over the span keeps the fin's size.
    """
    if steps <= 0 or new_steps <= 0 or new_steps == steps or proportion <= 0:
        return proportion
    return float(proportion ** (steps / new_steps))


def _as_tuple(points: np.ndarray) -> Points:
    return tuple((float(u), float(v)) for u, v in points)


def _body_points(points: Points, old: tuple[int, int], new: tuple[int, int]) -> Points:
    """The body's (B, C) texture grid resampled at the new rings: linear along the body, periodic
    around it (circle C - 1 neighbours circle 0)."""
    b0, c0 = old
    b, c = new
    grid = np.asarray(points, np.float64).reshape(b0, c0, 2)
    f = np.arange(b) * (b0 - 1) / (b - 1)                     # fractional old section of each new ring
    j = np.minimum(np.floor(f).astype(np.int64), b0 - 2)
    s = (f - j)[:, None, None]
    rows = grid[j] * (1 - s) + grid[j + 1] * s                # (b, c0, 2)
    # fractional old circle of each new point, by angle (an odd ring is turned: ring_offset)
    g = ((np.arange(c) + ring_offset(c)) * c0 / c - ring_offset(c0)) % c0
    i = np.floor(g).astype(np.int64) % c0
    t = (g - np.floor(g))[None, :, None]
    out = rows[:, i] * (1 - t) + rows[:, (i + 1) % c0] * t
    return _as_tuple(out.reshape(-1, 2))


def _resample(row: np.ndarray, count: int) -> np.ndarray:
    """A row of points resampled to ``count`` points, evenly by index, ends kept."""
    if len(row) == 1 or count == 1:
        return np.repeat(row[:1], count, axis=0)
    old = np.linspace(0.0, 1.0, len(row))
    new = np.linspace(0.0, 1.0, count)
    return np.stack([np.interp(new, old, row[:, k]) for k in range(2)], axis=1)


# A fin's two rows of points (base and top, or base and outer edge) as Fixel lays them out: four
# corners, each a row's first (0) or last (-1) point, then row 0's inner points, then row 1's.
VERTICAL_CORNERS = ((1, 0), (0, 0), (0, -1), (1, -1))    # T_0, B_0, B_n, T_n; row 0 the base
PELVIC_CORNERS = ((0, 0), (0, -1), (1, 0), (1, -1))      # B_0, B_n, O_0, O_n; row 1 the outer edge


def _rows_resampled(points: Points, corners: tuple[tuple[int, int], ...], count: int) -> Points:
    """Points laid out by ``corners`` resampled to ``count`` a row and laid out alike. A fin of one
    section (as given, or as resampled) is each row's one point, the rows in their corners' order."""
    p = np.asarray(points, np.float64)
    n = len(p) // 2 - 1
    order = sorted((0, 1), key=lambda row: corners.index((row, 0)))
    if n < 1:
        given = {row: p[k:k + 1] for k, row in enumerate(order)}
    else:
        inner = (p[4:4 + n - 1], p[4 + n - 1:])
        at = {corner: p[[k]] for k, corner in enumerate(corners)}
        given = {row: np.concatenate([at[row, 0], inner[row], at[row, -1]]) for row in (0, 1)}
    rows = {row: _resample(given[row], count) for row in (0, 1)}
    if count < 2:
        return _as_tuple(np.concatenate([rows[row] for row in order]))
    ends = [rows[row][[end]] for row, end in corners]
    return _as_tuple(np.concatenate(ends + [rows[0][1:-1], rows[1][1:-1]]))


def _vertical_points(points: Points, fin: VerticalFin) -> Points:
    """Fixel order T_0, B_0, B_n, T_n, B_1..B_{n-1}, T_1..T_{n-1}, resampled to ``fin``'s sections."""
    return _rows_resampled(points, VERTICAL_CORNERS, fin.end_section - fin.start_section + 1)


def _pectoral_points(points: Points, triangles: int) -> Points:
    """Fixel order T_0, B_0, B_n, B_1..B_{n-1}, T_1..T_{n-1} (T_n is B_n), resampled to ``triangles``."""
    p = np.asarray(points, np.float64)
    n = (len(p) - 1) // 2
    base = np.concatenate([p[1:2], p[3:3 + n - 1], p[2:3]])
    top = np.concatenate([p[0:1], p[3 + n - 1:], p[2:3]])
    base, top = _resample(base, triangles + 1), _resample(top, triangles + 1)
    return _as_tuple(np.concatenate([top[:1], base[:1], base[-1:], base[1:-1], top[1:-1]]))


def _pelvic_points(points: Points, count: int) -> Points:
    """Fixel order B_0, B_n, O_0, O_n, B_1..B_{n-1}, O_1..O_{n-1}, resampled to ``count`` sections."""
    return _rows_resampled(points, PELVIC_CORNERS, count)
