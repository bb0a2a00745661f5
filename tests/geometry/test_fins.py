"""Fins (thesis 4.2): structure, Fixel vertex order, contact with the body, mirroring."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

from fishgen.assembly.fins import build_fins
from fishgen.geometry.body import build_body
from fishgen.geometry.fins import CaudalParams, VerticalParams, caudal_fin, vertical_fin
from fishgen.geometry.shapes import profile_for
from fishgen.species.parser import parse_species
from tests.conftest import PARAMS

SPECIES = [parse_species(p.read_text(), str(p)) for p in sorted(PARAMS.glob("*.txt"))]


def body_and_fins(sp):
    body = build_body(profile_for(sp.shape_class, sp.shape_params), sp.body_sections, sp.circle_sections,
                      sp.scale)
    return body, {f.name: f for f in build_fins(sp, body.rings)}


@pytest.mark.parametrize("sp", SPECIES, ids=lambda s: s.name)
def test_fin_vertices_match_texture_point_counts(sp):
    _, fins = body_and_fins(sp)
    tp = sp.texture_points
    for name, points in (("caudal_fin", tp.caudal), ("dorsal_fin", tp.dorsal), ("anal_fin", tp.anal),
                         ("pectoral_fin_left", tp.pectoral), ("pelvic_fin_left", tp.pelvic)):
        if name == "anal_fin" and len(fins[name].mesh.positions) < len(points):
            # ended in front of the caudal fin (decisions.md): Fixel's first points, end moved up
            n = len(fins[name].mesh.positions) // 2
            assert 2 <= n < len(points) // 2 and np.allclose(fins[name].mesh.uvs[:2], points[:2])
            continue
        assert len(fins[name].mesh.positions) == len(points)
        assert np.allclose(fins[name].mesh.uvs, points)


@pytest.mark.parametrize("sp", SPECIES, ids=lambda s: s.name)
def test_fins_touch_the_body(sp):
    body, fins = body_and_fins(sp)
    mesh = trimesh.Trimesh(body.mesh.positions, body.mesh.faces, process=False)
    scale = np.ptp(body.mesh.positions[:, 0])
    for name, fin in fins.items():
        if name == "caudal_fin":
            # its connection point sits on the axis inside the tail
            assert mesh.contains(fin.pivot[None, :])[0] or np.linalg.norm(fin.pivot[1:]) < 1e-9
            continue
        _, dist, _ = trimesh.proximity.closest_point(mesh, fin.mesh.positions)
        assert dist.min() < 1e-6 * scale, name


@pytest.mark.parametrize("bodies,circles", [(8, 6), (16, 12), (9, 7)])
def test_no_gap_under_the_dorsal_fin_at_any_level_of_detail(bodies, circles):
    body = build_body(profile_for("FishShapeSin"), bodies, circles, (0.26, 0.1, 0.04))
    fin = vertical_fin("dorsal_fin", VerticalParams(2, bodies - 3, 0.6, 0.1, 70, 0.9), body.rings,
                       np.array([0.26, 0.1, 0.04]), 1.0)
    mesh = trimesh.Trimesh(body.mesh.positions, body.mesh.faces, process=False)
    n = bodies - 4
    base = fin.mesh.positions[[1, 2, *range(4, 4 + n - 2)]]     # Fixel order: B_0, B_n, B_1..
    _, dist, _ = trimesh.proximity.closest_point(mesh, base)
    assert dist.max() < 1e-9


@pytest.mark.parametrize("sp", SPECIES, ids=lambda s: s.name)
@pytest.mark.parametrize("circles", [3, 5, 7, 9])
def test_paired_fins_touch_the_body_at_an_odd_number_of_circle_sections(sp, circles):
    """An odd ring was no mirror image of itself, so the right fins (mirror images of the left)
    stood off the body by up to 15 % of its length (PineappleFish at 16x3)."""
    from fishgen.assembly.levels import at_level

    body, fins = body_and_fins(at_level(sp, 16, circles))
    mesh = trimesh.Trimesh(body.mesh.positions, body.mesh.faces, process=False)
    scale = np.ptp(body.mesh.positions[:, 0])
    for name in ("pectoral_fin_left", "pectoral_fin_right", "pelvic_fin_left", "pelvic_fin_right"):
        _, dist, _ = trimesh.proximity.closest_point(mesh, fins[name].mesh.positions)
        assert np.sort(dist)[1] < 1e-6 * scale, f"{name}: {np.sort(dist)[1] / scale:.3f} of the length off"


@pytest.mark.parametrize("sp", SPECIES, ids=lambda s: s.name)
def test_right_fins_mirror_the_left(sp):
    _, fins = body_and_fins(sp)
    for kind in ("pectoral", "pelvic"):
        left, right = fins[f"{kind}_fin_left"], fins[f"{kind}_fin_right"]
        assert np.allclose(right.mesh.positions, left.mesh.positions * [1, 1, -1])
        assert np.allclose(right.pivot, left.pivot * [1, 1, -1])
        assert np.all(left.mesh.positions[:, 2] > 0) and np.all(right.mesh.positions[:, 2] < 0)


def test_caudal_fin_follows_its_lines_and_angles():
    fin = caudal_fin(CaudalParams(1.0, 0.5, 90.0, 2, (1.0, 0.0, 0.0), 0.0, 1.0, 45.0, 1, 10, 1), np.ones(3))
    p = fin.mesh.positions
    assert np.allclose(p[0], [1, 0, 0])                            # connection point
    assert np.allclose(p[1], [1, 1, 0])                            # top tip, 90 degrees up
    assert np.allclose(p[3], [1.5, 0, 0]) and np.allclose(p[5], p[3])  # middle end, twice
    assert np.allclose(p[4], [1 + np.sqrt(0.5), -np.sqrt(0.5), 0])  # bottom tip at 45 degrees
    assert np.allclose(p[2], (p[1] + p[3]) / 2)                    # linear interpolation


def test_vertical_fin_proportion_and_ninety_degree_end():
    rings = build_body(profile_for("FishShapeSin"), 16, 12, (1, 1, 1)).rings
    fin = vertical_fin("dorsal_fin", VerticalParams(4, 7, 0.5, 0.2, 60.0, 0.5), rings, np.ones(3), 1.0)
    p = fin.mesh.positions
    t0, b0, b3, t3, b1, b2, t1, t2 = p
    assert np.allclose(t0 - b0, [0.5 * np.cos(np.radians(60)), 0.5 * np.sin(np.radians(60)), 0])
    assert np.allclose(t1, b1 + 0.5 * (t0 - b1)) and np.allclose(t2, b2 + 0.5 * (t1 - b2))
    assert np.allclose(t3 - b3, [0, 0.2, 0])


def test_anal_fin_hangs_below_whatever_the_angle_sign():
    rings = build_body(profile_for("FishShapeSin"), 16, 12, (1, 1, 1)).rings
    for angle in (-55.0, 55.0):
        fin = vertical_fin("anal_fin", VerticalParams(11, 14, 0.3, 0.1, angle, 0.9), rings, np.ones(3), -1.0)
        assert fin.mesh.positions[:, 1].max() <= 1e-12
