"""The glTF reader turns every malformed or oversized asset into one ``expected ..., found ...`` line.

Each fault class of issue 8 has a case here: broken node trees, indices out of
range, wrong TRS / factor sizes, accessor types and counts per semantic,
animation sampler counts and times, morph targets, skins, non-finite numbers,
and declared sizes that do not match the bytes (refused before allocating).
Valid edge cases (a node scaled to zero, or animated to zero) still load and render.
"""
from __future__ import annotations

import copy
import json
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest

from fishgen.errors import FishgenError
from fishgen.exchange import gltf_container
from fishgen.exchange.gltf_reader import read_gltf
from fishgen.scene.pose import bounds, pose
from tests.conftest import run_cli


class Doc:
    """A small valid glTF (one triangle, a material, an animation) to break one rule at a time."""

    def __init__(self) -> None:
        self.bin = bytearray()
        self.d: dict = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
                        "nodes": [{"mesh": 0, "name": "tri"}], "meshes": [], "accessors": [],
                        "bufferViews": [], "buffers": [],
                        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0.2, 1]}}]}
        self.pos = self.add(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32), "VEC3")
        self.nrm = self.add(np.array([[0, 0, 1]] * 3, np.float32), "VEC3")
        self.idx = self.add(np.array([0, 1, 2], np.uint16), "SCALAR", 5123)
        self.d["meshes"].append({"primitives": [{"attributes": {"POSITION": self.pos, "NORMAL": self.nrm},
                                                 "indices": self.idx, "material": 0}]})
        self.times = self.add(np.array([0, 1], np.float32), "SCALAR")
        self.rot = self.add(np.array([[0, 0, 0, 1], [0, 0.7071068, 0, 0.7071068]], np.float32), "VEC4")
        self.d["animations"] = [{"name": "turn", "samplers": [{"input": self.times, "output": self.rot}],
                                 "channels": [{"sampler": 0, "target": {"node": 0, "path": "rotation"}}]}]

    @property
    def prim(self) -> dict:
        return self.d["meshes"][0]["primitives"][0]

    def add(self, array: np.ndarray, kind: str, ctype: int = 5126, normalized: bool = False) -> int:
        """Append ``array`` to the buffer; returns the new accessor's index."""
        a = np.ascontiguousarray(array)
        self.d["bufferViews"].append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": a.nbytes})
        self.bin += a.tobytes()
        self.bin += b"\0" * (-len(self.bin) % 4)
        acc = {"bufferView": len(self.d["bufferViews"]) - 1, "componentType": ctype,
               "count": len(a), "type": kind}
        if normalized:
            acc["normalized"] = True
        self.d["accessors"].append(acc)
        return len(self.d["accessors"]) - 1

    def glb(self) -> bytes:
        d = copy.deepcopy(self.d)
        d["buffers"] = [{"byteLength": len(self.bin)}]
        text = json.dumps(d).encode()
        text += b" " * (-len(text) % 4)
        body = struct.pack("<II", len(text), 0x4E4F534A) + text
        body += struct.pack("<II", len(self.bin), 0x004E4942) + bytes(self.bin)
        return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body

    def write(self, folder: Path, name: str = "asset.glb") -> Path:
        path = folder / name
        if name.endswith(".glb"):
            path.write_bytes(self.glb())
        else:
            (folder / "asset.bin").write_bytes(bytes(self.bin))
            d = copy.deepcopy(self.d)
            d["buffers"] = [{"uri": "asset.bin", "byteLength": len(self.bin)}]
            path.write_text(json.dumps(d))
        return path


def refused(path: Path, pattern: str) -> str:
    """The one-line message, checked for its form and for ``pattern``."""
    with pytest.raises(FishgenError) as err:
        read_gltf(path)
    text = str(err.value)
    assert text.startswith(f"{path}: expected "), text
    assert ", found " in text and "\n" not in text, text
    assert not __import__("re").search(r"found \w+Error\b", text), text  # never an exception's name
    assert __import__("re").search(pattern, text), text
    return text


def test_the_base_document_is_valid(tmp_path):
    for name in ("asset.glb", "asset.gltf"):
        scene = read_gltf(Doc().write(tmp_path, name))
        assert scene.counts()["triangles"] == 1 and scene.clips[0].duration == 1.0
        assert scene.materials[0].base_color == (1, 0.5, 0.2, 1)


# -- node trees and indices ----------------------------------------------------------------
def _nodes(doc: Doc, nodes: list, roots: list) -> None:
    doc.d["nodes"], doc.d["scenes"] = nodes, [{"nodes": roots}]


def _set(path: str, value):
    """A mutation that sets ``a.b.0.c`` (dots, list indices as numbers) to ``value``."""
    def apply(doc: Doc) -> None:
        keys = [int(k) if k.isdigit() else k for k in path.split(".")]
        target = doc.d
        for k in keys[:-1]:
            target = target[k]
        target[keys[-1]] = value
    return apply


STRUCTURE = {
    "own child": (_set("nodes.0.children", [0]), r"node 0 as its own child"),
    "cycle": (lambda d: _nodes(d, [{"mesh": 0}, {"children": [2]}, {"children": [1]}], [0]),
              r"without cycles, found node 1 among its own ancestors"),
    "two parents": (lambda d: _nodes(d, [{"children": [2]}, {"children": [2]}, {"mesh": 0}], [0, 1]),
                    r"one parent for node 2, found nodes 0 and 1"),
    "child twice": (lambda d: _nodes(d, [{"children": [1, 1]}, {"mesh": 0}], [0]), r"listed twice"),
    "child out of range": (_set("nodes.0.children", [5]), r"node index from 0 to 0 at nodes\[0\]\.children"),
    "non-root in scene": (lambda d: _nodes(d, [{"children": [1]}, {"mesh": 0}], [0, 1]),
                          r"only root nodes at scenes\[0\]\.nodes, found node 1"),
    "scene out of range": (_set("scene", 3), r"scene index from 0 to 0"),
    # was "found TypeError: unhashable type: 'list'" (issue 26): a name, not an exception
    "extension not a name": (lambda d: d.d.update(extensionsRequired=[["KHR_x"]]),
                             r"an extension name at extensionsRequired\[0\], found a list"),
    "used extension not a name": (lambda d: d.d.update(extensionsUsed=[{"a": 1}]),
                                  r"an extension name at extensionsUsed\[0\], found an object"),
    "mesh out of range": (_set("nodes.0.mesh", 3), r"mesh index from 0 to 0 at nodes\[0\]\.mesh, found 3"),
    "skin out of range": (_set("nodes.0.skin", 0), r"skin index \(the file has no skins\)"),
    "material out of range": (_set("meshes.0.primitives.0.material", 2), r"material index from 0 to 0"),
    "texture out of range": (_set("materials.0.pbrMetallicRoughness.baseColorTexture", {"index": 4}),
                             r"texture index \(the file has no textures\)"),
    "image out of range": (lambda d: d.d.update(textures=[{"source": 3}]), r"image index"),
    "sampler out of range": (lambda d: d.d.update(textures=[{"sampler": 2}]), r"sampler index"),
    "accessor out of range": (_set("meshes.0.primitives.0.attributes.POSITION", 99),
                              r"accessor index from 0 to \d+ at meshes\[0\]\.primitives\[0\]\.attributes"),
    "bufferView out of range": (_set("accessors.0.bufferView", 99), r"bufferView index"),
    "buffer out of range": (_set("bufferViews.0.buffer", 3), r"buffer index from 0 to 0"),
    "animation sampler out of range": (_set("animations.0.channels.0.sampler", 5),
                                       r"sampler index from 0 to 0"),
    "animation node out of range": (_set("animations.0.channels.0.target.node", 7), r"node index"),
    "index not an integer": (_set("nodes.0.mesh", 0.5), r"mesh index .* found 0\.5"),
    "3-number rotation": (_set("nodes.0.rotation", [0, 0, 0]),
                          r"4 finite numbers at nodes\[0\]\.rotation, found 3"),
    "2-number translation": (_set("nodes.0.translation", [0, 0]),
                             r"3 finite numbers at nodes\[0\]\.translation"),
    "4-number scale": (_set("nodes.0.scale", [1, 1, 1, 1]), r"3 finite numbers at nodes\[0\]\.scale"),
    "15-number matrix": (_set("nodes.0.matrix", [1] * 15), r"16 finite numbers at nodes\[0\]\.matrix"),
    "string in translation": (_set("nodes.0.translation", [0, "a", 0]), r"3 finite numbers"),
    "3-number baseColorFactor": (_set("materials.0.pbrMetallicRoughness.baseColorFactor", [1, 1, 1]),
                                 r"4 finite numbers at materials\[0\]"
                                 r"\.pbrMetallicRoughness\.baseColorFactor"),
    "bad alphaMode": (_set("materials.0.alphaMode", "GLASS"), r"one of OPAQUE, MASK, BLEND"),
    "bad interpolation": (_set("animations.0.samplers.0.interpolation", "SMOOTH"),
                          r"LINEAR, STEP, CUBICSPLINE"),
    "version 1": (_set("asset.version", "1.0"), r'asset\.version "2\.0", found \'1\.0\''),
    "required extension": (_set("extensionsRequired", ["KHR_draco_mesh_compression"]),
                           r"found 'KHR_draco_mesh_compression'"),
    "primitive mode 9": (_set("meshes.0.primitives.0.mode", 9), r"integer from 0 to 6"),
    "negative count": (_set("accessors.0.count", -1), r"integer of at least 1 at accessors\[0\]\.count"),
    "bad componentType": (_set("accessors.0.componentType", 5130), r"componentType"),
    "bad byteStride": (_set("bufferViews.0.byteStride", 3), r"byteStride from 4 to 252"),
    "stride below element": (lambda d: (_set("bufferViews.0.byteStride", 4)(d)),
                             r"byteStride of at least 12"),
}


@pytest.mark.parametrize("case", list(STRUCTURE))
def test_structure_faults_are_one_line(tmp_path, case):
    doc = Doc()
    mutate, pattern = STRUCTURE[case]
    mutate(doc)
    refused(doc.write(tmp_path), pattern)


def test_infinite_and_nan_json_numbers_are_refused(tmp_path):
    path = Doc().write(tmp_path, "asset.gltf")
    text = path.read_text()
    path.write_text(text.replace('"name": "tri"', '"name": "tri", "translation": [0, 1e999, 0]'))
    refused(path, r"3 finite numbers at nodes\[0\]\.translation")
    path.write_text(text.replace('"name": "tri"', '"name": "tri", "scale": [NaN, 1, 1]'))
    refused(path, r"finite JSON numbers, found NaN")


# -- semantics, counts and data ------------------------------------------------------------------
def _attr(name: str, array, kind: str, ctype: int = 5126, normalized: bool = False):
    def apply(doc: Doc) -> None:
        doc.prim["attributes"][name] = doc.add(np.asarray(array), kind, ctype, normalized)
    return apply


def _skin(doc: Doc, joints=(0,), ibm_count: int | None = None, joint_values=0) -> None:
    doc.d["nodes"] = [{"mesh": 0, "skin": 0, "children": [1]}, {"name": "bone"}]
    doc.prim["attributes"]["JOINTS_0"] = doc.add(np.full((3, 4), joint_values, np.uint8), "VEC4", 5121)
    doc.prim["attributes"]["WEIGHTS_0"] = doc.add(np.tile([1, 0, 0, 0], (3, 1)).astype(np.float32), "VEC4")
    n = len(joints) if ibm_count is None else ibm_count
    ibm = doc.add(np.tile(np.eye(4, dtype=np.float32).ravel(), (n, 1)), "MAT4")
    doc.d["skins"] = [{"joints": list(joints), "inverseBindMatrices": ibm}]


def _morph(doc: Doc, targets_per_prim=(1,), weights_len: int | None = None) -> None:
    prims = []
    for t in targets_per_prim:
        p = copy.deepcopy(doc.prim)
        p["targets"] = [{"POSITION": doc.add(np.full((3, 3), 0.1, np.float32), "VEC3")} for _ in range(t)]
        prims.append(p)
    doc.d["meshes"][0]["primitives"] = prims
    if weights_len is not None:
        doc.d["meshes"][0]["weights"] = [0.0] * weights_len


def _channel(doc: Doc, path: str, values, kind: str, interp: str = "LINEAR", times=(0, 1)) -> None:
    doc.times = doc.add(np.asarray(times, np.float32), "SCALAR")
    out = doc.add(np.asarray(values, np.float32), kind)
    doc.d["animations"] = [{"samplers": [{"input": doc.times, "output": out, "interpolation": interp}],
                            "channels": [{"sampler": 0, "target": {"node": 0, "path": path}}]}]


SEMANTICS = {
    "2 normals for 3 positions": (_attr("NORMAL", np.zeros((2, 3), np.float32), "VEC3"),
                                  r"3 NORMAL values \(one per POSITION\) .* found 2"),
    "POSITION as VEC2": (lambda d: d.prim["attributes"].update(
        POSITION=d.add(np.zeros((3, 2), np.float32), "VEC2")), r"POSITION as VEC3 of floats"),
    "NORMAL as bytes": (_attr("NORMAL", np.zeros((3, 3), np.int8), "VEC3", 5120, True), r"NORMAL as VEC3"),
    "TEXCOORD_0 as VEC3": (_attr("TEXCOORD_0", np.zeros((3, 3), np.float32), "VEC3"), r"TEXCOORD_0 as VEC2"),
    "TEXCOORD_0 unnormalized bytes": (_attr("TEXCOORD_0", np.zeros((3, 2), np.uint8), "VEC2", 5121),
                                      r"TEXCOORD_0 as VEC2"),
    "COLOR_0 as VEC2": (_attr("COLOR_0", np.zeros((3, 2), np.float32), "VEC2"), r"COLOR_0 as VEC3 or VEC4"),
    "JOINTS_0 as floats": (_attr("JOINTS_0", np.zeros((3, 4), np.float32), "VEC4"),
                           r"JOINTS_0 as VEC4 of unsigned bytes or shorts"),
    "WEIGHTS_0 as VEC3": (_attr("WEIGHTS_0", np.zeros((3, 3), np.float32), "VEC3"), r"WEIGHTS_0 as VEC4"),
    "_RADIUS as VEC3": (_attr("_RADIUS", np.zeros((3, 3), np.float32), "VEC3"), r"_RADIUS as SCALAR"),
    "indices as floats": (lambda d: d.prim.update(indices=d.add(np.zeros(3, np.float32), "SCALAR")),
                          r"indices as SCALAR unsigned"),
    "index past the vertices": (lambda d: d.prim.update(indices=d.add(np.array([0, 1, 7], np.uint16),
                                                                       "SCALAR", 5123)),
                                r"vertex indices below 3 at meshes\[0\]\.primitives\[0\], found 7"),
    "NaN position": (lambda d: d.prim["attributes"].update(POSITION=d.add(
        np.array([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]], np.float32), "VEC3")),
                     r"finite numbers .* found nan"),
    "infinite normal": (_attr("NORMAL", np.array([[0, 0, np.inf]] * 3, np.float32), "VEC3"), r"found inf"),
    "rotation output count": (lambda d: _channel(d, "rotation", [[0, 0, 0, 1]], "VEC4"),
                              r"2 output values \(2 keyframes\) .* found 1"),
    "cubic output count": (lambda d: _channel(d, "translation", np.zeros((2, 3)), "VEC3", "CUBICSPLINE"),
                           r"6 output values \(2 keyframes x 3\) .* found 2"),
    "rotation as VEC3": (lambda d: _channel(d, "rotation", np.zeros((2, 3)), "VEC3"),
                         r"rotation keyframes as VEC4"),
    "NaN time": (lambda d: _channel(d, "scale", np.ones((2, 3)), "VEC3", times=(0, np.nan)),
                 r"finite numbers .* found nan"),
    "decreasing times": (lambda d: _channel(d, "scale", np.ones((3, 3)), "VEC3", times=(0, 2, 1)),
                         r"keyframe times that never decrease .* found 1 after 2"),
    "morph counts differ": (lambda d: _morph(d, (1, 2)), r"same number of morph targets .* found 1, 2"),
    "mesh weights count": (lambda d: _morph(d, (2,), weights_len=3), r"2 default weights .* found 3"),
    "weights without targets": (lambda d: _channel(d, "weights", [0, 1], "SCALAR"),
                                r"a node with morph targets .* found node 0 without any"),
    "weights output count": (lambda d: (_morph(d, (2,)), _channel(d, "weights", [0, 1], "SCALAR")),
                             r"4 output values \(2 keyframes x 2\)"),
    "joint out of range": (lambda d: _skin(d, joints=(0, 9)),
                           r"node index from 0 to 1 at skins\[0\]\.joints\[1\]"),
    "no joints": (lambda d: _skin(d, joints=(), ibm_count=1), r"at least one joint"),
    "inverse bind count": (lambda d: _skin(d, joints=(0, 1), ibm_count=1),
                           r"2 inverseBindMatrices \(one per joint\) .* found 1"),
    "JOINTS_0 past the joints": (lambda d: _skin(d, joints=(0, 1), joint_values=2),
                                 r"JOINTS_0 values below 2 .* found 2"),
    "weights summing to 0": (lambda d: (_skin(d), d.prim["attributes"].update(
        WEIGHTS_0=d.add(np.zeros((3, 4), np.float32), "VEC4"))), r"WEIGHTS_0 .* summing to 1"),
    # finite numbers that multiply past what a float32 camera can frame (the fuzz harness's
    # finding at 0.2.17: a cloud's default morph weight of 1e300, its points posed to NaN)
    "morph weight past reach": (lambda d: (_morph(d, (1,), weights_len=1),
                                           d.d["meshes"][0].update(weights=[1e300])),
                                r"within 1e30 of the origin posed at rest .* found one 1e\+299 away"),
    "nested scales past reach": (lambda d: d.d.update(nodes=[{"children": [1], "scale": [1e20] * 3},
                                                             {"mesh": 0, "scale": [1e20] * 3}]),
                                 r"within 1e30 of the origin posed at rest .* found one 1e\+40 away"),
    "animated past reach": (lambda d: _channel(d, "translation", [[0, 0, 0], [1e35, 0, 0]], "VEC3"),
                            r"posed in animation .* at 0.5 s .* found one 5e\+34 away"),
}


@pytest.mark.parametrize("case", list(SEMANTICS))
def test_data_faults_are_one_line(tmp_path, case):
    doc = Doc()
    mutate, pattern = SEMANTICS[case]
    mutate(doc)
    refused(doc.write(tmp_path), pattern)


def test_large_scenes_within_reach_load(tmp_path):
    """Scales, weights and translations large but within a float32 camera's reach still load."""
    doc = Doc()
    _morph(doc, (1,), weights_len=1)
    doc.d["meshes"][0]["weights"] = [1e20]
    doc.d["nodes"] = [{"children": [1], "scale": [1e4] * 3}, {"mesh": 0, "translation": [1e9, 0, 0]}]
    scene = read_gltf(doc.write(tmp_path))
    assert np.isfinite(bounds(scene)).all() and np.abs(bounds(scene)).max() > 1e23


def test_valid_skins_morphs_and_cubic_splines_load(tmp_path):
    doc = Doc()
    _skin(doc, joints=(0, 1), joint_values=1)
    _morph(doc, (2,), weights_len=2)
    doc.d["nodes"][0]["skin"] = 0
    read_gltf(doc.write(tmp_path))
    doc = Doc()
    _morph(doc, (2,))
    _channel(doc, "weights", np.zeros(12), "SCALAR", "CUBICSPLINE")
    scene = read_gltf(doc.write(tmp_path))
    assert scene.clips[0].channels[0].sampler.values.shape == (6, 2)


# -- sizes: refused before reading or allocating -------------------------------------------------
def test_accessor_larger_than_its_view_is_refused(tmp_path):
    doc = Doc()
    doc.d["accessors"][doc.pos]["count"] = 10**8
    doc.d["accessors"][doc.nrm]["count"] = 10**8
    path = doc.write(tmp_path)
    assert path.stat().st_size < 2000
    refused(path, r"accessors\[0\] \(100,000,000 elements of 12 bytes from byte 0\) within bufferView 0 "
                  r"of 36 bytes, found 1,200,000,000 bytes needed")


def test_view_past_its_buffer_is_refused(tmp_path):
    doc = Doc()
    doc.d["bufferViews"][0]["byteLength"] = 10**9
    refused(doc.write(tmp_path), r"bufferViews\[0\] \(bytes 0 to 1,000,000,000\) within buffer 0")


def test_accessor_without_view_over_the_element_cap_is_refused(tmp_path):
    doc = Doc()
    doc.d["accessors"].append({"componentType": 5126, "count": 10**8, "type": "VEC3"})
    refused(doc.write(tmp_path), r"at most 67,108,864 accessor components in the file")


def test_zero_filled_accessor_within_the_cap_reads(tmp_path):
    doc = Doc()
    doc.d["accessors"].append({"componentType": 5126, "count": 3, "type": "VEC3"})
    doc.prim["attributes"]["NORMAL"] = len(doc.d["accessors"]) - 1
    prim = read_gltf(doc.write(tmp_path)).meshes[0].primitives[0]
    assert not prim.attributes["NORMAL"].any()


def test_buffer_file_of_another_size_is_refused_by_stat(tmp_path):
    path = Doc().write(tmp_path, "asset.gltf")
    with (tmp_path / "asset.bin").open("r+b") as f:
        f.truncate(2 * 2**30)  # sparse: 2 GiB by stat, nothing on disk
    refused(path, r"a buffer file of at most 512\.0 MiB at buffers\[0\], found 'asset\.bin' of 2\.0 GiB")
    with (tmp_path / "asset.bin").open("r+b") as f:
        f.truncate(1000)
    refused(path, r"bytes in 'asset\.bin' \(buffers\[0\]\.byteLength\), found 1,000 bytes")


def test_whole_file_over_the_cap_is_refused_by_stat(tmp_path):
    path = Doc().write(tmp_path)
    with path.open("r+b") as f:
        f.truncate(4 * 2**30)
    refused(path, r"a glTF file of at most 512\.0 MiB, found 4\.0 GiB")
    big_json = tmp_path / "big.gltf"
    with big_json.open("wb") as f:
        f.write(b"{")
        f.truncate(200 * 2**20)
    refused(big_json, r"a glTF JSON file of at most 128\.0 MiB")


def test_data_uri_over_the_cap_is_refused_before_decoding(tmp_path, monkeypatch):
    import base64

    doc = Doc()
    d = copy.deepcopy(doc.d)
    d["buffers"] = [{"uri": "data:application/octet-stream;base64," + base64.b64encode(doc.bin).decode(),
                     "byteLength": len(doc.bin)}]
    path = tmp_path / "inline.gltf"
    path.write_text(json.dumps(d))
    assert read_gltf(path).counts()["triangles"] == 1
    monkeypatch.setattr(gltf_container, "MAX_DATA_URI_CHARS", 64)
    refused(path, r"a data URI of at most 64 bytes at buffers\[0\]")
    monkeypatch.undo()
    d["buffers"][0]["byteLength"] += 4
    d["bufferViews"][0]["byteLength"] = 36
    path.write_text(json.dumps(d))
    refused(path, r"bytes in the data URI of buffers\[0\], found")


def test_too_many_json_items_are_refused_before_parsing(tmp_path, monkeypatch):
    doc = Doc()
    doc.d["extras"] = [0] * 1000
    monkeypatch.setattr(gltf_container, "MAX_JSON_ITEMS", 500)
    refused(doc.write(tmp_path), r"a JSON document of at most 500 items")


def _png_header(width: int, height: int) -> bytes:
    """A PNG whose header claims ``width`` x ``height`` (no real pixel data follows)."""
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    chunk = b"IHDR" + ihdr
    return (b"\x89PNG\r\n\x1a\n" + struct.pack(">I", len(ihdr)) + chunk
            + struct.pack(">I", zlib.crc32(chunk)) + struct.pack(">I", 0) + b"IEND"
            + struct.pack(">I", zlib.crc32(b"IEND")))


def _png(size=(4, 4)) -> bytes:
    import io

    from PIL import Image

    out = io.BytesIO()
    Image.new("RGBA", size, (255, 0, 0, 255)).save(out, "PNG")
    return out.getvalue()


def _textured(doc: Doc, image: bytes) -> None:
    view = len(doc.d["bufferViews"])
    doc.d["bufferViews"].append({"buffer": 0, "byteOffset": len(doc.bin), "byteLength": len(image)})
    doc.bin += image
    doc.bin += b"\0" * (-len(doc.bin) % 4)
    doc.d["images"] = [{"bufferView": view, "mimeType": "image/png"}]
    doc.d["textures"] = [{"source": 0}]
    doc.d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    doc.prim["attributes"]["TEXCOORD_0"] = doc.add(np.zeros((3, 2), np.float32), "VEC2")


def test_huge_texture_is_refused_from_its_header(tmp_path):
    doc = Doc()
    _textured(doc, _png_header(12000, 12000))
    refused(doc.write(tmp_path),
            r"at most 8192 px a side and 67,108,864 pixels at images\[0\].*found 12000x12000")
    doc = Doc()
    _textured(doc, _png_header(8192, 8193))
    refused(doc.write(tmp_path), r"found 8192x8193")


def test_damaged_texture_is_a_reader_error(tmp_path):
    png = bytearray(_png())
    png[-20] ^= 0xFF  # inside the IDAT chunk: its CRC no longer matches
    doc = Doc()
    _textured(doc, bytes(png))
    refused(doc.write(tmp_path), r"an undamaged image at images\[0\]")
    doc = Doc()
    _textured(doc, b"not an image at all")
    refused(doc.write(tmp_path), r"a PNG or JPEG image at images\[0\].*found unreadable data")
    doc = Doc()
    _textured(doc, _png())
    scene = read_gltf(doc.write(tmp_path))
    assert scene.images[0].rgba().shape == (4, 4, 4)


def test_glb_container_faults(tmp_path):
    good = Doc().glb()
    cases = {
        b"glTF": r"a glTF 2\.0 file \(JSON, or GLB with a 12-byte header\), found 4 bytes",
        good[:8] + struct.pack("<I", 10**9) + good[12:]: r"a GLB of 1,000,000,000 bytes",
        good[:4] + struct.pack("<I", 1) + good[8:]: r"a GLB of version 2, found version 1",
        good[:12] + struct.pack("<I", 10**9) + good[16:]: r"a GLB chunk of 1,000,000,000 bytes "
                                                          r"within the file",
        b"\xff\xfe{}": r"found bytes that are not UTF-8",
        b"[1, 2]": r"holding a JSON object, found a JSON list",
        b"[" * 100000: r"found JSON nested too deeply|found invalid JSON",
    }
    for k, (data, pattern) in enumerate(cases.items()):
        path = tmp_path / f"bad{k}.glb"
        path.write_bytes(data)
        refused(path, pattern)


def test_glb_bytes_cannot_name_side_files():
    doc = Doc()
    doc.d["images"] = [{"uri": "skin.png"}]
    with pytest.raises(FishgenError,
                       match=r"^<glb>: expected only embedded data, found a reference to 'skin.png'"):
        read_gltf(data=doc.glb())


# -- valid edge cases render -----------------------------------------------------------------
def test_scale_zero_and_scale_animated_to_zero_load_and_pose(tmp_path):
    doc = Doc()
    doc.d["nodes"][0]["scale"] = [0, 0, 0]
    scene = read_gltf(doc.write(tmp_path, "zero.glb"))
    assert np.allclose(bounds(scene), 0)
    doc = Doc()
    _channel(doc, "scale", [[1, 1, 1], [0, 0, 0]], "VEC3")
    scene = read_gltf(doc.write(tmp_path, "shrink.glb"))
    assert np.allclose(pose(scene, 1.0).world[0][:3, :3], 0)




@pytest.mark.usefixtures("gl_available")
@pytest.mark.parametrize("case", ["scale zero", "scale animated to zero"])
def test_cli_renders_zero_scale(tmp_path, case):
    doc = Doc()
    if case == "scale zero":
        doc.d["nodes"] = [{"children": [1]}, {"mesh": 0, "scale": [0, 0, 0]}]
        doc.d["nodes"].append({"mesh": 0, "translation": [1, 0, 0]})
        doc.d["nodes"][0]["children"].append(2)
        doc.d["animations"][0]["channels"][0]["target"]["node"] = 2
    else:
        _channel(doc, "scale", [[1, 1, 1], [0, 0, 0]], "VEC3")
    path = doc.write(tmp_path)
    for out, extra in ((tmp_path / "still.png", ["--time", "1"]), (tmp_path / "loop.gif", ["--frames", "3"])):
        result = run_cli("preview", path, "-o", out, "--size", "64x48", *extra)
        assert result.returncode == 0 and out.is_file(), result.stderr


@pytest.mark.usefixtures("gl_available")
def test_cli_reports_a_hostile_glb_in_one_line(tmp_path):
    doc = Doc()
    doc.d["accessors"][doc.pos]["count"] = 10**8
    path = doc.write(tmp_path)
    result = run_cli("preview", path, "-o", tmp_path / "x.png", "--size", "64x48")
    assert result.returncode == 2, result.stderr
    assert result.stderr.strip().startswith(f"{path}: expected accessors[0]"), result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr


def test_skinned_mesh_with_a_joint_scaled_to_zero_poses(tmp_path):
    from fishgen.scene.pose import deformed

    doc = Doc()
    _skin(doc, joints=(1,))
    _channel(doc, "scale", [[1, 1, 1], [0, 0, 0]], "VEC3")
    doc.d["animations"][0]["channels"][0]["target"]["node"] = 1
    scene = read_gltf(doc.write(tmp_path))
    positions, _ = deformed(scene, 0, scene.meshes[0].primitives[0], pose(scene, 1.0))
    assert np.allclose(positions, 0)


def test_morph_target_names_are_read_back_and_odd_ones_ignored(tmp_path):
    """extras.targetNames (what three.js, Blender and Godot name blend shapes by) survive a round
    trip; names that are not one string per target are application data, not names."""
    from fishgen.assembly.fish import build_fish
    from fishgen.exchange import export
    from fishgen.species.parser import load_species
    from tests.conftest import PARAMS

    out = tmp_path / "fish.glb"
    export(build_fish(load_species(PARAMS / "bonybream.txt")), out)
    body = next(m for m in read_gltf(out).meshes if m.name == "body")
    assert body.target_names == ["wave_sin+", "wave_sin-", "wave_cos+", "wave_cos-"]
    from fishgen.exchange.gltf_scene import _target_names
    assert _target_names({"extras": {"targetNames": ["a"]}, "primitives": [{"targets": [{}, {}]}]}) == []
    assert _target_names({"extras": {"targetNames": [1, 2]}, "primitives": [{"targets": [{}, {}]}]}) == []
