"""Pose a node hierarchy from glTF animation channels (pure numpy, no GL).

Implements glTF 2.0 sampler semantics: LINEAR (slerp for rotations), STEP and
CUBICSPLINE on node translation/rotation/scale; times outside the keyframes
clamp to the first/last key. Weights (morph targets) are not animated here.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

PATHS = ("translation", "rotation", "scale")
INTERPOLATIONS = ("LINEAR", "STEP", "CUBICSPLINE")


@dataclass
class Node:
    """One scene node: local TRS (rotation as x, y, z, w) or an explicit matrix."""

    name: str = ""
    parent: int | None = None
    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 0.0, 1.0]))
    scale: np.ndarray = field(default_factory=lambda: np.ones(3))
    matrix: np.ndarray | None = None  # 4x4, column vectors; wins over TRS (not animatable)


@dataclass
class Channel:
    """Keyframes for one node property; ``values`` is (keys, n) or (3*keys, n) for CUBICSPLINE."""

    node: int
    path: str
    times: np.ndarray
    values: np.ndarray
    interpolation: str = "LINEAR"


@dataclass
class Animation:
    name: str
    channels: list[Channel]

    @property
    def duration(self) -> float:
        ends = [float(c.times[-1]) for c in self.channels if len(c.times)]
        return max(ends, default=0.0)


def _normalize(q: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(q)
    return q / n if n > 0 else np.array([0.0, 0.0, 0.0, 1.0])


def slerp(a: np.ndarray, b: np.ndarray, s: float) -> np.ndarray:
    """Shortest-path spherical interpolation of unit quaternions (x, y, z, w)."""
    a, b = _normalize(np.asarray(a, float)), _normalize(np.asarray(b, float))
    d = float(np.dot(a, b))
    if d < 0.0:  # q and -q are the same rotation: take the short arc
        b, d = -b, -d
    if d > 0.9995:  # nearly parallel: lerp avoids dividing by sin(~0)
        return _normalize(a + s * (b - a))
    theta = np.arccos(min(d, 1.0))
    return (np.sin((1 - s) * theta) * a + np.sin(s * theta) * b) / np.sin(theta)


def sample(channel: Channel, t: float) -> np.ndarray:
    """The channel's value at time ``t`` seconds."""
    times = np.asarray(channel.times, float)
    values = np.asarray(channel.values, float)
    cubic = channel.interpolation == "CUBICSPLINE"
    keys = values.reshape(len(times), 3, -1) if cubic else values.reshape(len(times), -1)
    at = (lambda k: keys[k, 1]) if cubic else (lambda k: keys[k])
    rotation = channel.path == "rotation"
    if len(times) == 1 or t <= times[0]:
        out = at(0)
    elif t >= times[-1]:
        out = at(len(times) - 1)
    else:
        k = int(np.searchsorted(times, t, side="right")) - 1
        t0, t1 = times[k], times[k + 1]
        s = (t - t0) / (t1 - t0) if t1 > t0 else 0.0
        if channel.interpolation == "STEP":
            out = at(k)
        elif cubic:
            dt = t1 - t0
            p0, m0 = keys[k, 1], keys[k, 2] * dt   # value, out-tangent
            p1, m1 = keys[k + 1, 1], keys[k + 1, 0] * dt  # value, in-tangent
            s2, s3 = s * s, s * s * s
            out = ((2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0
                   + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * m1)
        elif rotation:
            out = slerp(at(k), at(k + 1), s)
        else:
            out = (1 - s) * at(k) + s * at(k + 1)
    return _normalize(out) if rotation else np.array(out, float)


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """3x3 rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = _normalize(np.asarray(q, float))
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def trs_matrix(t: np.ndarray, r: np.ndarray, s: np.ndarray) -> np.ndarray:
    """4x4 local matrix T * R * S, as glTF composes it."""
    m = np.eye(4)
    m[:3, :3] = quat_matrix(r) * np.asarray(s, float)[None, :]
    m[:3, 3] = t
    return m


def pose(nodes: list[Node], animation: Animation | None, t: float) -> list[np.ndarray]:
    """World matrices of every node with ``animation`` sampled at ``t`` (None: rest pose)."""
    trs = [[np.asarray(n.translation, float), np.asarray(n.rotation, float),
            np.asarray(n.scale, float)] for n in nodes]
    if animation is not None:
        for ch in animation.channels:
            if ch.path in PATHS and 0 <= ch.node < len(nodes) and nodes[ch.node].matrix is None:
                trs[ch.node][PATHS.index(ch.path)] = sample(ch, t)
    local = [n.matrix if n.matrix is not None else trs_matrix(*trs[i]) for i, n in enumerate(nodes)]
    world: list[np.ndarray | None] = [None] * len(nodes)

    def resolve(i: int, depth: int = 0) -> np.ndarray:
        if world[i] is None:
            parent = nodes[i].parent
            if depth > len(nodes):
                raise ValueError("node hierarchy has a cycle")
            world[i] = local[i] if parent is None else resolve(parent, depth + 1) @ local[i]
        return world[i]

    return [resolve(i) for i in range(len(nodes))]
