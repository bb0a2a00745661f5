"""glTF 2.0 writer (.glb and .gltf + .bin + .png) built on pygltflib.

Nodes: a root named after the species, one child per part; moving fins carry
their pivot as the node translation and are animated by the ``swim`` clip.
"""
from __future__ import annotations

import json
from pathlib import Path
from urllib.parse import quote

import numpy as np
import pygltflib as gl

from fishgen import __version__
from fishgen.assembly.animation import y_rotation_quaternions
from fishgen.atomic import write_files

CLAMP, LINEAR, LINEAR_MIPMAP_LINEAR = 33071, 9729, 9987


class _Blob:
    """Accumulates the binary buffer with 4-byte aligned buffer views."""

    def __init__(self, gltf: gl.GLTF2):
        self.gltf = gltf
        self.data = bytearray()

    def view(self, payload: bytes, target: int | None = None) -> int:
        self.data.extend(b"\0" * (-len(self.data) % 4))
        self.gltf.bufferViews.append(gl.BufferView(buffer=0, byteOffset=len(self.data),
                                                   byteLength=len(payload), target=target))
        self.data.extend(payload)
        return len(self.gltf.bufferViews) - 1

    def accessor(self, array: np.ndarray, kind: str, target: int | None = None,
                 bounds: bool = False) -> int:
        array = np.ascontiguousarray(array)
        component = {np.dtype(np.float32): gl.FLOAT, np.dtype(np.uint16): gl.UNSIGNED_SHORT,
                     np.dtype(np.uint32): gl.UNSIGNED_INT}[array.dtype]
        view = self.view(array.tobytes(), target)
        acc = gl.Accessor(bufferView=view, componentType=component, count=len(array), type=kind)
        if bounds:
            flat = array.reshape(len(array), -1)
            acc.min = [float(v) for v in flat.min(axis=0)]
            acc.max = [float(v) for v in flat.max(axis=0)]
        self.gltf.accessors.append(acc)
        return len(self.gltf.accessors) - 1


def _unit(v: np.ndarray) -> np.ndarray:
    v = v.astype(np.float32)
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def build_gltf(asset, image_uri=None) -> tuple[gl.GLTF2, bytes, dict[str, bytes]]:
    """The glTF document, its binary buffer, and the images (for external files)."""
    gltf = gl.GLTF2(asset=gl.Asset(version="2.0", generator=f"fishgen {__version__}"))
    blob = _Blob(gltf)

    image_index: dict[str, int] = {}
    for key, png in asset.images.items():
        if image_uri is None:
            gltf.images.append(gl.Image(bufferView=blob.view(png), mimeType="image/png", name=key))
        else:
            gltf.images.append(gl.Image(uri=image_uri(key), name=key))
        image_index[key] = len(gltf.images) - 1
    if asset.images:
        gltf.samplers.append(gl.Sampler(magFilter=LINEAR, minFilter=LINEAR_MIPMAP_LINEAR,
                                        wrapS=CLAMP, wrapT=CLAMP))
    texture_index = {}
    for key, idx in image_index.items():
        gltf.textures.append(gl.Texture(sampler=0, source=idx, name=key))
        texture_index[key] = len(gltf.textures) - 1

    material_index = {}
    for name, mat in asset.materials.items():
        pbr = gl.PbrMetallicRoughness(baseColorFactor=[float(c) for c in mat.base_color],
                                      metallicFactor=0.0, roughnessFactor=0.55)
        if mat.texture is not None:
            pbr.baseColorTexture = gl.TextureInfo(index=texture_index[mat.texture])
        gltf.materials.append(gl.Material(name=name, pbrMetallicRoughness=pbr, alphaMode=mat.alpha_mode,
                                          alphaCutoff=mat.alpha_cutoff, doubleSided=mat.double_sided))
        material_index[name] = len(gltf.materials) - 1

    textured = bool(asset.images)
    children = []
    for part in asset.parts:
        mesh = part.mesh
        attrs = gl.Attributes(
            POSITION=blob.accessor(mesh.positions.astype(np.float32), gl.VEC3, gl.ARRAY_BUFFER, True),
            NORMAL=blob.accessor(_unit(mesh.normals), gl.VEC3, gl.ARRAY_BUFFER))
        if textured:
            attrs.TEXCOORD_0 = blob.accessor(mesh.uvs.astype(np.float32), gl.VEC2, gl.ARRAY_BUFFER)
        index_type = np.uint16 if len(mesh.positions) < 65535 else np.uint32
        indices = blob.accessor(mesh.faces.reshape(-1).astype(index_type), gl.SCALAR,
                                gl.ELEMENT_ARRAY_BUFFER, True)
        gltf.meshes.append(gl.Mesh(name=part.name, primitives=[gl.Primitive(
            attributes=attrs, indices=indices, material=material_index[part.material])]))
        node = gl.Node(name=part.name, mesh=len(gltf.meshes) - 1)
        if np.any(part.translation):
            node.translation = [float(v) for v in part.translation]
        gltf.nodes.append(node)
        children.append(len(gltf.nodes) - 1)
    gltf.nodes.append(gl.Node(name=asset.name, children=children))
    gltf.scenes.append(gl.Scene(name=asset.name, nodes=[len(gltf.nodes) - 1]))
    gltf.scene = 0

    animated = [(i, p) for i, p in enumerate(asset.parts) if p.motion is not None]
    if animated:
        anim = gl.Animation(name="swim")
        for node, part in animated:
            frames, angles = part.motion.keys(asset.clip_frames)
            times = blob.accessor((frames / asset.fps).astype(np.float32), gl.SCALAR, bounds=True)
            rot = blob.accessor(y_rotation_quaternions(angles).astype(np.float32), gl.VEC4)
            anim.samplers.append(gl.AnimationSampler(input=times, output=rot, interpolation="LINEAR"))
            anim.channels.append(gl.AnimationChannel(sampler=len(anim.samplers) - 1,
                                                     target=gl.AnimationChannelTarget(node=node,
                                                                                      path="rotation")))
        gltf.animations.append(anim)

    data = bytes(blob.data) + b"\0" * (-len(blob.data) % 4)
    gltf.buffers.append(gl.Buffer(byteLength=len(data)))
    return gltf, data, asset.images


def _json(gltf: gl.GLTF2) -> bytes:
    # Stable key order and no whitespace: same asset -> same bytes.
    doc = json.loads(gltf.to_json())
    return json.dumps(doc, separators=(",", ":"), sort_keys=True).encode("utf-8")


def glb_bytes(asset) -> bytes:
    """The asset as one binary glTF (.glb) file, in memory."""
    gltf, data, _ = build_gltf(asset)
    body = _json(gltf)
    body += b" " * (-len(body) % 4)
    total = 12 + 8 + len(body) + 8 + len(data)
    return b"".join([
        np.array([0x46546C67, 2, total], dtype="<u4").tobytes(),
        np.array([len(body), 0x4E4F534A], dtype="<u4").tobytes(), body,
        np.array([len(data), 0x004E4942], dtype="<u4").tobytes(), data,
    ])


def write_glb(asset, path: Path) -> list[Path]:
    write_files({path: glb_bytes(asset)})
    return [path]


def write_gltf(asset, path: Path) -> list[Path]:
    """``.gltf`` JSON with the buffer and textures as files beside it."""
    stem = path.stem
    # URIs are percent-encoded: a file named "a b.bin" is referenced as "a%20b.bin".
    gltf, data, images = build_gltf(asset, image_uri=lambda key: quote(f"{stem}_{key}.png"))
    gltf.buffers[0].uri = quote(f"{stem}.bin")
    files = {path: _json(gltf), path.with_name(f"{stem}.bin"): data}
    for key, png in images.items():
        files[path.with_name(f"{stem}_{key}.png")] = png
    write_files(files)
    return list(files)
