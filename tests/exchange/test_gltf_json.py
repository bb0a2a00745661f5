"""The glTF writer's own JSON and GLB framing agree byte for byte with pygltflib's.

fishgen builds its documents with pygltflib's classes but serialises them itself (pygltflib's
deep copies were most of a school's write time); these tests pin the two together.
"""
from __future__ import annotations

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


@pytest.mark.parametrize("name", SCENES)
def test_json_is_pygltflib_json(name):
    gltf, _ = build_document(SCENES[name](), Path("x.glb"))
    expected = gltf.gltf_to_json(separators=(",", ":"), indent=None).encode("utf-8")
    assert document_json(gltf, Path("x.glb")) == expected


@pytest.mark.parametrize("name", ["fish", "school"])
def test_glb_container_is_pygltflib_container(name):
    scene = SCENES[name]()
    gltf, buf = build_document(scene, Path("x.glb"))
    gltf.set_binary_blob(b"".join(buf.pieces) + b"\0" * (-buf.length % 4))
    assert glb_bytes(scene) == b"".join(gltf.save_to_bytes())
    loaded = pygltflib.GLTF2.load_from_bytes(glb_bytes(scene))
    assert len(loaded.binary_blob()) == loaded.buffers[0].byteLength


def test_non_finite_numbers_are_refused_in_our_words():
    from fishgen.errors import FishgenError

    scene = SCENES["fish"]()
    gltf, _ = build_document(scene, Path("x.glb"))
    gltf.materials[0].pbrMetallicRoughness.roughnessFactor = float("nan")
    with pytest.raises(FishgenError, match="expected finite numbers"):
        document_json(gltf, Path("x.glb"))
