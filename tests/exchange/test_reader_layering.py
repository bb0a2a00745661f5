"""The readers' layering: each step of the glTF reader uses only the steps before it, and the
OBJ/PLY reader shares only ``exchange.guards`` with it.

The steps, in order: container -> checks -> accessors -> scene -> the entry, ``gltf_reader``.
Each case runs a real read in a fresh interpreter, so lazy imports count too.
"""
from __future__ import annotations

import pytest

from tests.geometry.test_layering import modules_loaded_by

STEPS = ("fishgen.exchange.gltf_container", "fishgen.exchange.gltf_checks",
         "fishgen.exchange.gltf_accessors", "fishgen.exchange.gltf_scene", "fishgen.exchange.gltf_reader")
CORPUS = "fishgen/fuzz/seeds"
GLTF = f"{CORPUS}/gltf/pineapplefish_gltf/pineapplefish.gltf"


def test_mesh_reader_reads_obj_and_ply_without_the_gltf_reader():
    loaded = modules_loaded_by(
        ("fishgen.exchange.mesh_reader",),
        f"fishgen.exchange.mesh_reader.read_mesh_file('{CORPUS}/obj/pineapplefish/pineapplefish.obj')\n"
        f"fishgen.exchange.mesh_reader.read_mesh_file('{CORPUS}/ply/pineapplefish/pineapplefish.ply')")
    assert "fishgen.exchange.guards" in loaded
    assert [m for m in loaded if m.startswith("fishgen.exchange.gltf_")] == []


# Reads the file's bytes and checks them, with steps 0 and 1 only.
CHECKED = ("from pathlib import Path\nfrom fishgen.exchange import gltf_checks, gltf_container\n"
           f"doc, blob = gltf_container.unpack(Path('{GLTF}').read_bytes())\n"
           f"document = gltf_checks.check_document(doc, blob, Path('{GLTF}'))\n")


@pytest.mark.parametrize("step, then", [
    (0, f"from pathlib import Path\nfishgen.exchange.gltf_container.unpack(Path('{GLTF}').read_bytes())"),
    (1, CHECKED),
    (2, CHECKED + "d = fishgen.exchange.gltf_accessors.Decoder(document)\nd.accessor(0)\nd.image_bytes(0)"),
    (3, CHECKED + "fishgen.exchange.gltf_scene.build_scene(document, 'fish', 'fish.gltf')"),
], ids=[s.rsplit(".", 1)[1] for s in STEPS[:4]])
def test_each_gltf_step_uses_no_later_one(step, then):
    loaded = modules_loaded_by((STEPS[step],), then)
    assert [m for m in STEPS[step + 1:] if m in loaded] == []
