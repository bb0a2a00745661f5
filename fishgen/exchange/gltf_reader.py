"""Read a glTF 2.0 asset (.glb / .gltf, or GLB bytes) into the scene model.

The reader parses the GLB container and the JSON itself and decodes the
accessors itself, so that alpha modes, double-sidedness, POINTS primitives
with ``_RADIUS``, skins, morph targets and every animation channel survive
(general mesh loaders drop some of them). Side files are read only from the
asset's own folder.

Everything read is checked against the glTF 2.0 rules before the scene is
built (the renderer and the posing code only ever see a well-formed scene):
indices in range, node trees without cycles or second parents, the sizes of
TRS, matrices and colour factors, accessor types and counts per semantic,
animation sampler counts, skins, morph targets and finite numbers. Declared
sizes are checked against the bytes really there, and against the caps below,
before anything is read or allocated. Every fault is one ``FishgenError``
reading ``expected ..., found ...``.
"""
from __future__ import annotations

from pathlib import Path
from typing import cast

import numpy as np

from fishgen.errors import FishgenError, describe
from fishgen.exchange.gltf_checks import COMPONENT_DTYPES, TYPE_WIDTHS, Document, check_document, item_name
from fishgen.exchange.gltf_container import data_uri, read_capped, side_path, unpack
from fishgen.exchange.guards import check_picture, one_line
from fishgen.scene.model import (
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

_MODES: dict[int, PrimitiveMode] = {0: "POINTS", 4: "TRIANGLES", 5: "TRIANGLES", 6: "TRIANGLES"}
_IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]


def read_gltf(path: str | Path | None = None, *, data: bytes | None = None,
              label: str | None = None) -> Scene:
    """Load a .glb/.gltf file (or GLB ``data``) as a Scene; bad files raise FishgenError."""
    where = str(path) if path is not None else "<glb>"
    try:
        if data is None:
            if path is None:
                raise FishgenError("expected a file or GLB bytes to read, found neither")
            data = read_capped(Path(path), where)
        doc, blob = unpack(data)
        del data  # the BIN chunk is a view; a .gltf's text is no longer needed
        reader = _Reader(check_document(doc, blob, Path(path) if path is not None else None), where)
        return reader.scene(label if label is not None else (Path(path).stem if path else ""))
    except FishgenError as err:
        if err.file is None:
            err.file = where
            err.args = (str(err),)
        raise
    except MemoryError:
        raise FishgenError("expected an asset that fits in memory, found it does not", where) from None
    except Exception as err:  # a fault the checks above missed: still one line, never a traceback
        raise FishgenError(f"expected a well-formed glTF 2.0 asset, found {type(err).__name__}: "
                           f"{one_line(err)}", where) from None


def _fail(what: str, found: str) -> FishgenError:
    return FishgenError(f"expected {what}, found {found}")


def _mime(img: dict) -> str:
    mime = img.get("mimeType")
    return mime if isinstance(mime, str) else "image/png"


class _Reader:
    """Builds the scene from a checked document."""

    def __init__(self, document: Document, where: str):
        self.document, self.where = document, where
        self.doc, self.lists = document.doc, document.lists
        self.blob, self.asset = document.blob, document.asset
        self._files, self.textured, self.parent = document.files, document.textured, document.parent
        self._buffers: dict[int, bytes | memoryview] = {}

    # -- raw data -------------------------------------------------------------
    def buffer(self, i: int) -> bytes | memoryview:
        if i not in self._buffers:
            buf = self.lists["buffers"][i]
            where = f"buffers[{i}]"
            if buf.get("uri") is None:
                data: bytes | memoryview = cast(memoryview, self.blob)
            elif i in self._files:
                data = self._files[i].read_bytes()
                if len(data) != buf["byteLength"]:  # changed since the check
                    raise _fail(f"{buf['byteLength']:,} bytes in {describe(buf['uri'])}", f"{len(data):,}")
            else:
                data = data_uri(buf["uri"], where)
                if len(data) != buf["byteLength"]:
                    raise _fail(f"{buf['byteLength']:,} bytes in the data URI of {where}", f"{len(data):,}")
            self._buffers[i] = data
        return self._buffers[i]

    def _view(self, i: int) -> tuple[bytes | memoryview, int]:
        view = self.lists["bufferViews"][i]
        return self.buffer(view["buffer"]), view.get("byteOffset", 0)

    def accessor(self, i: int) -> np.ndarray:
        """The accessor's values, (count, components); normalized integers as float32."""
        acc = self.lists["accessors"][i]
        dtype = np.dtype(COMPONENT_DTYPES[acc["componentType"]])
        width, count = TYPE_WIDTHS[acc["type"]], acc["count"]
        if acc.get("bufferView") is None:
            out = np.zeros((count, width), dtype)
        else:
            raw, offset = self._view(acc["bufferView"])
            offset += acc.get("byteOffset", 0)
            item = dtype.itemsize * width
            stride = self.lists["bufferViews"][acc["bufferView"]].get("byteStride") or item
            if stride == item:
                out = np.frombuffer(raw, dtype, count * width, offset).reshape(count, width)
            else:  # interleaved: view the rows through a strided window
                rows = np.frombuffer(raw, np.uint8, stride * (count - 1) + item, offset)
                out = np.lib.stride_tricks.as_strided(rows, (count, item), (stride, 1))
                out = np.ascontiguousarray(out).view(dtype).reshape(count, width)
        sparse = acc.get("sparse")
        if sparse is not None:
            out = out.copy()
            n, idx_part, val_part = sparse["count"], sparse["indices"], sparse["values"]
            raw, offset = self._view(idx_part["bufferView"])
            idx = np.frombuffer(raw, COMPONENT_DTYPES[idx_part["componentType"]], n,
                                offset + idx_part.get("byteOffset", 0))
            if int(idx.max()) >= count:
                raise _fail(f"sparse indices below {count:,} at accessors[{i}]", str(int(idx.max())))
            raw, offset = self._view(val_part["bufferView"])
            out[idx] = np.frombuffer(raw, dtype, n * width,
                                     offset + val_part.get("byteOffset", 0)).reshape(n, width)
        if dtype.kind == "f" and not np.isfinite(out).all():
            bad = out[~np.isfinite(out)].ravel()[0]
            raise _fail(f"finite numbers in accessors[{i}]", str(bad))
        if acc.get("normalized") and dtype.kind in "iu":
            out = np.maximum(out.astype(np.float32) / np.iinfo(dtype).max, -1.0)
        return out

    def image_bytes(self, i: int) -> bytes:
        img = self.lists["images"][i]
        if img.get("bufferView") is not None:
            raw, offset = self._view(img["bufferView"])
            data = bytes(raw[offset: offset + self.lists["bufferViews"][img["bufferView"]]["byteLength"]])
        elif img["uri"].strip().startswith("data:"):
            data = data_uri(img["uri"], f"images[{i}]")
        else:
            data = side_path(self.asset, img["uri"]).read_bytes()
        if i in self.textured:
            check_picture(data, f"images[{i}] ({item_name(img, 'unnamed')!r})")
        return data

    # -- scene ------------------------------------------------------------------
    def material(self, k: int) -> Material:
        m = self.lists["materials"][k]
        pbr = m.get("pbrMetallicRoughness") or {}
        texture = None
        if pbr.get("baseColorTexture") is not None:
            texture = self.lists["textures"][pbr["baseColorTexture"]["index"]].get("source")
        factor = pbr.get("baseColorFactor") or [1, 1, 1, 1]
        base_color = cast(tuple[float, float, float, float], tuple(float(v) for v in factor))
        cutoff = m.get("alphaCutoff")
        return Material(name=item_name(m, f"material{k}"), base_color=base_color,
                        texture=texture, alpha_mode=m.get("alphaMode", "OPAQUE"),
                        alpha_cutoff=None if cutoff is None else float(cutoff),
                        double_sided=bool(m.get("doubleSided", False)),
                        unlit="KHR_materials_unlit" in (m.get("extensions") or {}))

    def primitive(self, prim: dict, where: str) -> Primitive | None:
        mode = prim.get("mode", 4)
        attrs = prim["attributes"]
        if "POSITION" not in attrs or mode not in _MODES:
            return None  # lines have no surface to preview
        attributes = {name: self.accessor(index) for name, index in attrs.items()}
        attributes = {name: (a.ravel() if a.shape[1] == 1 else a) for name, a in attributes.items()}
        attributes["POSITION"] = attributes["POSITION"].astype(np.float32)
        n = len(attributes["POSITION"])
        weights = attributes.get("WEIGHTS_0")
        if weights is not None and "JOINTS_0" in attributes:
            sums = np.asarray(weights, np.float64).sum(axis=1)
            if (weights < 0).any() or not np.allclose(sums, 1.0, atol=0.02):
                bad = int(np.argmax(np.abs(sums - 1.0) + (weights < 0).any(axis=1)))
                raise _fail(f"WEIGHTS_0 of each vertex non-negative and summing to 1 at {where}",
                            f"{np.round(weights[bad], 4).tolist()} at vertex {bad}")
        indices = None
        if _MODES[mode] == "TRIANGLES":
            flat = (self.accessor(prim["indices"]).ravel().astype(np.uint32) if "indices" in prim
                    else np.arange(n, dtype=np.uint32))
            if len(flat) and int(flat.max()) >= n:  # the GPU would read past the vertices
                raise _fail(f"vertex indices below {n} at {where}", str(int(flat.max())))
            indices = _triangles(flat, mode)
        targets = [{name: self.accessor(index).astype(np.float32) for name, index in target.items()}
                   for target in prim.get("targets", [])]
        return Primitive(attributes, indices, prim.get("material"), _MODES[mode], targets)

    def scene(self, label: str) -> Scene:
        lists = self.lists
        scene = Scene(name=label, source=self.where)
        for k, m in enumerate(lists["meshes"]):
            prims = [self.primitive(p, f"meshes[{k}].primitives[{j}]") for j, p in enumerate(m["primitives"])]
            scene.meshes.append(Mesh(item_name(m, f"mesh{k}"), [p for p in prims if p is not None],
                                     [float(w) for w in m.get("weights", [])]))
        scene.images = [Image(item_name(img, f"image{k}"), self.image_bytes(k), _mime(img))
                        for k, img in enumerate(lists["images"])]
        scene.materials = [self.material(k) for k in range(len(lists["materials"]))]
        for i, n in enumerate(lists["nodes"]):
            node = Node(name=item_name(n, f"node{i}"), children=list(n.get("children", [])),
                        mesh=n.get("mesh"), skin=n.get("skin"))
            if n.get("matrix") is not None and list(n["matrix"]) != _IDENTITY:
                node.matrix = np.asarray(n["matrix"], float).reshape(4, 4).T  # column-major
            if n.get("translation") is not None:
                node.translation = cast(tuple[float, float, float], tuple(map(float, n["translation"])))
            if n.get("rotation") is not None:
                node.rotation = cast(tuple[float, float, float, float], tuple(map(float, n["rotation"])))
            if n.get("scale") is not None:
                node.scale = cast(tuple[float, float, float], tuple(map(float, n["scale"])))
            scene.nodes.append(node)
        for k, skin in enumerate(lists["skins"]):
            joints = list(skin["joints"])
            if skin.get("inverseBindMatrices") is not None:
                ibm = (self.accessor(skin["inverseBindMatrices"]).astype(float)
                       .reshape(-1, 4, 4).transpose(0, 2, 1))
            else:
                ibm = np.repeat(np.eye(4)[None], len(joints), axis=0)
            scene.skins.append(Skin(item_name(skin, f"skin{k}"), joints, ibm, skin.get("skeleton")))
        self._check_joints(scene)
        # Only nodes reachable from the default scene are drawn, as an engine would.
        scenes = lists["scenes"]
        scene.roots = (list(scenes[self.doc.get("scene", 0)].get("nodes", [])) if scenes
                       else [i for i in range(len(lists["nodes"])) if i not in self.parent])
        for k, a in enumerate(lists["animations"]):
            channels = []
            for j, ch in enumerate(a.get("channels", [])):
                smp = a["samplers"][ch["sampler"]]
                interp = smp.get("interpolation", "LINEAR")
                node, path = ch["target"].get("node"), ch["target"]["path"]
                if node is None or path not in PATHS:
                    continue
                times = self.accessor(smp["input"]).astype(float).ravel()
                if len(times) > 1 and (np.diff(times) < 0).any():
                    at = int(np.argmax(np.diff(times) < 0)) + 1
                    raise _fail(f"keyframe times that never decrease at animations[{k}].channels[{j}]",
                                f"{times[at]:g} after {times[at - 1]:g}")
                values = self.accessor(smp["output"]).astype(float)
                if path == "weights":
                    values = values.reshape(len(times) * (3 if interp == "CUBICSPLINE" else 1), -1)
                channels.append(Channel(node, path, Sampler(times, values, interp)))
            scene.clips.append(Clip(item_name(a, f"clip{k}"), channels))
        return scene

    def _check_joints(self, scene: Scene) -> None:
        """JOINTS_0 of a skinned mesh index its skin's joints."""
        for i, node in enumerate(scene.nodes):
            if node.skin is None or node.mesh is None:
                continue
            joints = len(scene.skins[node.skin].joints)
            for prim in scene.meshes[node.mesh].primitives:
                a = prim.attributes.get("JOINTS_0")
                if a is not None and len(a) and int(a.max()) >= joints:
                    raise _fail(f"JOINTS_0 values below {joints} (the joints of skins[{node.skin}]) "
                                f"in meshes[{node.mesh}] on nodes[{i}]", str(int(a.max())))


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
