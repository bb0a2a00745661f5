"""Read a glb's morph data and weight keys with pygltflib and numpy alone, independently of
fishgen's scene model and pose code, to measure what a client will play."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pygltflib

_DTYPES = {5126: np.float32, 5123: np.uint16, 5121: np.uint8, 5125: np.uint32, 5122: np.int16, 5120: np.int8}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def accessor(doc: pygltflib.GLTF2, blob: bytes, index: int) -> np.ndarray:
    acc = doc.accessors[index]
    view = doc.bufferViews[acc.bufferView]
    dtype = np.dtype(_DTYPES[acc.componentType])
    width = _WIDTH[acc.type]
    start = (view.byteOffset or 0) + (acc.byteOffset or 0)
    stride = view.byteStride or dtype.itemsize * width
    rows = np.ndarray((acc.count, width), dtype=dtype, buffer=blob, offset=start,
                      strides=(stride, dtype.itemsize))
    out = rows.astype(np.float64)
    if acc.normalized:
        out /= np.iinfo(dtype).max
    return out


def _trs(node: pygltflib.Node) -> np.ndarray:
    m = np.eye(4)
    if node.matrix:
        return np.asarray(node.matrix, float).reshape(4, 4).T
    x, y, z, w = node.rotation or (0, 0, 0, 1)
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m[:3, :3] = r * np.asarray(node.scale or (1, 1, 1), float)
    m[:3, 3] = node.translation or (0, 0, 0)
    return m


@dataclass
class MorphedPart:
    name: str
    world: np.ndarray          # 4x4 rest world matrix of the node
    positions: np.ndarray      # (n, 3) local rest positions
    targets: list[np.ndarray]  # per target (n, 3) local displacements
    times: np.ndarray          # weight key times
    weights: np.ndarray        # (keys, targets)

    def weights_at(self, t: np.ndarray) -> np.ndarray:
        """Linear interpolation of the weight keys (glTF LINEAR), one row per time."""
        columns = range(self.weights.shape[1])
        return np.stack([np.interp(t, self.times, self.weights[:, k]) for k in columns], 1)

    def world_positions(self, t: np.ndarray) -> np.ndarray:
        """(len(t), n, 3) world positions with the morphs applied and the node at rest."""
        w = self.weights_at(np.atleast_1d(t))
        local = self.positions[None] + np.einsum("fk,knc->fnc", w, np.stack(self.targets))
        return local @ self.world[:3, :3].T + self.world[:3, 3]


def morphed_parts(path: Path, animation: int = 0) -> dict[str, MorphedPart]:
    """Every node with a morphed mesh and a weights channel, by node name."""
    doc = pygltflib.GLTF2().load(str(path))
    blob = doc.binary_blob()
    parents = {c: i for i, n in enumerate(doc.nodes) for c in (n.children or [])}

    def world(i: int) -> np.ndarray:
        m = _trs(doc.nodes[i])
        while i in parents:
            i = parents[i]
            m = _trs(doc.nodes[i]) @ m
        return m

    anim = doc.animations[animation]
    keys = {}
    for ch in anim.channels:
        if ch.target.path == "weights":
            smp = anim.samplers[ch.sampler]
            keys[ch.target.node] = (accessor(doc, blob, smp.input)[:, 0],
                                    accessor(doc, blob, smp.output)[:, 0])
    parts = {}
    for i, node in enumerate(doc.nodes):
        if node.mesh is None or i not in keys:
            continue
        prim = doc.meshes[node.mesh].primitives[0]
        targets = [accessor(doc, blob, t["POSITION"]) for t in prim.targets]
        times, flat = keys[i]
        parts[node.name] = MorphedPart(node.name, world(i), accessor(doc, blob, prim.attributes.POSITION),
                                       targets, times, flat.reshape(len(times), len(targets)))
    return parts


def rest_positions(path: Path) -> dict[str, np.ndarray]:
    """World rest positions of every morphed mesh node, by node name."""
    return {name: part.positions @ part.world[:3, :3].T + part.world[:3, 3]
            for name, part in morphed_parts(path).items()}


def node_channels(path: Path, animation: int = 0) -> tuple[pygltflib.GLTF2, dict[tuple[int, str], tuple]]:
    """The document and every channel's keys: (node, path) -> (times, values (keys, width))."""
    doc = pygltflib.GLTF2().load(str(path))
    blob = doc.binary_blob()
    anim = doc.animations[animation]
    out = {}
    for ch in anim.channels:
        smp = anim.samplers[ch.sampler]
        times = accessor(doc, blob, smp.input)[:, 0]
        values = accessor(doc, blob, smp.output)
        out[(ch.target.node, ch.target.path)] = (times, values.reshape(len(times), -1))
    return doc, out
