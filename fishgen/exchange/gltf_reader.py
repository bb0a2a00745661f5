"""Read a glTF 2.0 asset (.glb / .gltf, or GLB bytes) into a preview ``Scene``.

Uses pygltflib for the JSON and does the accessor decoding itself, so that
alpha modes, double-sidedness, POINTS primitives with a ``_RADIUS`` attribute
and the animation channels all survive (general mesh loaders drop some of them).
"""
from __future__ import annotations

import base64
import io
from pathlib import Path

import numpy as np

from fishgen.errors import FishgenError, describe
from fishgen.preview.animation import INTERPOLATIONS, PATHS, Animation, Channel, Node
from fishgen.preview.scene import (Material, MeshPart, PointPart, Scene, vertex_normals)
from fishgen.preview.sidefiles import side_file

_DTYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16,
           5125: np.uint32, 5126: np.float32}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
POINT_SIZE_FRACTION = 0.004
"""Radius of particles that carry no ``_RADIUS``, as a fraction of the bounding-box diagonal."""


def read_gltf(path: str | Path | None = None, *, data: bytes | None = None,
              label: str | None = None) -> Scene:
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
        raise FishgenError(f"not a readable glTF asset ({type(err).__name__}: {one_line(err)})", where) from None


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
            raise FishgenError(f"expected only embedded data, found a reference to {describe(uri)}", self.where)
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

    def image(self, i: int) -> np.ndarray:
        from PIL import Image

        if i not in self._images:
            img = self.g.images[i]
            if img.bufferView is not None:
                raw, offset, _ = self.view_bytes(img.bufferView)
                blob = raw[offset: offset + self.g.bufferViews[img.bufferView].byteLength]
            else:
                blob = self._uri(img.uri)
            self._images[i] = np.asarray(Image.open(io.BytesIO(blob)).convert("RGBA"))
        return self._images[i]

    # -- scene ------------------------------------------------------------------
    def material(self, i: int | None) -> Material:
        if i is None:
            return Material()
        m = self.g.materials[i]
        pbr = m.pbrMetallicRoughness
        texture = None
        if pbr is not None and pbr.baseColorTexture is not None:
            source = self.g.textures[pbr.baseColorTexture.index].source
            if source is not None:
                texture = self.image(source)
        factor = tuple(pbr.baseColorFactor) if pbr is not None and pbr.baseColorFactor else (1, 1, 1, 1)
        return Material(base_color=tuple(float(v) for v in factor), texture=texture,
                        alpha_mode=m.alphaMode or "OPAQUE",
                        alpha_cutoff=0.5 if m.alphaCutoff is None else float(m.alphaCutoff),
                        double_sided=bool(m.doubleSided),
                        unlit="KHR_materials_unlit" in (m.extensions or {}))

    def primitive(self, prim, node: int, scene: Scene) -> None:
        attrs = prim.attributes
        mode = 4 if prim.mode is None else prim.mode
        if attrs.POSITION is None or mode not in (0, 4, 5, 6):
            return  # lines have no surface to preview
        positions = self.accessor(attrs.POSITION).astype(np.float32)
        material = self.material(prim.material)
        colors = None
        if attrs.COLOR_0 is not None:
            colors = self.accessor(attrs.COLOR_0).astype(np.float32)
            if colors.shape[1] == 3:
                colors = np.hstack([colors, np.ones((len(colors), 1), np.float32)])
        if mode == 0:
            extra = {k.upper(): v for k, v in vars(attrs).items() if k.startswith("_") and v is not None}
            if "_RADIUS" in extra:
                radii = self.accessor(extra["_RADIUS"]).astype(np.float32).ravel()
            else:
                span = positions.max(0) - positions.min(0) if len(positions) else np.ones(3)
                radii = np.full(len(positions), POINT_SIZE_FRACTION * float(np.linalg.norm(span)), np.float32)
            rgba = np.ones((len(positions), 4), np.float32) if colors is None else colors
            rgba = rgba * np.asarray(material.base_color, np.float32)
            if "_DENSITY" in extra:  # fishgen clouds: thin edge particles are fainter
                rgba[:, 3] *= np.clip(self.accessor(extra["_DENSITY"]).ravel(), 0, 1)
            scene.points.append(PointPart(positions, radii, rgba, node))
            return
        if prim.indices is not None:
            flat = self.accessor(prim.indices).ravel().astype(np.uint32)
        else:
            flat = np.arange(len(positions), dtype=np.uint32)
        if len(flat) and int(flat.max()) >= len(positions):  # the GPU would read past the vertices
            raise FishgenError(f"expected vertex indices below {len(positions)}, found {int(flat.max())}",
                               self.where)
        indices = _triangles(flat, mode)
        normals = self.accessor(attrs.NORMAL).astype(np.float32) if attrs.NORMAL is not None else None
        uvs = self.accessor(attrs.TEXCOORD_0).astype(np.float32) if attrs.TEXCOORD_0 is not None else None
        if normals is None:
            normals = vertex_normals(positions, indices)
        scene.meshes.append(MeshPart(positions, indices, material, node, normals, uvs, colors))

    def scene(self, label: str) -> Scene:
        g = self.g
        scene = Scene(label=label)
        parents: dict[int, int] = {}
        for i, n in enumerate(g.nodes):
            for c in n.children or []:
                parents[c] = i
        for i, n in enumerate(g.nodes):
            node = Node(name=n.name or f"node{i}", parent=parents.get(i))
            if n.matrix is not None and list(n.matrix) != [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]:
                node.matrix = np.asarray(n.matrix, float).reshape(4, 4).T  # column-major
            if n.translation is not None:
                node.translation = np.asarray(n.translation, float)
            if n.rotation is not None:
                node.rotation = np.asarray(n.rotation, float)
            if n.scale is not None:
                node.scale = np.asarray(n.scale, float)
            scene.nodes.append(node)
        # Only nodes reachable from the default scene are drawn, as an engine would.
        roots = list(range(len(g.nodes)))
        if g.scenes:
            roots = g.scenes[g.scene or 0].nodes or []
        stack, seen = list(roots), set()
        while stack:
            i = stack.pop()
            if i in seen:
                continue
            seen.add(i)
            if g.nodes[i].mesh is not None:
                for prim in g.meshes[g.nodes[i].mesh].primitives:
                    self.primitive(prim, i, scene)
            stack.extend(g.nodes[i].children or [])
        for k, a in enumerate(g.animations or []):
            channels = []
            for ch in a.channels:
                smp = a.samplers[ch.sampler]
                interp = smp.interpolation or "LINEAR"
                if ch.target.node is None or ch.target.path not in PATHS or interp not in INTERPOLATIONS:
                    continue
                channels.append(Channel(ch.target.node, ch.target.path,
                                        self.accessor(smp.input).astype(float).ravel(),
                                        self.accessor(smp.output).astype(float), interp))
            scene.animations.append(Animation(a.name or f"clip{k}", channels))
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
