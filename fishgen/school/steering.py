"""What every behaviour model shares: soft bounds, keeping away from other species, fleeing a
predator, the turn limit and the hard separation, all vectorised over (3, N) state."""
from __future__ import annotations

import numpy as np

from fishgen.school.neighbours import Neighbours
from fishgen.school.state import SchoolState, norm

GAIN_BOUNDS = 6.0
GAIN_OTHER_SPECIES = 6.0
GAIN_FLEE = 8.0
OTHER_SPECIES_DISTANCE = 4.0  # body lengths: keep away from other species inside this
FLEE_SPEEDUP = 1.5         # speed up to (1 + this) x cruise next to a predator
SEPARATION_PASSES = 1


def bounds_accel(state: SchoolState) -> np.ndarray:
    """Towards the inside, growing over BOUNDS_MARGIN body lengths from each wall."""
    pos = state.pos
    below = np.minimum(np.maximum((state.inner_lo - pos) * state.inv_margin, 0.0), 1.0)
    above = np.minimum(np.maximum((pos - state.inner_hi) * state.inv_margin, 0.0), 1.0)
    return (2.0 * GAIN_BOUNDS * state.cruise) * (below - above)


def other_species_accel(state: SchoolState, nbrs: Neighbours) -> np.ndarray:
    """Away from the nearest fish of another species inside OTHER_SPECIES_DISTANCE body lengths."""
    if nbrs.other is None:
        return np.zeros_like(state.pos)
    ok = nbrs.other >= 0
    off = state.pos - state.pos[:, np.where(ok, nbrs.other, 0)]
    dist = norm(off)
    radius = OTHER_SPECIES_DISTANCE * state.length
    strength = np.clip(1.0 - dist / radius, 0.0, None) * ok * state.weights["keepaway"]
    return (GAIN_OTHER_SPECIES * state.cruise * strength / np.maximum(dist, 1e-12)) * off


def flee_accel(state: SchoolState, predator: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Away from the predator inside the flee distance, and how close it is (0-1, for speeding up)."""
    off = state.pos - predator[:, None]
    dist = norm(off)
    near = np.clip(1.0 - dist / np.maximum(state.flee_dist, 1e-12), 0.0, 1.0)
    flee = state.weights["flee"]
    near = near * (flee > 0)
    acc = (GAIN_FLEE * flee * state.cruise * near / np.maximum(dist, 1e-12)) * off
    return acc, np.sqrt(near)


def separate(state: SchoolState, nbrs: Neighbours, rows: np.ndarray | None = None) -> None:
    """Push apart pairs closer than HARD_SEPARATION mean body lengths (each side moves half).

    `rows`: only these fish (the others are known to be clear of their nearest this step)."""
    if state.n < 2:
        return
    pos = state.pos
    near, need, ok = nbrs.near, nbrs.near_need, nbrs.near_ok
    if rows is not None:
        if rows.size == 0:
            return
        near, need, ok = near[:, rows], need[:, rows], ok[:, rows]
    mine = pos if rows is None else pos[:, rows]
    off = mine[:, None, :] - np.take(pos, near, axis=1)     # from neighbour to me: (3, m, rows)
    dist = norm(off)
    short = np.maximum(need - dist, 0.0) * ok
    if not short.any():
        return
    tiny = dist < 1e-9
    push = np.einsum("kn,ckn->cn", short / np.maximum(dist, 1e-12), off)
    if tiny.any():  # coincident fish: each goes its own fixed random way
        fallback = state.fallback if rows is None else state.fallback[:, rows]
        push += (short * tiny).sum(axis=0) * fallback
    if rows is None:
        state.pos = pos + 0.5 * push
    else:
        state.pos[:, rows] += 0.5 * push


def clamp(state: SchoolState) -> None:
    np.clip(state.pos, state.lo, state.hi, out=state.pos)


def turn_towards(d: np.ndarray, want: np.ndarray, max_angle: np.ndarray | float) -> np.ndarray:
    """Unit directions `d` (3, N) rotated towards `want` by at most `max_angle` radians.

    A fish that wants to turn by less than that simply takes the wanted direction; only the others
    (few, once a school has formed) pay for the rotation's trigonometry."""
    wn = norm(want)
    t = np.where(wn > 1e-12, want / np.maximum(wn, 1e-12), d)
    c = np.minimum(np.maximum(d[0] * t[0] + d[1] * t[1] + d[2] * t[2], -1.0), 1.0)
    limit = np.cos(np.minimum(max_angle, np.pi))
    rows = np.flatnonzero(c < limit)
    if rows.size == 0:
        return t
    d_r, c_r = d[:, rows], c[rows]
    perp = t[:, rows] - c_r * d_r
    pn = norm(perp)
    flat = pn < 1e-9
    if flat.any():  # exactly behind: turn about the vertical, or about X if vertical
        alt = np.cross(d_r[:, flat].T, np.array([0.0, 1.0, 0.0]))
        bad = np.linalg.norm(alt, axis=1) < 1e-6
        alt[bad] = np.cross(d_r[:, flat][:, bad].T, np.array([1.0, 0.0, 0.0]))
        perp[:, flat] = alt.T
        pn[flat] = np.linalg.norm(alt, axis=1)
    a = np.minimum(np.arccos(c_r), max_angle if np.ndim(max_angle) == 0 else np.asarray(max_angle)[rows])
    out = np.cos(a) * d_r + (np.sin(a) / pn) * perp
    t[:, rows] = out / norm(out)
    return t
