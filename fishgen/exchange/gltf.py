"""glTF 2.0 writer (.glb, or .gltf + .bin + images) of a scene, built on pygltflib.

It only writes: the scene says what the nodes, meshes, materials, skins and
clips are. pygltflib holds the document and makes the GLB container; this
module lays the arrays out in one buffer (4-byte aligned views) and checks that
nothing non-finite or larger than a GLB can hold gets written.
"""
from __future__ import annotations

import json
import struct
from pathlib import Path
from typing import Any
from urllib.parse import quote

import numpy as np
import pygltflib as gl

from fishgen import __version__
from fishgen.atomic import atomic_open, write_files
from fishgen.errors import FishgenError
from fishgen.scene.model import Primitive, Scene

GLB_LIMIT = 2**32 - 1
SHARED_ARRAY_BYTES = 1 << 16
"""Arrays up to this size are looked up before they are stored, so identical ones are stored once."""
_COMPONENT = {np.dtype(np.float32): gl.FLOAT, np.dtype(np.uint8): gl.UNSIGNED_BYTE,
              np.dtype(np.uint16): gl.UNSIGNED_SHORT, np.dtype(np.uint32): gl.UNSIGNED_INT,
              np.dtype(np.int8): gl.BYTE, np.dtype(np.int16): gl.SHORT}
_TYPE = {1: gl.SCALAR, 2: gl.VEC2, 3: gl.VEC3, 4: gl.VEC4, 16: gl.MAT4}
_NORMALIZED = ("COLOR_0", "WEIGHTS_0", "TEXCOORD_0")
_MODES = {"TRIANGLES": gl.TRIANGLES, "POINTS": gl.POINTS}


class _Buffer:
    """The binary buffer as a list of pieces, with 4-byte aligned buffer views and accessors."""

    def __init__(self, gltf: gl.GLTF2, where: Path):
        self.gltf, self.where = gltf, where
        self.pieces: list[bytes | memoryview] = []
        self.length = 0
        # Identical arrays are stored once: a school's fish share fin keys and key times.
        self._known: dict[tuple, int] = {}

    def view(self, payload: bytes | memoryview, target: int | None = None, stride: int | None = None) -> int:
        pad = -self.length % 4
        if pad:
            self.pieces.append(b"\0" * pad)
            self.length += pad
        self.gltf.bufferViews.append(gl.BufferView(buffer=0, byteOffset=self.length, byteStride=stride,
                                                   byteLength=len(payload), target=target))
        self.pieces.append(payload)
        self.length += len(payload)
        if self.length > GLB_LIMIT:
            raise FishgenError(f"expected at most 4 GiB of binary data for glTF, found more than "
                               f"{self.length:,} bytes", self.where)
        return len(self.gltf.bufferViews) - 1

    def accessor(self, array: np.ndarray, *, target: int | None = None, bounds: bool = False,
                 normalized: bool = False, mat4: bool = False) -> int:
        array = np.ascontiguousarray(array)
        if array.dtype == np.float64:
            array = array.astype(np.float32)
        identity: tuple | None = None
        if array.nbytes <= SHARED_ARRAY_BYTES:  # big arrays are never repeated; don't copy them to look
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
        if target == gl.ARRAY_BUFFER and row % 4:  # vertex rows must be 4-byte aligned: pad them
            stride = row + (-row % 4)
            padded = np.zeros((len(flat), stride), np.uint8)
            padded[:, :row] = flat.view(np.uint8).reshape(len(flat), row)
            payload = padded.data.cast("B")
        acc = gl.Accessor(bufferView=self.view(payload, target, stride),
                          componentType=_COMPONENT[array.dtype], count=len(array), type=_TYPE[width],
                          normalized=True if normalized and array.dtype.kind in "iu" else None)
        if bounds and len(array):
            acc.min = [v.item() for v in flat.min(axis=0)]
            acc.max = [v.item() for v in flat.max(axis=0)]
        self.gltf.accessors.append(acc)
        if identity is not None:
            self._known[identity] = len(self.gltf.accessors) - 1
        return len(self.gltf.accessors) - 1


def build_document(scene: Scene, where: Path, image_uri=None) -> tuple[gl.GLTF2, _Buffer]:
    """The glTF document and its buffer; ``image_uri(index)`` names external image files."""
    gltf = gl.GLTF2(asset=gl.Asset(version="2.0", generator=f"fishgen {__version__}"))
    buf = _Buffer(gltf, where)

    for k, image in enumerate(scene.images):
        if image_uri is None:
            gltf.images.append(gl.Image(bufferView=buf.view(image.encoded()), mimeType=image.mime_type,
                                        name=image.name))
        else:
            gltf.images.append(gl.Image(uri=image_uri(k), name=image.name))
    textures: dict[int, int] = {}
    for mat in scene.materials:
        if mat.texture is not None and mat.texture not in textures:
            if not gltf.samplers:
                gltf.samplers.append(gl.Sampler(magFilter=gl.LINEAR, minFilter=gl.LINEAR_MIPMAP_LINEAR,
                                                wrapS=gl.CLAMP_TO_EDGE, wrapT=gl.CLAMP_TO_EDGE))
            gltf.textures.append(gl.Texture(sampler=0, source=mat.texture,
                                            name=scene.images[mat.texture].name))
            textures[mat.texture] = len(gltf.textures) - 1
    for mat in scene.materials:
        pbr = gl.PbrMetallicRoughness(baseColorFactor=[float(c) for c in mat.base_color],
                                      metallicFactor=float(mat.metallic),
                                      roughnessFactor=float(mat.roughness))
        if mat.texture is not None:
            pbr.baseColorTexture = gl.TextureInfo(index=textures[mat.texture])
        out = gl.Material(name=mat.name, pbrMetallicRoughness=pbr, alphaMode=mat.alpha_mode,
                          doubleSided=mat.double_sided,
                          alphaCutoff=(0.5 if mat.alpha_cutoff is None else mat.alpha_cutoff)
                          if mat.alpha_mode == "MASK" else None)
        if mat.unlit:
            out.extensions = {"KHR_materials_unlit": {}}
            if "KHR_materials_unlit" not in gltf.extensionsUsed:
                gltf.extensionsUsed.append("KHR_materials_unlit")
        gltf.materials.append(out)

    for mesh in scene.meshes:
        gltf.meshes.append(gl.Mesh(name=mesh.name, primitives=[_primitive(buf, p) for p in mesh.primitives],
                                   weights=[float(w) for w in mesh.weights] or None))
    for node in scene.nodes:
        out_node = gl.Node(name=node.name or None, mesh=node.mesh, skin=node.skin,
                           children=list(node.children))
        if node.matrix is not None:
            out_node.matrix = [float(v) for v in np.asarray(node.matrix, float).T.ravel()]
        else:
            if any(node.translation):
                out_node.translation = [float(v) for v in node.translation]
            if tuple(node.rotation) != (0.0, 0.0, 0.0, 1.0):
                out_node.rotation = [float(v) for v in node.rotation]
            if tuple(node.scale) != (1.0, 1.0, 1.0):
                out_node.scale = [float(v) for v in node.scale]
        gltf.nodes.append(out_node)
    for skin in scene.skins:
        ibm = np.asarray(skin.inverse_bind_matrices, np.float32).transpose(0, 2, 1)  # column-major
        gltf.skins.append(gl.Skin(name=skin.name, joints=list(skin.joints), skeleton=skin.skeleton,
                                  inverseBindMatrices=buf.accessor(ibm.reshape(-1, 16), mat4=True)))
    gltf.scenes.append(gl.Scene(name=scene.name or None, nodes=list(scene.roots)))
    gltf.scene = 0

    for clip in scene.clips:
        anim = gl.Animation(name=clip.name)
        samplers: dict[tuple[int, int, str], int] = {}
        stored: dict[int, int] = {}  # id of a scene Sampler (alive all along) -> its glTF sampler
        for ch in clip.channels:
            smp = ch.sampler
            if id(smp) not in stored:  # a fish's parts share one weights Sampler: look it up once
                times = buf.accessor(np.asarray(smp.times, np.float32).ravel(), bounds=True)
                values = np.asarray(smp.values, np.float32)
                if ch.path == "weights":
                    values = values.ravel()  # glTF: SCALAR, (keys x targets) values
                key = (times, buf.accessor(values), smp.interpolation)
                if key not in samplers:  # channels with the same keys share one sampler
                    anim.samplers.append(gl.AnimationSampler(input=key[0], output=key[1],
                                                             interpolation=key[2]))
                    samplers[key] = len(anim.samplers) - 1
                stored[id(smp)] = samplers[key]
            # plain JSON rather than pygltflib's dataclasses: a school has tens of thousands
            anim.channels.append(_Json(sampler=stored[id(smp)], target=_Json(node=ch.node, path=ch.path)))
        gltf.animations.append(anim)
    gltf.buffers.append(gl.Buffer(byteLength=buf.length + (-buf.length % 4)))
    return gltf, buf


def _primitive(buf: _Buffer, prim: Primitive) -> gl.Primitive:
    attrs = gl.Attributes()
    for name, array in prim.attributes.items():
        acc = buf.accessor(array, target=gl.ARRAY_BUFFER, bounds=name == "POSITION",
                           normalized=name in _NORMALIZED)
        setattr(attrs, name, acc)
    out = gl.Primitive(attributes=attrs, material=prim.material,
                       mode=None if prim.mode == "TRIANGLES" else _MODES[prim.mode])
    if prim.indices is not None:
        flat = np.asarray(prim.indices).ravel()
        dtype = np.uint16 if prim.vertex_count < 65535 else np.uint32
        out.indices = buf.accessor(flat.astype(dtype), target=gl.ELEMENT_ARRAY_BUFFER, bounds=True)
    if prim.targets:
        out.targets = [{name: buf.accessor(array, target=gl.ARRAY_BUFFER, bounds=name == "POSITION")
                        for name, array in target.items()} for target in prim.targets]
    return out


def _blob(buf: _Buffer) -> bytes:
    return b"".join(buf.pieces) + b"\0" * (-buf.length % 4)


def document_json(gltf: gl.GLTF2, where: Path) -> bytes:
    """The pygltflib document as compact JSON, exactly as its ``gltf_to_json`` writes it.

    pygltflib deep-copies every leaf on the way to a dict, which is most of a school's write time
    (1,000 fish x 300 frames: about 0.7 s of 0.85 s); this walks the same dataclasses without
    copying and drops the same empty members (None, empty lists, dicts and strings, except inside
    ``extensions``). `tests/exchange/test_gltf_json.py` checks the two agree.
    """
    try:
        return json.dumps(_plain(gltf), allow_nan=False, separators=(",", ":")).encode("utf-8")
    except ValueError as err:  # NaN or infinity
        raise FishgenError(f"expected finite numbers in the glTF document, found one that is not ({err})",
                           where) from None


_LEAVES = (int, float, str, bool)


class _Json(dict):
    """A document member written as plain JSON already (no empty members): stored as it is."""


def _plain(obj: Any, keep_empty: bool = False) -> Any:
    """Dataclasses to dicts without their empty members; inside ``extensions`` everything is kept.

    Written for speed (a school has tens of thousands of channels): leaves are copied inline."""
    kind = type(obj)
    if kind in _LEAVES or obj is None or kind is _Json:
        return obj
    if kind is list or kind is tuple:
        return [item if type(item) in _LEAVES else _plain(item, keep_empty) for item in obj]
    items: Any
    if kind is dict:
        items = obj.items()
    else:  # a pygltflib dataclass, or its Attributes (a plain object with custom members)
        items = vars(obj).items()
        if kind is gl.GLTF2:  # leave out pygltflib's private state (a loaded blob, a path)
            items = [(key, value) for key, value in items if not key.startswith("_")]
        keep_empty = False
    out: dict[str, Any] = {}
    for key, value in items:
        if value is None:
            if keep_empty:
                out[key] = None
            continue
        kind = type(value)
        if kind is int or kind is float or kind is bool:
            out[key] = value
        elif not keep_empty and kind in (str, list, dict, tuple) and not value:
            continue
        elif kind is str:
            out[key] = value
        else:
            out[key] = _plain(value, keep_empty or key == "extensions")
    return out


def _glb_pieces(scene: Scene, where: Path) -> list[bytes | memoryview]:
    """The GLB container (glTF 2.0 spec, "Binary glTF Layout"): header, JSON chunk, BIN chunk."""
    gltf, buf = build_document(scene, where)
    text = document_json(gltf, where)
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
    stem = path.stem
    names = [f"{stem}_{image.name}.{'jpg' if image.mime_type == 'image/jpeg' else 'png'}"
             for image in scene.images]
    gltf, buf = build_document(scene, path, image_uri=lambda k: quote(names[k]))
    gltf.buffers[0].uri = quote(f"{stem}.bin")
    files: dict[Path, bytes] = {path: document_json(gltf, path),
                                path.with_name(f"{stem}.bin"): _blob(buf)}
    for name, image in zip(names, scene.images, strict=True):
        files[path.with_name(name)] = image.encoded()
    write_files(files)
    return list(files)
