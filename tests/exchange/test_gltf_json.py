"""The glTF writer's own documents and GLB framing are what pygltflib reads and writes.

fishgen builds its documents as plain dicts and frames the GLB itself (pygltflib's classes cost
every process 45 ms to import and its serialisation deep-copied every leaf); these tests pin the
members, their order and the container to pygltflib's.
"""
from __future__ import annotations

import json
import struct
from pathlib import Path

import pygltflib
import pytest

from fishgen.assembly.fish import build_fish
from fishgen.exchange.gltf import build_document, document_json, glb_bytes
from fishgen.scene.model import Scene
from fishgen.species.parser import load_species

ROOT = Path(__file__).resolve().parents[2]


def _school() -> Scene:
    from fishgen.school import run_school
    from fishgen.school.scene_file import SceneFile, SpeciesEntry

    return run_school(SceneFile(species=(SpeciesEntry(ROOT / "params" / "bonybream.txt", 6),),
                                frames=20)).scene


def _cloud() -> Scene:
    from fishgen.clouds.scene import cube_file_scene

    return cube_file_scene(ROOT / "params" / "clouds" / "table_4_2.awn")


SCENES = {
    "fish": lambda: build_fish(load_species(ROOT / "params" / "bonybream.txt")),
    "masked fish": lambda: build_fish(load_species(ROOT / "params" / "bonybream.txt"), fins="mask"),
    "school": _school,
    "cloud": _cloud,
}


# Members pygltflib writes out at their glTF default where fishgen leaves them out (both mean
# the same): an accessor's "normalized": false and a primitive's "mode": 4 (TRIANGLES).
SPELLED_OUT_DEFAULTS = {"normalized": False, "mode": 4}


def _pairs(text: bytes):
    """JSON with every object as its ordered list of (key, value) pairs."""
    return json.loads(text, object_pairs_hook=list)


def _spelled_out_default(key, value) -> bool:
    default = SPELLED_OUT_DEFAULTS.get(key, ...)
    return type(value) is type(default) and value == default


def _without_spelled_out_defaults(node):
    if isinstance(node, list):
        if node and all(isinstance(item, tuple) for item in node):  # an object's pairs
            return [(k, _without_spelled_out_defaults(v)) for k, v in node if not _spelled_out_default(k, v)]
        return [_without_spelled_out_defaults(item) for item in node]
    return node


@pytest.mark.parametrize("name", SCENES)
def test_pygltflib_reads_the_json_back_and_writes_the_same_members_in_the_same_order(name):
    doc, _ = build_document(SCENES[name](), Path("x.glb"))
    ours = document_json(doc, Path("x.glb"))
    again = pygltflib.GLTF2.from_json(ours.decode()).gltf_to_json(separators=(",", ":"), indent=None)
    assert _pairs(ours) == _without_spelled_out_defaults(_pairs(again.encode()))
    assert ours == json.dumps(json.loads(ours), separators=(",", ":")).encode()  # compact


@pytest.mark.parametrize("name", ["fish", "school"])
def test_glb_container_is_the_specs_layout_and_pygltflib_loads_it(name):
    data = glb_bytes(SCENES[name]())
    magic, version, total = struct.unpack_from("<4sII", data)
    assert (magic, version, total) == (b"glTF", 2, len(data))
    json_length, json_type = struct.unpack_from("<I4s", data, 12)
    bin_length, bin_type = struct.unpack_from("<I4s", data, 20 + json_length)
    assert (json_type, bin_type) == (b"JSON", b"BIN\0")
    assert json_length % 4 == 0 and bin_length % 4 == 0 and 28 + json_length + bin_length == len(data)
    assert data[20 + json_length - 1:20 + json_length] in (b"}", b" ")  # padded with spaces
    loaded = pygltflib.GLTF2.load_from_bytes(data)
    assert len(loaded.binary_blob()) == loaded.buffers[0].byteLength == bin_length


def test_non_finite_numbers_are_refused_in_our_words():
    from fishgen.errors import FishgenError

    scene = SCENES["fish"]()
    doc, _ = build_document(scene, Path("x.glb"))
    doc["materials"][0]["pbrMetallicRoughness"]["roughnessFactor"] = float("nan")
    with pytest.raises(FishgenError, match="expected finite numbers"):
        document_json(doc, Path("x.glb"))
