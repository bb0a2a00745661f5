"""Read a glTF 2.0 asset (.glb / .gltf, or GLB bytes) into the scene model.

Uses pygltflib for the JSON and does the accessor decoding itself, so that
alpha modes, double-sidedness, POINTS primitives with ``_RADIUS``, skins,
morph targets and every animation channel survive (general mesh loaders drop
some of them). Side files are read only from the asset's own folder.
"""
from __future__ import annotations

import base64
from pathlib import Path
from typing import cast

import numpy as np

from fishgen.errors import FishgenError, describe
from fishgen.exchange.sidefiles import side_file
from fishgen.scene.model import (
    INTERPOLATIONS,
    PATHS,
    Channel,
    Clip,
    Image,
    Material,
    Mesh,
    Node,
    Primitive,
    PrimitiveMode,
    Sampler,
    Scene,
    Skin,
)

_DTYPES: dict[int, type[np.number]] = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16,
           5125: np.uint32, 5126: np.float32}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
_MODES: dict[int, PrimitiveMode] = {0: "POINTS", 4: "TRIANGLES", 5: "TRIANGLES", 6: "TRIANGLES"}


def read_gltf(path: str | Path | None = None, *, data: bytes | None = None,
              label: str | None = None, **_) -> Scene:
    """Load a .glb/.gltf file (or GLB ``data``) as a Scene; bad files raise FishgenError."""
    import pygltflib

    where = str(path) if path is not None else "<glb>"
    try:
        if data is not None:
            gltf = pygltflib.GLTF2.load_from_bytes(data)
        else:
            gltf = pygltflib.GLTF2.load(str(path))
        if gltf is None:
            raise ValueError("empty file")
        return _Reader(gltf, Path(path) if path is not None else None, where).scene(
            label if label is not None else (Path(path).stem if path else ""))
    except FishgenError:
        raise
    except Exception as err:  # pygltflib raises anything from KeyError to JSONDecodeError
        raise FishgenError(f"not a readable glTF asset ({type(err).__name__}: {one_line(err)})",
                           where) from None


def one_line(err: BaseException, limit: int = 200) -> str:
    """A library's error message squeezed onto one short line for ours."""
    text = " ".join(str(err).split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


class _Reader:
    def __init__(self, gltf, asset: Path | None, where: str):
        self.g, self.asset, self.where = gltf, asset, where
        self._buffers: dict[int, bytes] = {}
        self._images: dict[int, np.ndarray] = {}

    # -- raw data -------------------------------------------------------------
    def _uri(self, uri: str) -> bytes:
        if uri.strip().startswith("data:"):
            return base64.b64decode(uri.split(",", 1)[1])
        if self.asset is None:  # GLB bytes from memory have no folder to take side files from
            raise FishgenError(f"expected only embedded data, found a reference to {describe(uri)}",
                               self.where)
        # Only files in the asset's folder (glTF URIs are percent-encoded: "my%20skin.png").
        target = side_file(self.asset, uri, uri=True)
        if not target.is_file():
            raise FishgenError(f"expected a file beside the asset, found no {uri!r}", self.where)
        return target.read_bytes()

    def buffer(self, i: int) -> bytes:
        if i not in self._buffers:
            buf = self.g.buffers[i]
            self._buffers[i] = self._uri(buf.uri) if buf.uri else (self.g.binary_blob() or b"")
        return self._buffers[i]

    def view_bytes(self, i: int) -> tuple[bytes, int, int | None]:
        view = self.g.bufferViews[i]
        return self.buffer(view.buffer), view.byteOffset or 0, view.byteStride

    def accessor(self, i: int) -> np.ndarray:
        acc = self.g.accessors[i]
        dtype, width = np.dtype(_DTYPES[acc.componentType]), _WIDTH[acc.type]
        if acc.bufferView is None:
            out = np.zeros((acc.count, width), dtype)
        else:
            raw, offset, stride = self.view_bytes(acc.bufferView)
            offset += acc.byteOffset or 0
            item = dtype.itemsize * width
            stride = stride or item
            if stride == item:
                out = np.frombuffer(raw, dtype, acc.count * width, offset).reshape(acc.count, width)
            else:  # interleaved: view the rows through a strided window
                rows = np.frombuffer(raw, np.uint8, stride * (acc.count - 1) + item, offset)
                out = np.lib.stride_tricks.as_strided(rows, (acc.count, item), (stride, 1))
                out = np.ascontiguousarray(out).view(dtype).reshape(acc.count, width)
        if acc.sparse is not None:
            out = out.copy()
            idx = self._sparse(acc.sparse.indices, acc.sparse.count, acc.sparse.indices.componentType, 1)
            val = self._sparse(acc.sparse.values, acc.sparse.count, acc.componentType, width)
            out[idx.ravel()] = val
        if acc.normalized and dtype.kind in "iu":
            out = np.maximum(out.astype(np.float32) / np.iinfo(dtype).max, -1.0)
        return out

    def _sparse(self, part, count: int, ctype: int, width: int) -> np.ndarray:
        raw, offset, _ = self.view_bytes(part.bufferView)
        return np.frombuffer(raw, _DTYPES[ctype], count * width,
                             offset + (part.byteOffset or 0)).reshape(count, width)

    def image_bytes(self, i: int) -> bytes:
        img = self.g.images[i]
        if img.bufferView is not None:
            raw, offset, _ = self.view_bytes(img.bufferView)
            return bytes(raw[offset: offset + self.g.bufferViews[img.bufferView].byteLength])
        return self._uri(img.uri)

    # -- scene ------------------------------------------------------------------
    def material(self, k: int) -> Material:
        m = self.g.materials[k]
        pbr = m.pbrMetallicRoughness
        texture = None
        if pbr is not None and pbr.baseColorTexture is not None:
            texture = self.g.textures[pbr.baseColorTexture.index].source
        factor = tuple(pbr.baseColorFactor) if pbr is not None and pbr.baseColorFactor else (1, 1, 1, 1)
        # The tuple's length is the file's, as read (the glTF schema fixes it; not checked here).
        base_color = cast(tuple[float, float, float, float], tuple(float(v) for v in factor))
        return Material(name=m.name or f"material{k}", base_color=base_color,
                        texture=texture, alpha_mode=m.alphaMode or "OPAQUE",
                        alpha_cutoff=None if m.alphaCutoff is None else float(m.alphaCutoff),
                        double_sided=bool(m.doubleSided),
                        unlit="KHR_materials_unlit" in (m.extensions or {}))

    def primitive(self, prim) -> Primitive | None:
        mode = 4 if prim.mode is None else prim.mode
        if prim.attributes.POSITION is None or mode not in _MODES:
            return None  # lines have no surface to preview
        attributes = {name: self.accessor(index) for name, index in vars(prim.attributes).items()
                      if index is not None}
        attributes = {name: (a.ravel() if a.shape[1] == 1 else a) for name, a in attributes.items()}
        attributes["POSITION"] = attributes["POSITION"].astype(np.float32)
        n = len(attributes["POSITION"])
        indices = None
        if _MODES[mode] == "TRIANGLES":
            flat = (self.accessor(prim.indices).ravel().astype(np.uint32) if prim.indices is not None
                    else np.arange(n, dtype=np.uint32))
            if len(flat) and int(flat.max()) >= n:  # the GPU would read past the vertices
                raise FishgenError(f"expected vertex indices below {n}, found {int(flat.max())}", self.where)
            indices = _triangles(flat, mode)
        targets = [{name: self.accessor(index).astype(np.float32) for name, index in target.items()
                    if index is not None} for target in (prim.targets or [])]
        return Primitive(attributes, indices, prim.material, _MODES[mode], targets)

    def scene(self, label: str) -> Scene:
        g = self.g
        scene = Scene(name=label, info={"source": self.where})
        for k, m in enumerate(g.meshes):
            prims = [p for p in (self.primitive(prim) for prim in m.primitives) if p is not None]
            scene.meshes.append(Mesh(m.name or f"mesh{k}", prims, [float(w) for w in (m.weights or [])]))
        scene.images = [Image(img.name or f"image{k}", self.image_bytes(k), img.mimeType or "image/png")
                        for k, img in enumerate(g.images)]
        scene.materials = [self.material(k) for k in range(len(g.materials))]
        for i, n in enumerate(g.nodes):
            node = Node(name=n.name or f"node{i}", children=list(n.children or []), mesh=n.mesh, skin=n.skin)
            if n.matrix is not None and list(n.matrix) != [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]:
                node.matrix = np.asarray(n.matrix, float).reshape(4, 4).T  # column-major
            # TRS lengths are the file's, as read (the glTF schema fixes them; not checked here).
            if n.translation is not None:
                node.translation = cast(tuple[float, float, float], tuple(float(v) for v in n.translation))
            if n.rotation is not None:
                node.rotation = cast(tuple[float, float, float, float], tuple(float(v) for v in n.rotation))
            if n.scale is not None:
                node.scale = cast(tuple[float, float, float], tuple(float(v) for v in n.scale))
            scene.nodes.append(node)
        for k, skin in enumerate(g.skins or []):
            joints = list(skin.joints or [])
            if skin.inverseBindMatrices is not None:
                ibm = (self.accessor(skin.inverseBindMatrices).astype(float)
                       .reshape(-1, 4, 4).transpose(0, 2, 1))
            else:
                ibm = np.repeat(np.eye(4)[None], len(joints), axis=0)
            scene.skins.append(Skin(skin.name or f"skin{k}", joints, ibm, skin.skeleton))
        # Only nodes reachable from the default scene are drawn, as an engine would.
        scene.roots = list(g.scenes[g.scene or 0].nodes or []) if g.scenes else \
            [i for i in range(len(g.nodes)) if not any(i in (n.children or []) for n in g.nodes)]
        for k, a in enumerate(g.animations or []):
            channels = []
            for ch in a.channels:
                smp = a.samplers[ch.sampler]
                interp = smp.interpolation or "LINEAR"
                if ch.target.node is None or ch.target.path not in PATHS or interp not in INTERPOLATIONS:
                    continue
                times = self.accessor(smp.input).astype(float).ravel()
                values = self.accessor(smp.output).astype(float)
                if ch.target.path == "weights":
                    values = values.reshape(len(times) * (3 if interp == "CUBICSPLINE" else 1), -1)
                channels.append(Channel(ch.target.node, ch.target.path, Sampler(times, values, interp)))
            scene.clips.append(Clip(a.name or f"clip{k}", channels))
        return scene


def _triangles(flat: np.ndarray, mode: int) -> np.ndarray:
    """Triangle list from TRIANGLES / TRIANGLE_STRIP / TRIANGLE_FAN indices."""
    if mode == 4:
        return flat[: len(flat) // 3 * 3].reshape(-1, 3)
    n = len(flat) - 2
    if n <= 0:
        return np.zeros((0, 3), np.uint32)
    k = np.arange(n)
    if mode == 5:  # strip: odd triangles swap winding to keep faces consistent
        a, b = np.where(k % 2 == 0, k, k + 1), np.where(k % 2 == 0, k + 1, k)
        return np.stack([flat[a], flat[b], flat[k + 2]], 1)
    return np.stack([np.full(n, flat[0]), flat[k + 1], flat[k + 2]], 1)  # fan
