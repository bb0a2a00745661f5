"""Pose a scene at a time: glTF sampler semantics, node world matrices, morph targets, skinning.

Pure numpy, no GL: the renderer, the OBJ/PLY writers (rest pose) and the tests
all use it, so an animation is evaluated one way everywhere. Samplers follow
glTF 2.0: LINEAR (slerp for rotations), STEP and CUBICSPLINE; times outside
the keys clamp to the first or last key.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fishgen.scene.model import Channel, Clip, Primitive, Scene

_TRS = ("translation", "rotation", "scale")


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


def dequantized(values: np.ndarray) -> np.ndarray:
    """Key values as floats: normalized integers (a compact file's rotations and weights) divided by
    their type's largest value, as glTF reads them, and never below -1."""
    raw = np.asarray(values)
    if raw.dtype.kind in "iu":
        return np.maximum(raw.astype(np.float64) / np.iinfo(raw.dtype).max, -1.0)
    return raw.astype(np.float64)


def sample(channel: Channel, t: float) -> np.ndarray:
    """The channel's value at time ``t`` seconds."""
    smp = channel.sampler
    times = np.asarray(smp.times, float).ravel()
    values = dequantized(smp.values)
    cubic = smp.interpolation == "CUBICSPLINE"
    keys = values.reshape(len(times), 3, -1) if cubic else values.reshape(len(times), -1)

    def at(k: int) -> np.ndarray:
        return keys[k, 1] if cubic else keys[k]

    rotation = channel.path == "rotation"
    if len(times) == 1 or t <= times[0]:
        out = at(0)
    elif t >= times[-1]:
        out = at(len(times) - 1)
    else:
        k = int(np.searchsorted(times, t, side="right")) - 1
        t0, t1 = times[k], times[k + 1]
        s = (t - t0) / (t1 - t0) if t1 > t0 else 0.0
        if smp.interpolation == "STEP":
            out = at(k)
        elif cubic:
            dt = t1 - t0
            p0, m0 = keys[k, 1], keys[k, 2] * dt          # value, out-tangent
            p1, m1 = keys[k + 1, 1], keys[k + 1, 0] * dt  # value, in-tangent
            s2, s3 = s * s, s * s * s
            out = ((2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0
                   + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * m1)
        elif rotation:
            out = slerp(at(k), at(k + 1), s)
        else:
            out = (1 - s) * at(k) + s * at(k + 1)
    return _normalize(out) if rotation else np.array(out, float)


def sample_many(channel: Channel, ts: np.ndarray) -> np.ndarray:
    """The channel's values (T, width) at every time of ``ts``: :func:`sample`, for a whole
    timeline at once."""
    smp = channel.sampler
    times = np.asarray(smp.times, float).ravel()
    values = dequantized(smp.values)
    cubic = smp.interpolation == "CUBICSPLINE"
    keys = values.reshape(len(times), 3, -1) if cubic else values.reshape(len(times), -1)
    at = keys[:, 1] if cubic else keys
    ts = np.asarray(ts, float).ravel()
    rotation = channel.path == "rotation"
    if len(times) == 1:
        out = np.repeat(at[:1], len(ts), axis=0)
    else:
        k = np.clip(np.searchsorted(times, ts, side="right") - 1, 0, len(times) - 2)
        t0, t1 = times[k], times[k + 1]
        s = np.clip(np.where(t1 > t0, (ts - t0) / np.where(t1 > t0, t1 - t0, 1.0), 0.0), 0.0, 1.0)[:, None]
        a, b = at[k], at[k + 1]
        if smp.interpolation == "STEP":
            out = np.where(s >= 1.0, b, a)
        elif cubic:
            dt = (t1 - t0)[:, None]
            m0, m1 = keys[k, 2] * dt, keys[k + 1, 0] * dt
            s2, s3 = s * s, s * s * s
            out = ((2 * s3 - 3 * s2 + 1) * a + (s3 - 2 * s2 + s) * m0
                   + (-2 * s3 + 3 * s2) * b + (s3 - s2) * m1)
        elif rotation:
            out = _slerp_many(a, b, s)
        else:
            out = (1 - s) * a + s * b
    if rotation:
        norm = np.linalg.norm(out, axis=1, keepdims=True)
        out = np.where(norm > 0, out / np.where(norm > 0, norm, 1.0), np.array([0.0, 0.0, 0.0, 1.0]))
    return np.asarray(out, float)


def _slerp_many(a: np.ndarray, b: np.ndarray, s: np.ndarray) -> np.ndarray:
    """:func:`slerp` row by row: (T, 4) from (T, 4), (T, 4) and (T, 1)."""
    a = a / np.maximum(np.linalg.norm(a, axis=1, keepdims=True), 1e-300)
    b = b / np.maximum(np.linalg.norm(b, axis=1, keepdims=True), 1e-300)
    d = np.einsum("ij,ij->i", a, b)[:, None]
    b = np.where(d < 0, -b, b)
    d = np.abs(d)
    theta = np.arccos(np.minimum(d, 1.0))
    sin = np.sin(theta)
    near = d > 0.9995
    safe = np.where(near, 1.0, sin)
    far = (np.sin((1 - s) * theta) * a + np.sin(s * theta) * b) / safe
    return np.where(near, a + s * (b - a), far)


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """3x3 rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = _normalize(np.asarray(q, float))
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def quat_matrices(q: np.ndarray, normalize: bool = True) -> np.ndarray:
    """(..., 3, 3) rotation matrices of (..., 4) quaternions (x, y, z, w), normalized first unless
    ``normalize`` is False (then the unit formula as it stands, which is what USD applies to an
    instancer's half-precision orientations)."""
    q = np.asarray(q, float)
    if normalize:
        norm = np.linalg.norm(q, axis=-1, keepdims=True)
        q = np.where(norm > 0, q / np.where(norm > 0, norm, 1.0), [0.0, 0.0, 0.0, 1.0])
    x, y, z, w = np.moveaxis(q, -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def trs_matrix(t, r, s) -> np.ndarray:
    """4x4 local matrix T * R * S, as glTF composes it."""
    m = np.eye(4)
    m[:3, :3] = quat_matrix(np.asarray(r, float)) * np.asarray(s, float)[None, :]
    m[:3, 3] = t
    return m


@dataclass
class Pose:
    """World matrices of every node and morph weights of every node, at one time."""

    world: list[np.ndarray]
    weights: dict[int, np.ndarray]

    def matrix(self, node: int | None) -> np.ndarray:
        return np.eye(4) if node is None else self.world[node]


def pose(scene: Scene, t: float | None = None, clip: Clip | str | None = None) -> Pose:
    """Pose ``scene`` at ``t`` seconds of ``clip`` (a Clip or its name; None: the rest pose)."""
    nodes = scene.nodes
    trs = [[np.asarray(n.translation, float), np.asarray(n.rotation, float),
            np.asarray(n.scale, float)] for n in nodes]
    weights: dict[int, np.ndarray] = {}
    for i, n in enumerate(nodes):
        if n.mesh is not None and scene.meshes[n.mesh].weights:
            weights[i] = np.asarray(scene.meshes[n.mesh].weights, float)
    active = scene.clip(clip) if isinstance(clip, str) or clip is None else clip
    if t is not None and active is not None:
        for ch in active.channels:
            if not 0 <= ch.node < len(nodes):
                continue
            value = sample(ch, t)
            if ch.path == "weights":
                weights[ch.node] = value
            elif nodes[ch.node].matrix is None:
                trs[ch.node][_TRS.index(ch.path)] = value
    local = [n.matrix if n.matrix is not None else trs_matrix(*trs[i]) for i, n in enumerate(nodes)]
    parent: dict[int, int] = {}
    for i, n in enumerate(nodes):
        for c in n.children:
            parent.setdefault(c, i)
    world: list[np.ndarray | None] = [None] * len(nodes)
    for i in range(len(nodes)):  # iterative walk up: hierarchies may be deep
        chain = []
        j: int | None = i
        while j is not None and world[j] is None:
            chain.append(j)
            j = parent.get(j)
            if len(chain) > len(nodes):
                raise ValueError("node hierarchy has a cycle")
        above = np.eye(4) if j is None else world[j]
        for k in reversed(chain):
            above = above @ local[k]
            world[k] = above
    return Pose([w if w is not None else np.eye(4) for w in world], weights)


def deformed(scene: Scene, node: int, prim: Primitive, posed: Pose) -> tuple[np.ndarray, np.ndarray | None]:
    """World-space positions and normals of ``prim`` on ``node``: morph targets, then skin or node.

    Follows glTF: morphed = base + sum(w_i * target_i); a skinned mesh ignores its
    node's transform and takes sum(weight_j * joint_world_j * inverse_bind_j).
    """
    pos = np.asarray(prim.attributes["POSITION"], np.float64)
    nrm = prim.attributes.get("NORMAL")
    nrm = None if nrm is None else np.asarray(nrm, np.float64)
    w = posed.weights.get(node)
    if prim.targets and w is not None:
        for weight, target in zip(w, prim.targets, strict=False):  # a file may list more or fewer
            if weight == 0:
                continue
            if "POSITION" in target:
                pos = pos + weight * np.asarray(target["POSITION"], np.float64)
            if nrm is not None and "NORMAL" in target:
                nrm = nrm + weight * np.asarray(target["NORMAL"], np.float64)
    skin_index = scene.nodes[node].skin
    if skin_index is not None and "JOINTS_0" in prim.attributes and "WEIGHTS_0" in prim.attributes:
        skin = scene.skins[skin_index]
        joint_mats = np.stack([posed.world[j] for j in skin.joints]) @ np.asarray(skin.inverse_bind_matrices)
        joints = np.asarray(prim.attributes["JOINTS_0"], np.int64)
        wts = dequantized(prim.attributes["WEIGHTS_0"])  # normalized integers read as glTF reads them
        blend = np.einsum("nk,nkij->nij", wts, joint_mats[joints])  # (n, 4, 4) per vertex
        out = np.einsum("nij,nj->ni", blend[:, :3, :3], pos) + blend[:, :3, 3]
        if nrm is not None:
            nrm = np.einsum("nij,nj->ni", cofactor(blend[:, :3, :3]), nrm)
    else:
        m = posed.world[node]
        out = pos @ m[:3, :3].T + m[:3, 3]
        if nrm is not None:
            nrm = nrm @ cofactor(m[:3, :3]).T
    if nrm is not None:
        length = np.linalg.norm(nrm, axis=1, keepdims=True)
        nrm = np.where(length > 0, nrm / np.where(length > 0, length, 1), nrm)
    return out, nrm


def cofactor(m: np.ndarray) -> np.ndarray:
    """The normal transform of (..., 3, 3) linear maps: |det M| inv(M)^T, as a signed cofactor matrix.

    Unlike inv(M)^T it is defined (and zero, not an error) for a map that scales a
    node or joint to nothing; the sign keeps a mirrored map's normals pointing out.
    """
    a, b, c = m[..., :, 0], m[..., :, 1], m[..., :, 2]
    bc = _cross(b, c)
    cof = np.stack([bc, _cross(c, a), _cross(a, b)], axis=-1)
    det = np.einsum("...i,...i->...", a, bc)
    return np.where((det < 0)[..., None, None], -cof, cof)


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``np.cross`` of (..., 3) vectors, the same products and differences written out: np.cross's
    own set-up cost 10 us a call, and a fit poses one node at a time, 38,000 times in a test file."""
    return np.stack([u[..., 1] * v[..., 2] - u[..., 2] * v[..., 1],
                     u[..., 2] * v[..., 0] - u[..., 0] * v[..., 2],
                     u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]], axis=-1)


def bounds(scene: Scene, t: float | None = None, clip: Clip | str | None = None) -> np.ndarray:
    """(2, 3) min and max corner of every drawn vertex, posed (None: rest pose)."""
    posed = pose(scene, t, clip)
    points = [deformed(scene, node, prim, posed)[0] for node, prim in scene.drawn()
              if prim.vertex_count]
    if not points:
        return np.zeros((2, 3))
    allp = np.concatenate(points)
    return np.stack([allp.min(axis=0), allp.max(axis=0)])
