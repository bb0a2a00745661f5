"""The body: a profile rotated about the x-axis (thesis 4.1), closed at both ends.

Thesis axes: x from the nose (0) to the tail (1), y up, z to the fish's left.
Positions are returned already scaled by the species' scaleX/Y/Z.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fishgen.geometry.mesh import Mesh
from fishgen.geometry.shapes import Profile

CLOSED_EPS = 1e-9


@dataclass(frozen=True)
class Body:
    rings: np.ndarray        # (BodySections, CircleSections, 3) scaled positions
    radii: np.ndarray        # (BodySections,) unscaled profile radius
    mesh: Mesh
    ring_index: np.ndarray   # (BodySections, CircleSections) vertex index of each ring point


def ring_offset(circles: int) -> float:
    """Where ring point 0 stands, in steps of the ring, from the fish's left (+z).

    0 for an even count (the thesis' angle_i = 2 pi i / C). An odd ring from there is not a mirror
    image of itself across the fish's mid-plane, so the mirrored right fins stood off the body by up
    to 15 % of its length; turned a quarter step (the way that puts a point straight above the
    axis), it is, and every point moves by at most a quarter step.
    """
    if circles % 2 == 0:
        return 0.0
    return 0.25 if circles % 4 == 1 else -0.25


def ring_angles(circles: int) -> np.ndarray:
    """Angle of each ring point from the fish's left (+z) towards its back (+y)."""
    return 2.0 * np.pi * (np.arange(circles, dtype=np.float64) + ring_offset(circles)) / circles


def ring_positions(profile: Profile, bodies: int, circles: int, scale) -> tuple[np.ndarray, np.ndarray]:
    """Ring points: x_j = j/(B-1), r_j = profile(x_j), angle_i = 2 pi i / C (:func:`ring_angles`)."""
    x = np.arange(bodies, dtype=np.float64) / (bodies - 1)
    r = np.maximum(profile(x), 0.0)
    theta = ring_angles(circles)
    rings = np.empty((bodies, circles, 3))
    rings[:, :, 0] = x[:, None]
    rings[:, :, 1] = r[:, None] * np.sin(theta)[None, :]
    rings[:, :, 2] = r[:, None] * np.cos(theta)[None, :]
    return rings * np.asarray(scale, dtype=np.float64), r


def build_body(profile: Profile, bodies: int, circles: int, scale,
               uv: np.ndarray | None = None) -> Body:
    """Closed, watertight body mesh. ``uv`` is (B, C, 2) texture points or None.

    An end ring of zero radius collapses to one apex vertex; an end ring with a
    radius gets a flat cap around a centre vertex. Either way the surface closes.
    """
    rings, radii = ring_positions(profile, bodies, circles, scale)
    if uv is None:
        uv = np.zeros((bodies, circles, 2))
    open_rings = np.flatnonzero(radii > CLOSED_EPS)
    if open_rings.size == 0:
        raise ValueError("the body profile is zero everywhere")
    first, last = open_rings[0], open_rings[-1]
    kept = np.arange(first, last + 1)
    n_ring = kept.size * circles

    ring_index = np.full((bodies, circles), -1, dtype=np.int64)
    ring_index[kept] = np.arange(n_ring).reshape(kept.size, circles)
    nose, tail = n_ring, n_ring + 1
    nose_ring, tail_ring = max(first - 1, 0), min(last + 1, bodies - 1)
    # A collapsed end ring's points all map to the apex.
    if first > 0:
        ring_index[:first] = nose
    if last < bodies - 1:
        ring_index[last + 1:] = tail

    positions = np.concatenate([
        rings[kept].reshape(-1, 3),
        [[rings[nose_ring, 0, 0], 0.0, 0.0], [rings[tail_ring, 0, 0], 0.0, 0.0]],
    ])
    uvs = np.concatenate([uv[kept].reshape(-1, 2), [uv[nose_ring].mean(axis=0)],
                          [uv[tail_ring].mean(axis=0)]])

    i = np.arange(circles)
    p = (i + 1) % circles
    grid = np.arange(n_ring).reshape(kept.size, circles)
    a, b = grid[:-1][:, i], grid[:-1][:, p]          # ring j: points i and i+1
    c, d = grid[1:][:, i], grid[1:][:, p]            # ring j+1
    side = np.concatenate([np.stack([a, d, b], -1).reshape(-1, 3),
                           np.stack([a, c, d], -1).reshape(-1, 3)])
    front, back = grid[0], grid[-1]
    nose_fan = np.stack([np.full(circles, nose), front[i], front[p]], axis=1)
    tail_fan = np.stack([np.full(circles, tail), back[p], back[i]], axis=1)
    faces = np.concatenate([side, nose_fan, tail_fan]).astype(np.int64)
    return Body(rings, radii, Mesh(positions, faces, uvs), ring_index)


def midline_point(rings: np.ndarray, section: int, side: float) -> np.ndarray:
    """Point of the faceted ring ``section`` straight above (side=+1) or below (-1) the axis.

    Fins sit here, on the mesh's own surface rather than on the true curve, so
    there is no gap between fin and body at any level of detail (thesis 8.2.1).
    """
    return midline_points(rings, np.array([section]), side)[0]


def midline_points(rings: np.ndarray, sections: np.ndarray, side: float) -> np.ndarray:
    """:func:`midline_point` of each of ``sections`` (N, 3), all at once: on each ring the first
    edge (in vertex order) that crosses z = 0 on the ``side`` half, where it crosses; the axis
    when none does."""
    ring = rings[np.asarray(sections, np.intp)]
    z, y = ring[:, :, 2], ring[:, :, 1]
    z_next, y_next = np.roll(z, -1, axis=1), np.roll(y, -1, axis=1)
    crossing = (z >= 0) & (z_next <= 0) if side > 0 else (z <= 0) & (z_next >= 0)
    dz = z - z_next
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(dz == 0, 0.0, z / np.where(dz == 0, 1.0, dz))
    yk = y + t * (y_next - y)
    good = crossing & (yk * side >= 0)
    first = np.argmax(good, axis=1)
    found = good[np.arange(len(ring)), first]
    out = np.zeros((len(ring), 3))
    out[:, 0] = ring[:, 0, 0]
    out[:, 1] = np.where(found, yk[np.arange(len(ring)), first], 0.0)
    return out
