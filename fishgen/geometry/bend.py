"""A steady bend of the body: the midline laid on a circular arc, as turning fish and C-starts bend.

x is the position along the fish from the nose (0) to the tail tip (1) in body lengths, as in
:mod:`fishgen.geometry.body_wave`. The body bends about a pivot ``x_p`` (the centre of mass, which
barely moves in a C-start's first stage) with a constant curvature ``kappa`` (radians per body
length); the whole bend, nose tangent to tail tangent, is ``kappa`` radians. A point of the
straight midline at ``u = x_p - x`` (towards the nose) goes to the arc at angle ``phi = kappa u``:

    lateral  (1 - cos phi) / kappa        towards the fish's left (+X) at both ends: a C open to the left
    axial    sin(phi) / kappa - u         (negative: the arc's ends come closer to the pivot)

Every point of a cross-section moves with its midline point, so the bend, like the body wave,
displaces each vertex by a function of its own place along the fish. That is what keeps morphed
normals exact (:func:`fishgen.geometry.mesh.normal_deltas`): on the body every triangle has an
edge within one ring, whose two ends move alike, so the (area-weighted) face normals are linear in
any sum of such displacements. The cross-sections are carried along the arc without turning; at
the sharpest bend fishgen makes (a C-start) the thin tail is drawn a little thinner in the bend's
plane, and the midline keeps its length.
"""
from __future__ import annotations

import numpy as np

PIVOT = 0.4
"""Where the body bends about, body lengths from the nose: about a carangiform fish's centre of mass."""


def arc_offsets(x: np.ndarray, kappa: float, pivot: float = PIVOT) -> tuple[np.ndarray, np.ndarray]:
    """(lateral, axial) displacement in body lengths of midline points at ``x`` when the body bends
    with curvature ``kappa`` radians per body length to its left; axial is along the body towards
    the nose (glTF +Z), lateral towards the left (glTF +X)."""
    u = pivot - np.asarray(x, dtype=np.float64)
    if kappa == 0:
        return np.zeros_like(u), np.zeros_like(u)
    phi = kappa * u
    return (1.0 - np.cos(phi)) / kappa, np.sin(phi) / kappa - u


def bend_angle(kappa: float) -> float:
    """Degrees between the nose's and the tail tip's directions for curvature ``kappa``."""
    return float(np.degrees(kappa))
