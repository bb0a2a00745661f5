"""glTF 2.0 writer (.glb, or .gltf + .bin + images) of a scene.

It only writes: the scene says what the nodes, meshes, materials, skins and clips are. This
module lays the arrays out in one buffer (4-byte aligned views), checks that nothing non-finite
or larger than a GLB can hold gets written, and frames the GLB container itself (glTF 2.0 spec,
"Binary glTF Layout"). The document is plain dicts, with the members in the order pygltflib
writes them and empty ones left out as it does: `tests/exchange/test_gltf_json.py` checks that
pygltflib reads every kind of file back and writes the very same bytes. (Building the document
with pygltflib's classes cost every fishgen process 45 ms to import them, and pygltflib's own
serialisation deep-copied every leaf: 0.7 s of a 1,000-fish school's write.)
"""
from __future__ import annotations

import json
import struct
from pathlib import Path
from typing import Any

import numpy as np

from fishgen import __version__
from fishgen.atomic import atomic_open, write_files
from fishgen.errors import FishgenError
from fishgen.scene.model import Primitive, Scene

GLB_LIMIT = 2**32 - 1
SHARED_ARRAY_BYTES = 1 << 16
"""Arrays up to this size are looked up before they are stored, so identical ones are stored once."""
# glTF 2.0 constants (componentType, mode, bufferView target, sampler filters and wrapping)
FLOAT, UNSIGNED_BYTE, UNSIGNED_SHORT, UNSIGNED_INT, BYTE, SHORT = 5126, 5121, 5123, 5125, 5120, 5122
POINTS, TRIANGLES = 0, 4
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
LINEAR, LINEAR_MIPMAP_LINEAR, CLAMP_TO_EDGE = 9729, 9987, 33071
_COMPONENT = {np.dtype(np.float32): FLOAT, np.dtype(np.uint8): UNSIGNED_BYTE,
              np.dtype(np.uint16): UNSIGNED_SHORT, np.dtype(np.uint32): UNSIGNED_INT,
              np.dtype(np.int8): BYTE, np.dtype(np.int16): SHORT}
_TYPE = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4", 16: "MAT4"}
_NORMALIZED = ("COLOR_0", "WEIGHTS_0", "TEXCOORD_0")
_MODES = {"TRIANGLES": TRIANGLES, "POINTS": POINTS}
# pygltflib's Attributes lists these first, in this order; others follow as they come
_ATTRIBUTE_ORDER = ("POSITION", "NORMAL", "TANGENT", "TEXCOORD_0", "TEXCOORD_1", "COLOR_0", "JOINTS_0",
                    "WEIGHTS_0")
# top-level members in the order pygltflib writes them
_TOP = ("extensions", "extras", "accessors", "animations", "asset", "bufferViews", "buffers", "cameras",
        "extensionsUsed", "extensionsRequired", "images", "materials", "meshes", "nodes", "samplers",
        "scene", "scenes", "skins", "textures")

Document = dict[str, Any]


def _obj(**members: Any) -> dict[str, Any]:
    """A document object: its members in the order given, without the empty ones (None, empty
    lists, dicts and strings), as glTF writers leave them out."""
    return {key: value for key, value in members.items()
            if value is not None and not (type(value) in (list, dict, str) and not value)}


class _Buffer:
    """The binary buffer as a list of pieces, with 4-byte aligned buffer views and accessors."""

    def __init__(self, doc: Document, where: Path):
        self.views: list[dict[str, Any]] = doc["bufferViews"]
        self.accessors: list[dict[str, Any]] = doc["accessors"]
        self.where = where
        self.pieces: list[bytes | memoryview] = []
        self.length = 0
        # Identical arrays are stored once: a school's fish share fin keys and key times.
        self._known: dict[tuple, int] = {}
        self._objects: dict[tuple, tuple[np.ndarray, int]] = {}

    def view(self, payload: bytes | memoryview, target: int | None = None, stride: int | None = None) -> int:
        pad = -self.length % 4
        if pad:
            self.pieces.append(b"\0" * pad)
            self.length += pad
        self.views.append(_obj(buffer=0, byteOffset=self.length, byteLength=len(payload), byteStride=stride,
                               target=target))
        self.pieces.append(payload)
        self.length += len(payload)
        if self.length > GLB_LIMIT:
            raise FishgenError(f"expected at most 4 GiB of binary data for glTF, found more than "
                               f"{self.length:,} bytes", self.where)
        return len(self.views) - 1

    def accessor(self, array: np.ndarray, *, target: int | None = None, bounds: bool = False,
                 normalized: bool = False, mat4: bool = False) -> int:
        # A big array passed again as the same object (a school's colour variants of one mesh) is
        # stored once too; the object is kept alive so that its id cannot be reused.
        same_object = (id(array), target, bounds, normalized, mat4)
        if same_object in self._objects:
            return self._objects[same_object][1]
        given = array
        array = np.ascontiguousarray(array)
        if array.dtype == np.float64:
            array = array.astype(np.float32)
        identity: tuple | None = None
        if array.nbytes <= SHARED_ARRAY_BYTES:  # big arrays are rarely repeated; don't copy them to look
            identity = (array.dtype.str, array.shape, target, bounds, normalized, mat4, array.tobytes())
            if identity in self._known:
                return self._known[identity]
        if array.dtype.kind == "f" and not np.all(np.isfinite(array)):
            raise FishgenError("expected finite numbers in every array, found NaN or infinity",
                               self.where)
        width = 16 if mat4 else (1 if array.ndim == 1 else int(np.prod(array.shape[1:])))
        flat = array.reshape(len(array), width)
        payload, stride = flat.data.cast("B"), None
        row = flat.dtype.itemsize * width
        if target == ARRAY_BUFFER and row % 4:  # vertex rows must be 4-byte aligned: pad them
            stride = row + (-row % 4)
            padded = np.zeros((len(flat), stride), np.uint8)
            padded[:, :row] = flat.view(np.uint8).reshape(len(flat), row)
            payload = padded.data.cast("B")
        view = self.view(payload, target, stride)
        big = small = None
        if bounds and len(array):
            big, small = flat.max(axis=0).tolist(), flat.min(axis=0).tolist()
        self.accessors.append(_obj(bufferView=view, byteOffset=0, componentType=_COMPONENT[array.dtype],
                                   normalized=True if normalized and array.dtype.kind in "iu" else None,
                                   count=len(array), type=_TYPE[width], max=big, min=small))
        if identity is not None:
            self._known[identity] = len(self.accessors) - 1
        else:
            self._objects[same_object] = (given, len(self.accessors) - 1)
        return len(self.accessors) - 1


def build_document(scene: Scene, where: Path, image_uri=None) -> tuple[Document, _Buffer]:
    """The glTF document and its buffer; ``image_uri(index)`` names external image files."""
    doc: Document = {key: [] for key in ("accessors", "animations", "bufferViews", "buffers",
                                         "extensionsUsed", "images", "materials", "meshes", "nodes",
                                         "samplers", "scenes", "skins", "textures")}
    doc["asset"] = _obj(generator=f"fishgen {__version__}", version="2.0")
    buf = _Buffer(doc, where)

    for k, image in enumerate(scene.images):
        if image_uri is None:
            doc["images"].append(_obj(mimeType=image.mime_type, bufferView=buf.view(image.encoded()),
                                      name=image.name))
        else:
            doc["images"].append(_obj(uri=image_uri(k), name=image.name))
    textures: dict[int, int] = {}
    for mat in scene.materials:
        if mat.texture is not None and mat.texture not in textures:
            if not doc["samplers"]:
                doc["samplers"].append(_obj(magFilter=LINEAR, minFilter=LINEAR_MIPMAP_LINEAR,
                                            wrapS=CLAMP_TO_EDGE, wrapT=CLAMP_TO_EDGE))
            doc["textures"].append(_obj(sampler=0, source=mat.texture, name=scene.images[mat.texture].name))
            textures[mat.texture] = len(doc["textures"]) - 1
    for mat in scene.materials:
        pbr = _obj(baseColorFactor=[float(c) for c in mat.base_color], metallicFactor=float(mat.metallic),
                   roughnessFactor=float(mat.roughness),
                   baseColorTexture=None if mat.texture is None else _obj(index=textures[mat.texture],
                                                                          texCoord=0))
        extensions: dict[str, Any] | None = None
        if mat.unlit:
            extensions = {"KHR_materials_unlit": {}}
            if "KHR_materials_unlit" not in doc["extensionsUsed"]:
                doc["extensionsUsed"].append("KHR_materials_unlit")
        cutoff = None
        if mat.alpha_mode == "MASK":
            cutoff = 0.5 if mat.alpha_cutoff is None else mat.alpha_cutoff
        doc["materials"].append(_obj(
            extensions=extensions, pbrMetallicRoughness=pbr, emissiveFactor=[0.0, 0.0, 0.0],
            alphaMode=mat.alpha_mode, alphaCutoff=cutoff, doubleSided=mat.double_sided, name=mat.name))

    for mesh in scene.meshes:
        names = {"targetNames": list(mesh.target_names)} if mesh.target_names else None  # three.js, Blender
        doc["meshes"].append(_obj(extras=names, primitives=[_primitive(buf, p) for p in mesh.primitives],
                                  weights=[float(w) for w in mesh.weights], name=mesh.name))
    for node in scene.nodes:
        matrix = rotation = translation = scale = None
        if node.matrix is not None:
            matrix = [float(v) for v in np.asarray(node.matrix, float).T.ravel()]
        else:
            if any(node.translation):
                translation = [float(v) for v in node.translation]
            if tuple(node.rotation) != (0.0, 0.0, 0.0, 1.0):
                rotation = [float(v) for v in node.rotation]
            if tuple(node.scale) != (1.0, 1.0, 1.0):
                scale = [float(v) for v in node.scale]
        extensions, extras = None, dict(node.extras)
        if node.lods is not None:  # MSFT_lod, a Microsoft vendor extension: used, never required
            extensions = {"MSFT_lod": {"ids": [int(i) for i in node.lods.nodes]}}
            if node.lods.coverage:
                extras["MSFT_screencoverage"] = [float(c) for c in node.lods.coverage]
            if "MSFT_lod" not in doc["extensionsUsed"]:
                doc["extensionsUsed"].append("MSFT_lod")
        doc["nodes"].append(_obj(extensions=extensions, extras=extras or None,
                                 mesh=node.mesh, skin=node.skin, rotation=rotation, translation=translation,
                                 scale=scale, children=list(node.children), matrix=matrix,
                                 name=node.name or None))
    for skin in scene.skins:
        ibm = np.asarray(skin.inverse_bind_matrices, np.float32).transpose(0, 2, 1)  # column-major
        doc["skins"].append(_obj(inverseBindMatrices=buf.accessor(ibm.reshape(-1, 16), mat4=True),
                                 skeleton=skin.skeleton, joints=list(skin.joints), name=skin.name))
    doc["scenes"].append(_obj(extras=scene.extras or None, name=scene.name or None, nodes=list(scene.roots)))
    if scene.hidden_roots:  # not the default scene: clients that know nothing of levels leave it out
        doc["scenes"].append(_obj(name="levels of detail", nodes=list(scene.hidden_roots)))
    doc["scene"] = 0

    for clip in scene.clips:
        channels: list[dict[str, Any]] = []
        samplers: list[dict[str, Any]] = []
        known: dict[tuple[int, int, str], int] = {}
        stored: dict[int, int] = {}  # id of a scene Sampler (alive all along) -> its glTF sampler
        for ch in clip.channels:
            smp = ch.sampler
            if id(smp) not in stored:  # a fish's parts share one weights Sampler: look it up once
                times = buf.accessor(np.asarray(smp.times, np.float32).ravel(), bounds=True)
                values = np.asarray(smp.values)
                if values.dtype.kind not in "iu":
                    values = values.astype(np.float32)
                if ch.path == "weights":
                    values = values.ravel()  # glTF: SCALAR, (keys x targets) values
                # integer rotations and weights are normalized (glTF 2.0 allows them for these outputs)
                key = (times, buf.accessor(values, normalized=values.dtype.kind in "iu"), smp.interpolation)
                if key not in known:  # channels with the same keys share one sampler
                    samplers.append({"input": key[0], "interpolation": key[2], "output": key[1]})
                    known[key] = len(samplers) - 1
                stored[id(smp)] = known[key]
            channels.append({"sampler": stored[id(smp)], "target": {"node": ch.node, "path": ch.path}})
        doc["animations"].append(_obj(name=clip.name, channels=channels, samplers=samplers))
    doc["buffers"].append({"byteLength": buf.length + (-buf.length % 4)})
    return doc, buf


def _primitive(buf: _Buffer, prim: Primitive) -> dict[str, Any]:
    stored = {name: buf.accessor(array, target=ARRAY_BUFFER, bounds=name == "POSITION",
                                 normalized=name in _NORMALIZED) for name, array in prim.attributes.items()}
    names = [n for n in _ATTRIBUTE_ORDER if n in stored] + [n for n in stored if n not in _ATTRIBUTE_ORDER]
    attributes = {name: stored[name] for name in names}  # stored as they come, listed in pygltflib's order
    indices = None
    if prim.indices is not None:
        flat = np.asarray(prim.indices).ravel()
        dtype = np.uint16 if prim.vertex_count < 65535 else np.uint32
        indices = buf.accessor(flat.astype(dtype), target=ELEMENT_ARRAY_BUFFER, bounds=True)
    targets = [{name: buf.accessor(array, target=ARRAY_BUFFER, bounds=name == "POSITION")
                for name, array in target.items()} for target in prim.targets]
    return _obj(attributes=attributes, indices=indices,
                mode=None if prim.mode == "TRIANGLES" else _MODES[prim.mode], material=prim.material,
                targets=targets)


def _blob(buf: _Buffer) -> bytes:
    return b"".join(buf.pieces) + b"\0" * (-buf.length % 4)


def document_json(doc: Document, where: Path) -> bytes:
    """The document as compact JSON, its top-level members in pygltflib's order, empty ones left out."""
    ordered = {key: doc[key] for key in _TOP if key in doc and doc[key] not in (None, [], {}, "")}
    try:
        return json.dumps(ordered, allow_nan=False, separators=(",", ":")).encode("utf-8")
    except ValueError as err:  # NaN or infinity
        raise FishgenError(f"expected finite numbers in the glTF document, found one that is not ({err})",
                           where) from None


def _glb_pieces(scene: Scene, where: Path) -> list[bytes | memoryview]:
    """The GLB container (glTF 2.0 spec, "Binary glTF Layout"): header, JSON chunk, BIN chunk."""
    doc, buf = build_document(scene, where)
    text = document_json(doc, where)
    text += b" " * (-len(text) % 4)
    pad = b"\0" * (-buf.length % 4)
    total = 12 + 8 + len(text) + 8 + buf.length + len(pad)
    if total > GLB_LIMIT:
        raise FishgenError(f"expected a GLB of at most 4 GiB, found {total:,} bytes", where)
    return [struct.pack("<4sII", b"glTF", 2, total), struct.pack("<I4s", len(text), b"JSON"), text,
            struct.pack("<I4s", buf.length + len(pad), b"BIN\0"), *buf.pieces, pad]


def glb_bytes(scene: Scene, where: Path = Path("<glb>")) -> bytes:
    """The scene as one binary glTF (.glb) file, in memory."""
    return b"".join(_glb_pieces(scene, where))


def write_glb(scene: Scene, path: Path) -> list[Path]:
    pieces = _glb_pieces(scene, path)  # before the temp file: a refused scene leaves nothing
    with atomic_open(path) as handle:  # written piece by piece: no second copy of the buffer
        for piece in pieces:
            handle.write(piece)
    return [path]


def write_gltf(scene: Scene, path: Path) -> list[Path]:
    """``.gltf`` JSON with the buffer and images as files beside it (URIs percent-encoded)."""
    from fishgen.exchange.sidefiles import check_shared, image_side_stems, name_uri

    stem = path.stem
    stems = image_side_stems(stem, [image.name for image in scene.images])
    names = [f"{side}.{'jpg' if image.mime_type == 'image/jpeg' else 'png'}"
             for side, image in zip(stems, scene.images, strict=True)]
    doc, buf = build_document(scene, path, image_uri=lambda k: name_uri(names[k]))
    doc["buffers"][0] = {"uri": name_uri(f"{stem}.bin"), **doc["buffers"][0]}
    files: dict[Path, bytes] = {path: document_json(doc, path),
                                path.with_name(f"{stem}.bin"): _blob(buf)}
    for name, image in zip(names, scene.images, strict=True):
        files[path.with_name(name)] = image.encoded()
    check_shared(path, files)
    write_files(files)
    return list(files)
