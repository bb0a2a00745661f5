"""The swimming body: the wave a client plays from the file, fins that stay on, no overlaps.

The tail-tip checks read the written glb with pygltflib alone (`glb_motion`), not fishgen's pose
code: what they measure is what three.js or Blender will play.
"""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

from fishgen.assembly.fish import build_fish, make_fish
from fishgen.exchange import export
from fishgen.geometry.body_wave import BodyWave
from fishgen.scene.pose import deformed, pose
from fishgen.species.parser import load_species
from tests.assembly.glb_motion import morphed_parts
from tests.conftest import PARAMS, assert_valid_gltf

SPECIES = ["bonybream", "centroberyx", "pineapplefish", "threadfingoldie"]
WAVE = BodyWave()
SPEED = 1.0
EXPECTED_HZ = WAVE.strouhal * SPEED / WAVE.tail_peak_to_peak   # what the specified wave asks for


@pytest.fixture(scope="module", params=SPECIES)
def written(request, tmp_path_factory):
    species = load_species(PARAMS / f"{request.param}.txt")
    scene = build_fish(species, speed=SPEED)
    path = tmp_path_factory.mktemp("wave") / f"{request.param}.glb"
    export(scene, path)
    return species, scene, path


def _body_axis(parts):
    z = np.concatenate([p.world_positions(np.array([-1.0]))[0][:, 2] for p in parts.values()])
    return z.max(), z.max() - z.min()


def _demodulate(signal: np.ndarray, t: np.ndarray, hz: float) -> complex:
    return complex(np.sum((signal - signal.mean()) * np.exp(-2j * np.pi * hz * t)))


def test_the_file_is_valid_and_every_part_rides_the_wave(written):
    _, scene, path = written
    assert_valid_gltf(path)
    parts = morphed_parts(path)
    drawn = {n.name for n in scene.nodes if n.mesh is not None}
    assert set(parts) == drawn                              # body and every fin carry the targets
    for part in parts.values():
        assert len(part.targets) == 4 and part.weights.min() >= 0 and part.weights.max() <= 1
        assert np.allclose(part.weights[0], part.weights[-1])  # the loop closes


def test_tail_tip_amplitude_frequency_and_phase_lag_match_the_wave(written):
    _, scene, path = written
    parts = morphed_parts(path)
    nose, length = _body_axis(parts)
    duration = float(parts["body"].times[-1])
    t = np.linspace(0.0, duration, 6000, endpoint=False)

    caudal = parts["caudal_fin"]
    tip = int(np.argmin(caudal.world_positions(np.array([-1.0]))[0][:, 2]))
    tail = caudal.world_positions(t)[:, tip, 0]
    assert np.ptp(tail) == pytest.approx(WAVE.tail_peak_to_peak * length, rel=0.10)

    upward = np.count_nonzero((tail[:-1] < tail.mean()) & (tail[1:] >= tail.mean()))
    hz = upward / duration
    assert hz == pytest.approx(EXPECTED_HZ, rel=0.10)

    body = parts["body"]
    rest = body.world_positions(np.array([-1.0]))[0]
    x = (nose - rest[:, 2]) / length
    head = int(np.argmin(np.abs(x - 0.35)))
    head_motion = body.world_positions(t)[:, head, 0]
    lag = np.angle(_demodulate(head_motion, t, hz) / _demodulate(tail, t, hz)) % (2 * np.pi)
    expected = (2 * np.pi * (1.0 - x[head]) / WAVE.wavelength) % (2 * np.pi)
    assert lag == pytest.approx(expected, rel=0.10)


def _body_length(scene):
    from fishgen.scene.pose import bounds

    lo, hi = bounds(scene)
    return float(hi[2] - lo[2])


@pytest.mark.parametrize("name", SPECIES)
@pytest.mark.parametrize("swim", ["body", "fins"])
def test_fins_stay_on_the_body_over_the_whole_clip(name, swim):
    """No fin vertex that touches the body at rest is ever more than 1 % of the body length off
    its surface (before fins hinged on their base line, BonyBream's pelvic fins lifted 2.1 %)."""
    scene = build_fish(load_species(PARAMS / f"{name}.txt"), swim=swim)
    length = _body_length(scene)
    nodes = {n.name: i for i, n in enumerate(scene.nodes)}
    drawn = dict(scene.drawn())

    def world(node, posed):
        return deformed(scene, node, drawn[node], posed)[0]

    rest = pose(scene)
    body_faces = drawn[nodes["body"]].indices
    rest_body = trimesh.Trimesh(world(nodes["body"], rest), body_faces, process=False)
    touching = {}
    for fin, node in nodes.items():
        if node in drawn and fin not in ("body", name):
            _, distance, _ = trimesh.proximity.closest_point(rest_body, world(node, rest))
            touching[node] = np.flatnonzero(distance < 1e-3 * length)
    assert sum(len(v) for v in touching.values()) >= 8
    clip = scene.clip("swim")
    worst = 0.0
    for t in np.linspace(0.0, clip.duration, 97):
        posed = pose(scene, float(t), clip)
        body = trimesh.Trimesh(world(nodes["body"], posed), body_faces, process=False)
        for node, idx in touching.items():
            if len(idx):
                _, distance, _ = trimesh.proximity.closest_point(body, world(node, posed)[idx])
                worst = max(worst, float(distance.max()))
    assert worst <= 0.01 * length


def _triangle_overlap(a: np.ndarray, b: np.ndarray) -> float:
    """Area of the intersection of two 2D triangles (Sutherland-Hodgman, b as the clip window)."""
    def signed(poly):
        x, y = poly[:, 0], poly[:, 1]
        return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))

    if signed(a) < 0:
        a = a[::-1]
    if signed(b) < 0:
        b = b[::-1]
    def cross(u, v):
        return float(u[0] * v[1] - u[1] * v[0])

    poly = list(a)
    for k in range(3):
        p, q = b[k], b[(k + 1) % 3]
        edge = q - p
        inside = [cross(edge, v - p) >= 0 for v in poly]
        out = []
        for j, v in enumerate(poly):
            w = poly[(j + 1) % len(poly)]
            if inside[j]:
                out.append(v)
            if inside[j] != inside[(j + 1) % len(poly)]:
                d = w - v
                s = cross(edge, p - v) / cross(edge, d)
                out.append(v + s * d)
        poly = out
        if len(poly) < 3:
            return 0.0
    return abs(signed(np.array(poly)))


@pytest.mark.parametrize("name", SPECIES)
def test_fins_in_the_mid_plane_do_not_overlap(name):
    """The caudal, dorsal, adipose and anal fins share the plane x = 0; where two overlapped, path
    tracers showed black triangles and rasterizers flickered (BonyBream's anal and adipose fins)."""
    scene = build_fish(load_species(PARAMS / f"{name}.txt"), swim="fins")
    rest = pose(scene)
    flat = {}
    for node, prim in scene.drawn():
        points = deformed(scene, node, prim, rest)[0]
        if scene.nodes[node].name != "body" and np.ptp(points[:, 0]) < 1e-9:
            flat[scene.nodes[node].name] = points[:, [2, 1]][prim.indices]
    assert {"caudal_fin", "dorsal_fin", "anal_fin"} <= set(flat)
    length = _body_length(scene)
    names = sorted(flat)
    for i, first in enumerate(names):
        for second in names[i + 1:]:
            area = sum(_triangle_overlap(a, b) for a in flat[first] for b in flat[second])
            assert area <= 1e-9 * length ** 2, (first, second, area)


def _slice_is_simple(segments: np.ndarray) -> bool:
    """No two segments of a cross-section cross, except where they share an end."""
    p, q = segments[:, 0], segments[:, 1]
    d = q - p
    # [i, j]: on which side of segment i's line each end of segment j lies (all pairs at once)
    own = d[:, 0] * p[:, 1] - d[:, 1] * p[:, 0]
    side_p = np.sign(np.outer(d[:, 0], p[:, 1]) - np.outer(d[:, 1], p[:, 0]) - own[:, None])
    side_q = np.sign(np.outer(d[:, 0], q[:, 1]) - np.outer(d[:, 1], q[:, 0]) - own[:, None])
    straddles = side_p * side_q < 0
    i, j = np.nonzero(np.triu(straddles & straddles.T, 1))
    # shared ends only for the pairs that cross (few or none)
    scale = float(np.abs(segments).max())
    shared = np.min(np.stack([np.linalg.norm(p[i] - p[j], axis=1), np.linalg.norm(p[i] - q[j], axis=1),
                              np.linalg.norm(q[i] - p[j], axis=1), np.linalg.norm(q[i] - q[j], axis=1)]),
                    axis=0, initial=np.inf) < 1e-9 * scale
    return bool(np.all(shared))


def test_a_slice_that_crosses_itself_is_caught():
    """The check above finds a bow tie and passes a square, whose sides share their ends."""
    square = np.array([[[0, 0], [1, 0]], [[1, 0], [1, 1]], [[1, 1], [0, 1]], [[0, 1], [0, 0]]], float)
    bow_tie = np.array([[[0, 0], [1, 1]], [[1, 1], [1, 0]], [[1, 0], [0, 1]], [[0, 1], [0, 0]]], float)
    assert _slice_is_simple(square) and not _slice_is_simple(bow_tie)


@pytest.mark.parametrize("sections,circles", [(8, 6), (16, 12), (32, 24), (64, 48), (128, 96)])
def test_the_bent_body_never_intersects_itself(sections, circles):
    """BonyBream's body at each level of detail, with the wave targets a built fish gets, at every
    bend of a beat (the largest included): no cross-section crosses itself."""
    from fishgen.assembly.body_wave import add_wave_targets
    from fishgen.geometry.body import build_body
    from fishgen.geometry.body_wave import wave_weights
    from fishgen.geometry.shapes import profile_for
    from fishgen.scene.model import Mesh, Node, Primitive, Scene

    species = load_species(PARAMS / "bonybream.txt")
    body = build_body(profile_for(species.shape_class, species.shape_params), sections, circles,
                      species.scale, None)
    scene = Scene(name="lod")
    root = scene.add_node(Node(name="lod"))
    positions = body.mesh.positions[:, [2, 1, 0]] * [1, 1, -1]        # glTF axes: nose towards +Z
    mesh = scene.add_mesh(Mesh("body", [Primitive({"POSITION": positions.astype(np.float32)},
                                                  body.mesh.faces.astype(np.uint32))]))
    scene.add_node(Node(name="body", mesh=mesh), parent=root)
    add_wave_targets(scene, WAVE)
    prim = scene.meshes[mesh].primitives[0]
    targets = np.stack([t["POSITION"] for t in prim.targets]).astype(np.float64)
    assert np.ptp(targets[0][:, 0]) > 0.05 * np.ptp(positions[:, 2])  # it does bend
    for phase in np.linspace(0.0, 2 * np.pi, 16, endpoint=False):
        bent = positions + np.einsum("k,knc->nc", wave_weights(np.array(phase)), targets)
        mesh3d = trimesh.Trimesh(bent, prim.indices, process=False)
        lo, hi = mesh3d.bounds[:, 2]
        for z in np.linspace(lo, hi, 60)[1:-1]:
            segments = trimesh.intersections.mesh_plane(mesh3d, [0, 0, 1], [0, 0, z])
            if len(segments) > 2:
                assert _slice_is_simple(segments[:, :, :2]), (sections, phase, z)


@pytest.mark.parametrize("speed, fps", [(7, 30), (100, 30), (10, 240), (5.3, 30)])
def test_the_loop_never_beats_faster_than_the_cap(speed, fps):
    """Whole beats per loop were rounded to the nearest, up past the cap: 8.12 Hz at --speed 7,
    8.33 Hz at --fps 240, 'capped at 8 Hz'."""
    fish = make_fish(load_species(PARAMS / "bonybream.txt"), speed=speed, fps=fps)
    assert fish.facts.tail_beat_hz <= BodyWave().max_frequency


def test_a_loop_below_the_cap_keeps_its_nearest_whole_beats():
    from fishgen.assembly.body_wave import loop_beats, loop_laps

    wave = BodyWave()
    for seconds in (0.1, 0.5, 1.6, 3.2, 7.3):
        for speed in np.arange(0.05, 6.0, 0.05):
            beats, hz = loop_beats(wave, speed, seconds)
            nearest = max(1, round(float(wave.frequency(speed)) * seconds))
            if nearest / seconds <= wave.max_frequency:
                assert beats == nearest
            else:   # rounded down, but a loop too short for one beat under the cap keeps its one
                assert hz <= wave.max_frequency or beats == 1
    assert loop_laps(wave, 1.0, 1.6, 100) == 2   # the shipped bream's loop: 3.2 s at 1.56 Hz
