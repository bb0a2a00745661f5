"""Animation sampling and node posing (pure numpy): the glTF sampler rules."""
from __future__ import annotations

import math

import numpy as np
import pytest

from fishgen.preview.animation import Animation, Channel, Node, pose, sample, slerp


def _qy(deg: float) -> np.ndarray:
    h = math.radians(deg) / 2
    return np.array([0.0, math.sin(h), 0.0, math.cos(h)])


def test_linear_translation_interpolates_and_clamps():
    ch = Channel(0, "translation", np.array([1.0, 3.0]), np.array([[0, 0, 0], [2, 4, 6]], float))
    assert np.allclose(sample(ch, 2.0), [1, 2, 3])
    assert np.allclose(sample(ch, 0.0), [0, 0, 0])      # before the first key: first value
    assert np.allclose(sample(ch, 9.0), [2, 4, 6])      # after the last key: last value


def test_step_holds_the_previous_key():
    ch = Channel(0, "scale", np.array([0.0, 1.0]), np.array([[1, 1, 1], [2, 2, 2]], float), "STEP")
    assert np.allclose(sample(ch, 0.99), [1, 1, 1])
    assert np.allclose(sample(ch, 1.0), [2, 2, 2])


def test_rotation_uses_slerp_not_lerp():
    ch = Channel(0, "rotation", np.array([0.0, 1.0]), np.stack([_qy(0), _qy(90)]))
    assert np.allclose(sample(ch, 0.5), _qy(45))
    assert np.isclose(np.linalg.norm(sample(ch, 0.3)), 1.0)


def test_slerp_takes_the_short_way_round():
    # -q is the same rotation as q; interpolating toward it must not spin through 360 degrees.
    assert np.allclose(np.abs(slerp(_qy(10), -_qy(30), 0.5)), np.abs(_qy(20)))


def test_cubicspline_passes_through_keys_and_uses_tangents():
    # keys (in-tangent, value, out-tangent); zero tangents give smoothstep between values
    values = np.array([[0], [0], [0], [0], [1], [0]], float)
    ch = Channel(0, "translation", np.array([0.0, 1.0]), np.repeat(values, 3, axis=1), "CUBICSPLINE")
    assert np.allclose(sample(ch, 1.0), [1, 1, 1])
    assert np.allclose(sample(ch, 0.5), [0.5] * 3)
    assert np.allclose(sample(ch, 0.25), [0.15625] * 3)   # 3s^2 - 2s^3


def test_pose_composes_parent_rotation_into_child_position():
    nodes = [Node("root"), Node("fin", parent=0, translation=np.array([0.0, 0.0, -1.0]))]
    anim = Animation("swim", [Channel(0, "rotation", np.array([0.0, 1.0]), np.stack([_qy(0), _qy(90)]))])
    rest = pose(nodes, None, 0.0)
    turned = pose(nodes, anim, 1.0)
    assert np.allclose(rest[1][:3, 3], [0, 0, -1])
    assert np.allclose(turned[1][:3, 3], [-1, 0, 0])  # +90 degrees about Y takes -Z to -X
    assert anim.duration == 1.0


def test_matrix_nodes_are_not_animated():
    m = np.eye(4)
    m[:3, 3] = [5, 0, 0]
    nodes = [Node("fixed", matrix=m)]
    anim = Animation("a", [Channel(0, "translation", np.array([0.0]), np.array([[9.0, 9, 9]]))])
    assert np.allclose(pose(nodes, anim, 0.0)[0], m)


def test_cycle_in_hierarchy_is_reported():
    with pytest.raises(ValueError):
        pose([Node("a", parent=1), Node("b", parent=0)], None, 0.0)
