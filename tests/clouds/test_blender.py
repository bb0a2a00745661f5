"""Blender imports a billboard cloud as three.js shows it: blended, vertex colour times the sprite
(or a texture cloud's PNG), alpha from both, unlit, with the sunlight record kept.

Needs a Python with PyPI's `bpy` (3.11 only, large: its own venv), found at $FISHGEN_BPY_PYTHON
or /tmp/bpyvenv/bin/python; skipped without one (tools/check_clients.py --blender is the
project's other Blender route).
"""
from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest
from cloud_tables import PARAMS, TABLES

from fishgen.clouds import Lighting, export_cloud, fill_cloud, light_cloud, load_cubes

SCRIPT = Path(__file__).with_name("blender_clouds.py")
BPY = next((p for p in (os.environ.get("FISHGEN_BPY_PYTHON"), "/tmp/bpyvenv/bin/python")
            if p and Path(p).is_file()), None)
pytestmark = pytest.mark.skipif(BPY is None, reason="no Python with bpy ($FISHGEN_BPY_PYTHON)")


def test_blender_shows_the_billboards_blended_coloured_and_unlit(tmp_path):
    cloud = light_cloud(fill_cloud(load_cubes(TABLES["4.4"]), seed=0), Lighting(sun=(1, 0.3, 0)))
    sky = light_cloud(fill_cloud(load_cubes(PARAMS / "sky.awa"), seed=0))
    export_cloud(cloud, tmp_path / "billboards.glb", billboards=True)
    export_cloud(sky, tmp_path / "sky.glb", billboards=True)
    run = subprocess.run([BPY, str(SCRIPT), str(tmp_path / "billboards.glb"), str(tmp_path / "sky.glb")],
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    reports = [json.loads(line) for line in run.stdout.splitlines() if line.startswith("{")]
    billboards, textured = reports
    assert billboards["triangles"] == 6 * len(cloud) and "Color" in billboards["color_attributes"]
    assert "_LIGHT" in billboards["attributes"] and "fishgen_light" in billboards["scene_extras"]
    for report, images in ((billboards, [["gaussian sprite"]]), (textured, [["billow.png"], ["cumulus.png"],
                                                                            ["wisp.png"]])):
        assert sorted(m["images"] for m in report["materials"]) == images
        for m in report["materials"]:
            assert "BLEND" in (m["render_method"], m["blend_method"]) or m["render_method"] == "BLENDED"
            assert m["uses_vertex_colour"] and m["uses_image"] and m["unlit"] and m["transparent"]
            assert {"VERTEX_COLOR", "TEX_IMAGE"} <= set(m["alpha_from"])
