"""Posing a whole scene at once: every channel, node and instance as numpy arrays.

``fishgen.scene.pose`` evaluates one channel and one node at a time, which is
clear and fine for a fish (a few dozen nodes) but took most of a 200-fish
school's preview (2,000 nodes, 3,000 channels, 1,800 meshes a frame). Here the
same glTF semantics are compiled once per scene and clip into padded arrays and
evaluated for all channels at a time; a primitive shared by many nodes (each
fish of a school) is morphed and placed for all of them in one step. The
results equal ``pose`` / ``deformed`` to rounding (tests/preview/test_posing.py).
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from fishgen.scene.model import Clip, Material, Primitive, Scene
from fishgen.scene.pose import Pose, cofactor, deformed, pose

_PATHS = ("translation", "rotation", "scale")
Placed = tuple[np.ndarray, "np.ndarray | None"]
"""A batch's world positions and normals (``Batch.world``)."""
KEEP_BYTES = 256 << 20
_kept_total = 0
"""Posed vertices all ``Poser``s keep between framing and rendering: 48 frames of a 200-fish school
take 105 MB; a larger loop recomputes what does not fit."""
IDENTITY_QUAT = np.array([0.0, 0.0, 0.0, 1.0])


def _normalize_rows(q: np.ndarray) -> np.ndarray:
    """Unit quaternions; a zero one becomes the identity, as ``pose._normalize`` does."""
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(n > 0, q / np.where(n > 0, n, 1.0), IDENTITY_QUAT)


def _slerp_rows(a: np.ndarray, b: np.ndarray, s: np.ndarray) -> np.ndarray:
    a, b = _normalize_rows(a), _normalize_rows(b)
    d = np.einsum("ij,ij->i", a, b)
    b = np.where((d < 0)[:, None], -b, b)
    d = np.abs(d)
    near = d > 0.9995  # nearly parallel: lerp, as pose.slerp does
    theta = np.arccos(np.minimum(d, 1.0))
    sin = np.where(near, 1.0, np.sin(theta))
    out = (np.sin((1 - s) * theta)[:, None] * a + np.sin(s * theta)[:, None] * b) / sin[:, None]
    return np.where(near[:, None], _normalize_rows(a + s[:, None] * (b - a)), out)


@dataclass
class _Group:
    """Channels of one path, interpolation and value width, keys padded with their last one."""

    path: str
    interpolation: str
    order: np.ndarray    # (C,) index of each channel in the clip: later channels win
    nodes: np.ndarray    # (C,)
    count: np.ndarray    # (C,) keys
    times: np.ndarray    # (C, K)
    values: np.ndarray   # (C, K, W) or (C, K, 3, W) for CUBICSPLINE
    shared: np.ndarray | None = None   # (K,) the times, when every channel has these same keys

    def __post_init__(self) -> None:
        if len(self.times) and (self.count == self.count[0]).all() and (self.times == self.times[0]).all():
            self.shared = self.times[0]

    def sample(self, t: float) -> np.ndarray:
        """(C, W): every channel's value at ``t``, as ``pose.sample`` computes one."""
        rows = np.arange(len(self.nodes))
        cubic = self.interpolation == "CUBICSPLINE"
        keys = self.values

        def at(k: np.ndarray) -> np.ndarray:
            return keys[rows, k, 1] if cubic else keys[rows, k]

        last = self.count - 1
        if self.shared is not None:  # every channel keyed at the same times (a school's): one search
            k = np.full(len(rows), min(max(int(np.searchsorted(self.shared, t, side="right")) - 1, 0),
                                       max(len(self.shared) - 2, 0)))
        else:
            k = np.clip((self.times <= t).sum(1) - 1, 0, np.maximum(last - 1, 0))
        k1 = np.minimum(k + 1, last)
        t0, t1 = self.times[rows, k], self.times[rows, k1]
        span = t1 - t0
        s = np.where(span > 0, (t - t0) / np.where(span > 0, span, 1.0), 0.0)
        if self.interpolation == "STEP":
            out = at(k)
        elif cubic:
            dt = span[:, None]
            p0, m0 = keys[rows, k, 1], keys[rows, k, 2] * dt
            p1, m1 = keys[rows, k1, 1], keys[rows, k1, 0] * dt
            s1 = s[:, None]
            s2, s3 = s1 * s1, s1 * s1 * s1
            out = ((2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s1) * m0
                   + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * m1)
        elif self.path == "rotation":
            out = _slerp_rows(at(k), at(k1), s)
        else:
            out = (1 - s)[:, None] * at(k) + s[:, None] * at(k1)
        first = (self.count == 1) | (t <= self.times[:, 0])
        final = t >= self.times[rows, last]
        out = np.where(first[:, None], at(np.zeros_like(k)), np.where(final[:, None], at(last), out))
        return _normalize_rows(out) if self.path == "rotation" else out


@dataclass
class ArrayPose(Pose):
    """A ``Pose`` that also keeps its world matrices as one (N, 4, 4) array."""

    array: np.ndarray | None = None
    weight_rows: np.ndarray | None = None   # (N, most targets) morph weights, zero-padded
    morphed: np.ndarray | None = None       # (N,) the node has weights


class Poser:
    """``pose(scene, t, clip)`` for one scene and clip, compiled once and evaluated per frame."""

    def __init__(self, scene: Scene, clip: Clip | str | None = None):
        self._scene = weakref.ref(scene)  # poser_for keeps a Poser only while its scene lives
        nodes = scene.nodes
        n = len(nodes)
        self.active = scene.clip(clip) if isinstance(clip, str) or clip is None else clip
        self.translation = np.array([nd.translation for nd in nodes], float).reshape(n, 3)
        self.rotation = np.array([nd.rotation for nd in nodes], float).reshape(n, 4)
        self.scale = np.array([nd.scale for nd in nodes], float).reshape(n, 3)
        self.fixed = np.array([nd.matrix is not None for nd in nodes], bool)
        self.fixed_matrices = {i: np.asarray(nd.matrix, float) for i, nd in enumerate(nodes)
                               if nd.matrix is not None}
        self.rest_weights = {i: np.asarray(scene.meshes[nd.mesh].weights, float)
                             for i, nd in enumerate(nodes)
                             if nd.mesh is not None and scene.meshes[nd.mesh].weights}
        parent = np.full(n, -1)
        for i, nd in enumerate(nodes):
            for c in nd.children:
                if 0 <= c < n and parent[c] < 0:
                    parent[c] = i
        self.parent = parent
        self.levels = self._levels(parent)
        self.groups = self._compile(self.active, n) if self.active is not None else []
        self.most_weights = max([len(p.targets) for m in scene.meshes for p in m.primitives], default=0)
        self.rest_rows, self.rest_morphed = self._rows(self.rest_weights)
        morph_nodes = np.concatenate([np.zeros(0, int)] + [g.nodes for g in self.groups
                                                            if g.path == "weights"])
        self.weights_unique = len(np.unique(morph_nodes)) == len(morph_nodes)
        self.batches = batches(scene)
        self._kept: dict[float | None, tuple[Pose, list[Placed]]] = {}
        self._kept_bytes = 0

    @property
    def scene(self) -> Scene:
        scene = self._scene()
        if scene is None:
            raise ReferenceError("the posed scene is gone")
        return scene

    def forget(self) -> None:
        """Drop the kept frames (a loop is drawn): their bytes go back to ``KEEP_BYTES``."""
        global _kept_total
        _kept_total -= self._kept_bytes
        self._kept, self._kept_bytes = {}, 0

    def frame(self, t: float | None, keep: bool = False) -> tuple[Pose, list[Placed]]:
        """The pose at ``t`` and ``world`` of each of ``batches``. With ``keep`` the result is kept
        (up to ``KEEP_BYTES`` in all) for the next call at ``t``: framing a loop poses every frame,
        and rendering it poses them again."""
        if t in self._kept:
            return self._kept[t]
        posed = self(t)
        out = [b.world(self.scene, posed) for b in self.batches]
        size = sum(p.nbytes + (0 if n is None else n.nbytes) for p, n in out)
        global _kept_total
        if keep and _kept_total + size <= KEEP_BYTES:
            self._kept[t] = (posed, out)
            self._kept_bytes += size
            _kept_total += size
        return posed, out

    @staticmethod
    def _levels(parent: np.ndarray) -> list[np.ndarray] | None:
        """Nodes by depth (roots first), or None for a cycle (``pose`` then raises)."""
        depth = np.zeros(len(parent), int)
        node = parent.copy()
        for _ in range(len(parent) + 1):
            has = node >= 0
            if not has.any():
                return [np.nonzero(depth == d)[0] for d in range(int(depth.max(initial=0)) + 1)]
            depth += has
            node = np.where(has, parent[np.maximum(node, 0)], -1)
        return None

    @staticmethod
    def _compile(clip: Clip, n: int) -> list[_Group]:
        buckets: dict[tuple, list] = {}
        for order, ch in enumerate(clip.channels):
            if not 0 <= ch.node < n:
                continue
            smp = ch.sampler
            times = np.asarray(smp.times, float).ravel()
            values = np.asarray(smp.values, float)
            cubic = smp.interpolation == "CUBICSPLINE"
            keys = values.reshape(len(times), 3, -1) if cubic else values.reshape(len(times), -1)
            buckets.setdefault((ch.path, smp.interpolation, keys.shape[-1]), []).append(
                (order, ch.node, times, keys))
        groups = []
        for (path, interpolation, _), items in buckets.items():
            counts = np.array([len(it[2]) for it in items])
            most = int(counts.max())
            times = np.empty((len(items), most))
            values = np.empty((len(items), most, *items[0][3].shape[1:]))
            for row, (_, _, t, keys) in enumerate(items):  # padded with the last key: never chosen
                times[row, :len(t)], times[row, len(t):] = t, t[-1]
                values[row, :len(t)], values[row, len(t):] = keys, keys[-1]
            groups.append(_Group(path, interpolation, np.array([it[0] for it in items]),
                                 np.array([it[1] for it in items]), counts, times, values))
        return groups

    def _rows(self, weights: dict[int, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """(N, most targets) zero-padded morph weights and (N,) which nodes have any."""
        rows = np.zeros((len(self.fixed), self.most_weights))
        morphed = np.zeros(len(self.fixed), bool)
        if weights:
            morphed[list(weights)] = True
            for width in {len(v) for v in weights.values()}:
                same = [n for n in weights if len(weights[n]) == width]
                keep = min(width, self.most_weights)
                rows[same, :keep] = np.stack([weights[n] for n in same])[:, :keep]
        return rows, morphed

    def __call__(self, t: float | None) -> Pose:
        if self.levels is None:
            return pose(self.scene, t, self.active)  # a cycle: let pose raise its error
        trs = {"translation": self.translation.copy(), "rotation": self.rotation.copy(),
               "scale": self.scale.copy()}
        weights = dict(self.rest_weights)
        rows, morphed = self.rest_rows.copy(), self.rest_morphed.copy()  # the weights as one array
        if t is not None:
            latest: dict[str, list] = {}
            morphs: list[tuple[int, int, np.ndarray]] = []
            for g in self.groups:
                values = g.sample(t)
                if g.path != "weights":
                    latest.setdefault(g.path, []).append((g.order, g.nodes, values))
                elif self.weights_unique:  # one channel a node (a school's): no order to keep
                    weights.update(zip(g.nodes.tolist(), values, strict=True))
                    keep = min(values.shape[1], rows.shape[1])
                    rows[g.nodes, :keep], rows[g.nodes, keep:] = values[:, :keep], 0.0
                    morphed[g.nodes] = True
                else:
                    morphs += zip(g.order.tolist(), g.nodes.tolist(), values, strict=True)
            if morphs:
                morphs.sort(key=lambda item: item[0])  # the last channel of a node wins
                weights.update((node, v) for _, node, v in morphs)
                rows, morphed = self._rows(weights)
            for path in _PATHS:
                if path not in latest:
                    continue
                order = np.concatenate([o for o, _, _ in latest[path]])
                nodes = np.concatenate([nd for _, nd, _ in latest[path]])
                values = np.concatenate([v for _, _, v in latest[path]])
                by_order = np.argsort(order, kind="stable")[::-1]   # the last channel of a node wins
                _, first = np.unique(nodes[by_order], return_index=True)
                pick = by_order[first]
                pick = pick[~self.fixed[nodes[pick]]]
                trs[path][nodes[pick]] = values[pick]
        local = np.zeros((len(self.fixed), 4, 4))
        local[:, :3, :3] = _quat_matrices(trs["rotation"]) * trs["scale"][:, None, :]
        local[:, :3, 3] = trs["translation"]
        local[:, 3, 3] = 1.0
        for i, m in self.fixed_matrices.items():
            local[i] = m
        world = np.empty_like(local)
        for level, idx in enumerate(self.levels):
            world[idx] = local[idx] if level == 0 else world[self.parent[idx]] @ local[idx]
        return ArrayPose(list(world), weights, world, rows, morphed)


_POSERS: dict[tuple[int, int], tuple[weakref.ref, Poser]] = {}


def poser_for(scene: Scene, clip: str | None) -> Poser:
    """The scene's ``Poser`` for ``clip``, compiled once while the scene lives (framing and rendering
    share it)."""
    active = scene.clip(clip)
    key = (id(scene), id(active))
    held = _POSERS.get(key)
    if held is None or held[0]() is not scene or held[1].active is not active:
        for k in [k for k, (ref, _) in _POSERS.items() if ref() is None]:
            del _POSERS[k]
        held = (weakref.ref(scene), Poser(scene, active))
        _POSERS[key] = held
        weakref.finalize(scene, _drop, key, held[1])
    return held[1]


def _drop(key: tuple[int, int], poser: Poser) -> None:
    poser.forget()
    if key in _POSERS and _POSERS[key][1] is poser:
        del _POSERS[key]


def _quat_matrices(q: np.ndarray) -> np.ndarray:
    """(N, 3, 3) rotation matrices of (N, 4) quaternions (x, y, z, w), as ``pose.quat_matrix``."""
    x, y, z, w = _normalize_rows(q).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


@dataclass
class Batch:
    """One primitive and every node that draws it: a school's fish share nine of them."""

    prim: Primitive
    nodes: np.ndarray          # (I,) node indices, in the scene's drawing order
    material: Material | None
    skinned: bool              # posed vertex by vertex with ``deformed`` (rare: no fishgen asset is)
    indices: np.ndarray | None  # (I * F * 3,) the primitive's indices repeated for each instance
    base_pos: np.ndarray       # (V, 3) float64
    base_nrm: np.ndarray | None
    target_pos: np.ndarray     # (T, V, 3) zeros where a target moves no positions
    target_nrm: np.ndarray | None

    @property
    def instances(self) -> int:
        return len(self.nodes)

    def world(self, scene: Scene, posed: Pose,
              normals: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """World positions and unit normals (None without ``normals``) of every instance, stacked:
        (I * V, 3) each."""
        if self.skinned:
            out = [deformed(scene, int(n), self.prim, posed) for n in self.nodes]
            each = [o[1] for o in out]
            nrm: np.ndarray | None = None if not normals or any(n is None for n in each) \
                else np.concatenate(each)  # type: ignore[arg-type]
            return np.concatenate([o[0] for o in out]), nrm
        count = len(self.target_pos)
        w = np.zeros((self.instances, count))
        morphs = np.zeros(self.instances, bool)
        dense = getattr(posed, "weight_rows", None)
        if count and dense is not None and dense.shape[1] >= count:
            w, morphs = dense[self.nodes, :count], posed.morphed[self.nodes]  # type: ignore[attr-defined]
        elif count:
            for row, n in enumerate(self.nodes.tolist()):
                weights = posed.weights.get(n)
                if weights is not None:
                    m = min(count, len(weights))
                    w[row, :m] = weights[:m]
                    morphs[row] = True
        pos = np.broadcast_to(self.base_pos, (self.instances, *self.base_pos.shape))
        nrm = None if self.base_nrm is None or not normals else np.broadcast_to(self.base_nrm, pos.shape)
        if count and morphs.any():
            pos = pos + np.einsum("it,tvc->ivc", w, self.target_pos)
            if nrm is not None and self.target_nrm is not None:
                nrm = nrm + np.einsum("it,tvc->ivc", w, self.target_nrm)
        array = getattr(posed, "array", None)
        mats = array[self.nodes] if array is not None else np.stack([posed.world[int(n)] for n in self.nodes])
        out = pos @ mats[:, :3, :3].transpose(0, 2, 1) + mats[:, None, :3, 3]
        if nrm is not None:
            nrm = nrm @ cofactor(mats[:, :3, :3]).transpose(0, 2, 1)
            length = np.linalg.norm(nrm, axis=-1, keepdims=True)
            nrm = np.where(length > 0, nrm / np.where(length > 0, length, 1), nrm)
            nrm = nrm.reshape(-1, 3)
        return out.reshape(-1, 3), nrm


def batches(scene: Scene, share: bool = True) -> list[Batch]:
    """Every drawn non-point primitive with vertices, grouped by primitive across nodes.

    A BLEND primitive stays one batch per node (``share`` False does so for all):
    transparent meshes are sorted whole, farthest first, before their triangles are.
    """
    keyed: dict[int, list[int]] = {}
    groups: list[tuple[Primitive, list[int]]] = []
    for node, prim in scene.drawn():
        if prim.mode == "POINTS" or not prim.vertex_count:
            continue
        material = scene.materials[prim.material] if prim.material is not None else None
        skinned = scene.nodes[node].skin is not None and "JOINTS_0" in prim.attributes \
            and "WEIGHTS_0" in prim.attributes
        shareable = share and not skinned and (material is None or material.alpha_mode != "BLEND")
        if shareable and id(prim) in keyed:
            keyed[id(prim)].append(node)
            continue
        nodes = [node]
        groups.append((prim, nodes))
        if shareable:
            keyed[id(prim)] = nodes
    return [_batch(scene, prim, np.array(nodes)) for prim, nodes in groups]


def _batch(scene: Scene, prim: Primitive, nodes: np.ndarray) -> Batch:
    material = scene.materials[prim.material] if prim.material is not None else None
    skinned = scene.nodes[int(nodes[0])].skin is not None and "JOINTS_0" in prim.attributes \
        and "WEIGHTS_0" in prim.attributes
    pos = np.asarray(prim.attributes["POSITION"], np.float64)
    nrm = prim.attributes.get("NORMAL")
    nrm = None if nrm is None else np.asarray(nrm, np.float64)
    tp = np.zeros((len(prim.targets), *pos.shape))
    tn = np.zeros_like(tp) if nrm is not None and any("NORMAL" in t for t in prim.targets) else None
    for k, target in enumerate(prim.targets):
        if "POSITION" in target:
            tp[k] = np.asarray(target["POSITION"], np.float64)
        if tn is not None and "NORMAL" in target:
            tn[k] = np.asarray(target["NORMAL"], np.float64)
    indices = None
    if prim.indices is not None and len(prim.indices):
        one = np.asarray(prim.indices, np.int64).ravel()
        indices = (one[None, :] + (np.arange(len(nodes)) * prim.vertex_count)[:, None]).ravel()
    return Batch(prim, nodes, material, skinned, indices, pos, nrm, tp, tn)
