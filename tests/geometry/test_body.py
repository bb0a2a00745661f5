"""Body construction (thesis 4.1): level of detail, closure, normals."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

from fishgen.geometry.body import build_body, midline_point
from fishgen.geometry.shapes import SHAPES, profile_for

LODS = [(8, 6), (16, 12), (32, 24), (128, 96), (5, 7)]


@pytest.mark.parametrize("bodies,circles", LODS)
def test_counts_follow_level_of_detail(bodies, circles):
    body = build_body(profile_for("FishShapeSin"), bodies, circles, (0.26, 0.1, 0.04))
    # rings 0 and B-1 collapse to one apex each
    assert len(body.mesh.positions) == (bodies - 2) * circles + 2
    assert len(body.mesh.faces) == 2 * (bodies - 3) * circles + 2 * circles


@pytest.mark.parametrize("shape", sorted(SHAPES))
@pytest.mark.parametrize("bodies,circles", LODS)
def test_body_is_closed_watertight_and_outward(shape, bodies, circles):
    params = (0.3, 0.4, 0.7, 0.2) if shape == "FishShapeSpline" else ()
    body = build_body(profile_for(shape, params), bodies, circles, (0.26, 0.1, 0.04))
    mesh = trimesh.Trimesh(body.mesh.positions, body.mesh.faces, process=False)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.volume > 0


def test_normals_are_unit_and_point_outwards():
    body = build_body(profile_for("FishShapeSin"), 16, 12, (0.26, 0.1, 0.04))
    n = body.mesh.normals
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0)
    away = body.mesh.positions - np.array([0.13, 0.0, 0.0])
    assert np.all(np.einsum("ij,ij->i", n, away) > 0)


def test_profile_closes_at_both_ends_and_peaks_in_between():
    r = profile_for("FishShapeSin")(np.linspace(0, 1, 101))
    assert r[0] == pytest.approx(0) and r[-1] == pytest.approx(0, abs=1e-12)
    assert 0.3 < np.argmax(r) / 100 < 0.7 and r.max() == pytest.approx(0.5)


def test_spline_profile_passes_through_its_control_points():
    profile = profile_for("FishShapeSpline", (0.25, 0.3, 0.6, 0.45))
    assert profile(np.array([0.25, 0.6])) == pytest.approx([0.3, 0.45])
    assert np.all(profile(np.linspace(0, 1, 200)) >= 0)


def test_cross_sections_are_scaled_ellipses():
    body = build_body(profile_for("FishShapeSin"), 16, 12, (2.0, 0.5, 0.25))
    ring = body.rings[7]
    assert ring[:, 1].max() == pytest.approx(0.5 * 0.5 * np.sin(np.pi * 7 / 15))
    assert ring[:, 2].max() == pytest.approx(0.25 * 0.5 * np.sin(np.pi * 7 / 15))
    assert body.rings[:, 0, 0].max() == pytest.approx(2.0)


@pytest.mark.parametrize("circles", [6, 7, 12])
def test_midline_point_lies_on_the_faceted_surface(circles):
    body = build_body(profile_for("FishShapeSin"), 8, circles, (1, 1, 1))
    mesh = trimesh.Trimesh(body.mesh.positions, body.mesh.faces, process=False)
    pts = np.array([midline_point(body.rings, j, s) for j in range(1, 7) for s in (1, -1)])
    _, dist, _ = trimesh.proximity.closest_point(mesh, pts)
    assert dist.max() < 1e-9


@pytest.mark.parametrize("circles", range(3, 14))
def test_every_ring_is_its_own_mirror_image_across_the_mid_plane(circles):
    """Left and right of the fish are alike at any CircleSections: an odd ring is turned a quarter
    step so a point stands straight above the axis (an even one keeps the thesis' angles)."""
    from fishgen.geometry.body import ring_angles

    angles = ring_angles(circles)
    points = np.stack([np.sin(angles), np.cos(angles)], axis=1)          # (y, z)
    mirrored = points * [1, -1]
    assert np.abs(points[:, None] - mirrored[None]).max(axis=2).min(axis=1).max() < 1e-12
    if circles % 2:
        assert np.isclose(np.sin(angles).max(), 1.0)
    else:
        assert np.allclose(angles, 2 * np.pi * np.arange(circles) / circles)
