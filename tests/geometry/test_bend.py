"""The bend (a midline on a circular arc) and morph-target normals that stay exact when blended."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.geometry.bend import PIVOT, arc_offsets
from fishgen.geometry.body import build_body
from fishgen.geometry.body_wave import BodyWave, wave_targets
from fishgen.geometry.mesh import normal_deltas, vertex_normals
from fishgen.geometry.shapes import profile_for


def _midline(x, kappa):
    lateral, axial = arc_offsets(x, kappa)
    return np.stack([lateral, -x + axial], axis=1)          # (X, Z): the nose towards +Z


@pytest.mark.parametrize("degrees", [10.0, 45.0, 110.0, 170.0])
def test_the_midline_keeps_its_length_and_turns_by_the_curvature(degrees):
    kappa = np.radians(degrees)
    x = np.linspace(0.0, 1.0, 4001)
    bent = _midline(x, kappa)
    assert np.sum(np.linalg.norm(np.diff(bent, axis=0), axis=1)) == pytest.approx(1.0, rel=1e-6)
    head, tail = bent[1] - bent[0], bent[-1] - bent[-2]
    turn = np.degrees(np.arccos(np.dot(head, tail) / np.linalg.norm(head) / np.linalg.norm(tail)))
    assert turn == pytest.approx(degrees, abs=0.1)
    pivot = int(round(PIVOT * 4000))
    assert np.allclose(bent[pivot], [0.0, -PIVOT], atol=1e-12)     # the centre of mass stays put
    assert bent[0, 0] > 0 and bent[-1, 0] > 0                       # a C open to the fish's left (+X)


def test_no_curvature_no_bend():
    lateral, axial = arc_offsets(np.linspace(0, 1, 5), 0.0)
    assert not lateral.any() and not axial.any()


def _body(bodies=16, circles=12):
    body = build_body(profile_for("FishShapeSin"), bodies, circles, (0.26, 0.1, 0.04))
    positions = body.mesh.positions[:, [2, 1, 0]] * [1.0, 1.0, -1.0]   # glTF axes, nose towards +Z
    return positions, body.mesh.faces


def _targets(positions):
    """The wave's four targets and a bend, each vertex moved as the midline at its own place."""
    nose, length = positions[:, 2].max(), np.ptp(positions[:, 2])
    x = (nose - positions[:, 2]) / length
    moves = np.zeros((5, len(x), 3))
    moves[:4, :, 0] = wave_targets(x, BodyWave()) * length
    lateral, axial = arc_offsets(x, np.radians(60.0))
    moves[4, :, 0], moves[4, :, 2] = lateral * length, axial * length
    return moves


def _client_normals(positions, faces, moves, weights):
    """What a glTF client shades with: normalize(n0 + sum w_i * delta_i)."""
    deltas = normal_deltas(positions, faces, moves)
    n = vertex_normals(positions, faces) + np.einsum("k,knc->nc", weights, deltas)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def _angles(a, b):
    return np.degrees(np.arccos(np.clip(np.sum(a * b, axis=1), -1, 1)))


def test_blended_targets_are_shaded_as_their_own_recomputed_normals():
    positions, faces = _body()
    moves = _targets(positions)
    rng = np.random.default_rng(1)
    for weights in [np.eye(5)[k] for k in range(5)] + [rng.uniform(0, 1, 5) for _ in range(20)]:
        posed = positions + np.einsum("k,knc->nc", weights, moves)
        assert _angles(_client_normals(positions, faces, moves, weights),
                       vertex_normals(posed, faces)).max() < 1e-4      # degrees: rounding only


def test_turning_the_cross_sections_would_not_blend_exactly():
    """Why the bend carries each ring along without turning it: a bend that also turns the rings
    (a rigid bend) gives normals that no single delta can follow at half weight."""
    positions, faces = _body()
    nose, length = positions[:, 2].max(), np.ptp(positions[:, 2])
    kappa = np.radians(110.0)
    u = (PIVOT - (nose - positions[:, 2]) / length) * length
    phi = kappa * u / length
    x, y, z = positions.T
    rigid = np.stack([length / kappa * (1 - np.cos(phi)) + x * np.cos(phi), y,
                      z - u + length / kappa * np.sin(phi) - x * np.sin(phi)], axis=1)
    moves = (rigid - positions)[None]
    half = positions + 0.5 * moves[0]
    assert _angles(_client_normals(positions, faces, moves, np.array([0.5])),
                   vertex_normals(half, faces)).max() > 5.0
