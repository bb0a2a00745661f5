"""Posing a scene (pure numpy): the glTF sampler rules, node hierarchies, morph targets and skins."""
from __future__ import annotations

import math

import numpy as np
import pytest

from fishgen.scene.model import Channel, Clip, Mesh, Node, Primitive, Sampler, Scene, Skin
from fishgen.scene.pose import deformed, pose, sample, slerp


def channel(node, path, times, values, interpolation="LINEAR"):
    return Channel(node, path, Sampler(np.asarray(times, float), np.asarray(values, float), interpolation))


def scene_of(*nodes, roots=(0,), meshes=(), skins=(), clips=()):
    return Scene(nodes=list(nodes), roots=list(roots), meshes=list(meshes), skins=list(skins),
                 clips=list(clips))


def _qy(deg: float) -> np.ndarray:
    h = math.radians(deg) / 2
    return np.array([0.0, math.sin(h), 0.0, math.cos(h)])


def test_linear_translation_interpolates_and_clamps():
    ch = channel(0, "translation", [1.0, 3.0], [[0, 0, 0], [2, 4, 6]])
    assert np.allclose(sample(ch, 2.0), [1, 2, 3])
    assert np.allclose(sample(ch, 0.0), [0, 0, 0])      # before the first key: first value
    assert np.allclose(sample(ch, 9.0), [2, 4, 6])      # after the last key: last value


def test_step_holds_the_previous_key():
    ch = channel(0, "scale", [0.0, 1.0], [[1, 1, 1], [2, 2, 2]], "STEP")
    assert np.allclose(sample(ch, 0.99), [1, 1, 1])
    assert np.allclose(sample(ch, 1.0), [2, 2, 2])


def test_rotation_uses_slerp_not_lerp():
    ch = channel(0, "rotation", [0.0, 1.0], np.stack([_qy(0), _qy(90)]))
    assert np.allclose(sample(ch, 0.5), _qy(45))
    assert np.isclose(np.linalg.norm(sample(ch, 0.3)), 1.0)


def test_slerp_takes_the_short_way_round():
    # -q is the same rotation as q; interpolating toward it must not spin through 360 degrees.
    assert np.allclose(np.abs(slerp(_qy(10), -_qy(30), 0.5)), np.abs(_qy(20)))


def test_cubicspline_passes_through_keys_and_uses_tangents():
    # keys (in-tangent, value, out-tangent); zero tangents give smoothstep between values
    values = np.array([[0], [0], [0], [0], [1], [0]], float)
    ch = channel(0, "translation", [0.0, 1.0], np.repeat(values, 3, axis=1), "CUBICSPLINE")
    assert np.allclose(sample(ch, 1.0), [1, 1, 1])
    assert np.allclose(sample(ch, 0.5), [0.5] * 3)
    assert np.allclose(sample(ch, 0.25), [0.15625] * 3)   # 3s^2 - 2s^3


def test_pose_composes_parent_rotation_into_child_position():
    anim = Clip("swim", [channel(0, "rotation", [0.0, 1.0], np.stack([_qy(0), _qy(90)]))])
    scene = scene_of(Node("root", children=[1]), Node("fin", translation=(0.0, 0.0, -1.0)), clips=[anim])
    rest, turned = pose(scene), pose(scene, 1.0, "swim")
    assert np.allclose(rest.world[1][:3, 3], [0, 0, -1])
    assert np.allclose(turned.world[1][:3, 3], [-1, 0, 0])  # +90 degrees about Y takes -Z to -X
    assert anim.duration == 1.0


def test_matrix_nodes_are_not_animated():
    m = np.eye(4)
    m[:3, 3] = [5, 0, 0]
    anim = Clip("a", [channel(0, "translation", [0.0], [[9.0, 9, 9]])])
    assert np.allclose(pose(scene_of(Node("fixed", matrix=m), clips=[anim]), 0.0).world[0], m)


def test_cycle_in_hierarchy_is_reported():
    with pytest.raises(ValueError):
        pose(scene_of(Node("a", children=[1]), Node("b", children=[0])))


def test_zero_scale_hides_a_node_without_failing():
    tri = Primitive({"POSITION": np.eye(3, dtype=np.float32)}, np.array([[0, 1, 2]], np.uint32))
    scene = scene_of(Node("gone", scale=(0.0, 0.0, 0.0), mesh=0), meshes=[Mesh("m", [tri])])
    posed = pose(scene)
    assert np.allclose(deformed(scene, 0, tri, posed)[0], 0)


def test_morph_weights_animate_and_add_displacements():
    base = np.zeros((2, 3), np.float32)
    up = np.array([[0, 1, 0], [0, 1, 0]], np.float32)
    side = np.array([[1, 0, 0], [0, 0, 0]], np.float32)
    prim = Primitive({"POSITION": base}, mode="POINTS", targets=[{"POSITION": up}, {"POSITION": side}])
    clip = Clip("wave", [channel(0, "weights", [0.0, 1.0], [[0.0, 0.0], [1.0, 0.5]])])
    scene = scene_of(Node("n", mesh=0, translation=(0.0, 0.0, 2.0)), meshes=[Mesh("m", [prim], [0.0, 0.0])],
                     clips=[clip])
    pos, _ = deformed(scene, 0, prim, pose(scene, 0.5, "wave"))
    assert np.allclose(pos, [[0.25, 0.5, 2.0], [0.0, 0.5, 2.0]])   # weights (0.5, 0.25), then the node


def test_skin_follows_its_joints_and_ignores_its_own_node():
    # Two joints along +Z; vertex 0 on joint 0, vertex 1 on joint 1, vertex 2 half and half.
    joints = np.array([[0, 0, 0, 0], [1, 0, 0, 0], [0, 1, 0, 0]], np.uint16)
    weights = np.array([[1, 0, 0, 0], [1, 0, 0, 0], [0.5, 0.5, 0, 0]], np.float32)
    positions = np.array([[0, 0, 0], [0, 0, 2], [0, 0, 2]], np.float32)
    prim = Primitive({"POSITION": positions, "JOINTS_0": joints, "WEIGHTS_0": weights}, mode="POINTS")
    ibm = np.stack([np.eye(4), np.eye(4)])
    ibm[1][:3, 3] = [0, 0, -1]                                  # joint 1 sits at z = 1 at rest
    clip = Clip("bend", [channel(2, "rotation", [0.0, 1.0], np.stack([_qy(0), _qy(90)]))])
    scene = scene_of(Node("skinned", mesh=0, skin=0, translation=(7.0, 7.0, 7.0)),
                     Node("j0", children=[2]), Node("j1", translation=(0.0, 0.0, 1.0)),
                     roots=(0, 1), meshes=[Mesh("m", [prim])], skins=[Skin("s", [1, 2], ibm)], clips=[clip])
    rest, _ = deformed(scene, 0, prim, pose(scene))
    assert np.allclose(rest, positions)                         # the skinned node's own TRS is ignored
    bent, _ = deformed(scene, 0, prim, pose(scene, 1.0, "bend"))
    # joint 1 turned 90 degrees about Y: a point 1 past it swings from +Z to +X
    assert np.allclose(bent[0], [0, 0, 0]) and np.allclose(bent[1], [1, 0, 1])
    assert np.allclose(bent[2], [0.5, 0, 1.5])                 # linear blend of the two joints


def test_normals_follow_mirrors_and_survive_a_zero_scale():
    prim = Primitive({"POSITION": np.array([[1, 0, 0]], np.float32),
                      "NORMAL": np.array([[1, 0, 0]], np.float32)},
                     mode="POINTS")
    for scale, expected in (((-1.0, 1.0, 1.0), [-1, 0, 0]), ((2.0, 1.0, 1.0), [1, 0, 0]),
                            ((0.0, 1.0, 1.0), [1, 0, 0])):
        scene = scene_of(Node("n", mesh=0, scale=scale), meshes=[Mesh("m", [prim])])
        _, normals = deformed(scene, 0, prim, pose(scene))
        assert np.all(np.isfinite(normals)) and np.allclose(normals, expected), scale


def test_normalized_integer_skin_weights_read_as_fractions():
    """WEIGHTS_0 as normalized unsigned bytes (255 = 1.0), as a merged fish stores them."""
    positions = np.array([[0, 0, 2], [0, 0, 2]], np.float32)
    joints = np.array([[1, 0, 0, 0], [0, 1, 0, 0]], np.uint8)
    weights = np.array([[255, 0, 0, 0], [128, 127, 0, 0]], np.uint8)
    prim = Primitive({"POSITION": positions, "JOINTS_0": joints, "WEIGHTS_0": weights}, mode="POINTS")
    ibm = np.stack([np.eye(4), np.eye(4)])
    ibm[1][:3, 3] = [0, 0, -1]
    clip = Clip("bend", [channel(2, "rotation", [0.0, 1.0], np.stack([_qy(0), _qy(90)]))])
    scene = scene_of(Node("skinned", mesh=0, skin=0), Node("j0", children=[2]),
                     Node("j1", translation=(0.0, 0.0, 1.0)), roots=(0, 1), meshes=[Mesh("m", [prim])],
                     skins=[Skin("s", [1, 2], ibm)], clips=[clip])
    assert np.allclose(deformed(scene, 0, prim, pose(scene))[0], positions)       # not 255 times as far
    bent, _ = deformed(scene, 0, prim, pose(scene, 1.0, "bend"))
    assert np.allclose(bent[0], [1, 0, 1]) and np.allclose(bent[1], [127 / 255, 0, 1 + 128 / 255], atol=1e-6)


def test_normalized_integer_keys_play_as_floats():
    """A compact file's rotations (signed shorts) and weights (unsigned shorts), divided as glTF says."""
    q = np.round(np.stack([_qy(0), _qy(90)]) * 32767).astype(np.int16)
    spin = Channel(0, "rotation", Sampler(np.array([0.0, 1.0]), q))
    assert np.allclose(sample(spin, 1.0), _qy(90), atol=1e-4)
    w = Channel(0, "weights", Sampler(np.array([0.0, 1.0]), np.array([[0, 65535], [65535, 0]], np.uint16)))
    assert np.allclose(sample(w, 0.25), [0.25, 0.75])


@pytest.mark.parametrize("interpolation", ["LINEAR", "STEP", "CUBICSPLINE"])
@pytest.mark.parametrize("path", ["translation", "rotation", "weights"])
def test_a_whole_timeline_samples_as_each_time_alone(path, interpolation):
    """sample_many is sample at every time: between keys, on them, before the first and after the last."""
    from fishgen.scene.pose import sample_many

    rng = np.random.default_rng(4)
    times = np.array([0.0, 0.4, 0.5, 1.5])
    width = 4 if path in ("rotation", "weights") else 3
    values = rng.normal(size=(len(times) * (3 if interpolation == "CUBICSPLINE" else 1), width))
    ch = channel(0, path, times, values, interpolation)
    at = np.concatenate([[-1.0], np.linspace(0, 1.5, 31), [0.4, 2.0]])
    assert np.abs(sample_many(ch, at) - np.stack([sample(ch, t) for t in at])).max() < 1e-12


def test_rotation_matrices_of_many_quaternions_are_each_ones():
    from fishgen.scene.pose import quat_matrices, quat_matrix

    q = np.random.default_rng(5).normal(size=(6, 2, 4)) * 3     # not unit: both normalize
    many = quat_matrices(q)
    assert many.shape == (6, 2, 3, 3)
    assert np.allclose(many, [[quat_matrix(b) for b in a] for a in q])
    unit = q / np.linalg.norm(q, axis=-1, keepdims=True)
    assert np.allclose(quat_matrices(unit, normalize=False), many)
    assert not np.allclose(quat_matrices(q, normalize=False), many)  # the unit formula, as it stands
