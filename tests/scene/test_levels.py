"""Levels of detail in the scene model: one typed record (``Node.lods``) that the glTF writer turns
into MSFT_lod, the coarser levels in a second scene (no orphan nodes), for fish and skies alike."""
from __future__ import annotations

import json
import struct

import numpy as np
import pytest

from fishgen.exchange.gltf import glb_bytes
from fishgen.scene.model import Levels, Mesh, Node, Primitive, Scene


def _points(n: int) -> Mesh:
    return Mesh(f"points{n}", [Primitive({"POSITION": np.zeros((n, 3), np.float32)}, mode="POINTS")])


def _document(scene: Scene) -> dict:
    data = glb_bytes(scene)
    length, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON"
    return json.loads(data[20:20 + length])


def test_levels_want_a_coarser_level_and_one_decreasing_coverage_each():
    assert Levels((3, 4), (0.5, 0.2, 0.0)).coverage == (0.5, 0.2, 0.0)
    assert Levels((3,)).coverage == ()
    for nodes, coverage in (((), ()), ((3,), (0.5,)), ((3, 4), (0.5, 0.6, 0.0))):
        with pytest.raises(ValueError):
            Levels(nodes, coverage)


def test_add_levels_links_the_finest_and_hides_the_coarser_in_the_second_scene():
    scene = Scene(name="two clouds")
    for name in ("a", "b"):
        root = scene.add_node(Node(name=name))
        finest = scene.add_node(Node(name=f"{name}_LOD0", mesh=scene.add_mesh(_points(64))), parent=root)
        coarse = scene.add_node(Node(name=f"{name}_LOD1", mesh=scene.add_mesh(_points(8))), root=False)
        assert coarse not in scene.roots and all(coarse not in n.children for n in scene.nodes)
        scene.add_levels(finest, [coarse], [0.5, 0.0])
    scene.add_levels(0, [])                                   # no coarser level: nothing to do
    assert scene.nodes[0].lods is None
    assert scene.roots == [0, 3] and scene.hidden_roots == [2, 5]
    assert [i for i, _ in scene.drawn()] == [1, 4]            # a renderer draws the finest only

    doc = _document(scene)
    assert doc["extensionsUsed"] == ["MSFT_lod"] and "extensionsRequired" not in doc
    assert doc["nodes"][1]["extensions"] == {"MSFT_lod": {"ids": [2]}}
    assert doc["nodes"][1]["extras"] == {"MSFT_screencoverage": [0.5, 0.0]}
    assert doc["scene"] == 0 and doc["scenes"][1] == {"name": "levels of detail", "nodes": [2, 5]}
    in_a_scene = set()
    stack = [i for s in doc["scenes"] for i in s["nodes"]]
    while stack:
        i = stack.pop()
        in_a_scene.add(i)
        stack += doc["nodes"][i].get("children", [])
    assert in_a_scene == set(range(len(doc["nodes"])))        # no orphan: every node in a scene


def test_levels_left_out_of_every_scene_are_named_all_the_same():
    scene = Scene()
    finest = scene.add_node(Node(name="a_LOD0", mesh=scene.add_mesh(_points(64))))
    coarse = scene.add_node(Node(name="a_LOD1", mesh=scene.add_mesh(_points(8))), root=False)
    scene.add_levels(finest, [coarse], hidden=False)
    assert scene.hidden_roots == [] and scene.nodes[finest].lods == Levels((coarse,))
    doc = _document(scene)
    assert len(doc["scenes"]) == 1 and doc["nodes"][0]["extensions"] == {"MSFT_lod": {"ids": [1]}}
    assert "extras" not in doc["nodes"][0]                      # no coverage given: none written


def test_a_node_without_levels_writes_no_extension_and_keeps_its_extras():
    scene = Scene()
    scene.add_node(Node(name="one", mesh=scene.add_mesh(_points(4)), extras={"fishgen_cloud": {"k": 1}}))
    doc = _document(scene)
    assert "extensionsUsed" not in doc and len(doc["scenes"]) == 1
    assert "extensions" not in doc["nodes"][0] and doc["nodes"][0]["extras"] == {"fishgen_cloud": {"k": 1}}
