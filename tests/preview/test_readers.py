"""Every input kind reaches the renderer with what an engine would use: materials, clips, radii."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.errors import FishgenError
from fishgen.preview.inputs import load_input
from tests.conftest import PARAMS


def test_species_scene_has_textured_body_fins_and_swim_clip():
    scene = load_input(PARAMS / "bonybream.txt")
    assert [a.name for a in scene.animations] == ["swim"]
    body = [m for m in scene.meshes if scene.nodes[m.node].name == "body"]
    fins = [m for m in scene.meshes if "fin" in scene.nodes[m.node].name]
    assert body and body[0].material.texture is not None and body[0].uvs is not None
    assert len(fins) >= 5 and all(f.material.double_sided for f in fins)
    assert {f.material.alpha_mode for f in fins} <= {"MASK", "BLEND", "OPAQUE"}


def test_posing_moves_the_tail_but_not_the_body():
    scene = load_input(PARAMS / "bonybream.txt")
    tail = next(i for i, n in enumerate(scene.nodes) if n.name == "caudal_fin")
    body = next(i for i, n in enumerate(scene.nodes) if n.name == "body")
    duration = scene.clip().duration
    a, b = scene.world_matrices(0.0), scene.world_matrices(duration / 8)
    assert not np.allclose(a[tail], b[tail])
    assert np.allclose(a[body], b[body])


@pytest.mark.parametrize("ext", ["glb", "gltf", "obj", "ply"])
def test_fish_in_every_format_keeps_geometry_and_texture(assets, ext):
    scene = load_input(assets[f"fish.{ext}"])
    reference = load_input(assets["fish.glb"]).counts()
    assert scene.counts()["triangles"] == reference["triangles"]
    if ext != "ply":  # PLY carries no material: texture coordinates at most
        assert any(m.material.texture is not None for m in scene.meshes)
    if ext == "obj":  # the MTL's map_d makes the fins a cut-out, as in the glb
        assert {m.material.alpha_mode for m in scene.meshes} == {"OPAQUE", "MASK"}
    if ext in ("glb", "gltf"):
        assert scene.clip("swim") is not None


@pytest.mark.parametrize("ext", ["glb", "ply"])
def test_cloud_assets_carry_radius_and_density(assets, ext):
    scene = load_input(assets[f"cloud.{ext}"])
    direct = load_input(PARAMS / "clouds" / "table_4_3.awn")
    (points,), (expected,) = scene.points, direct.points
    assert len(points.positions) == assets["cloud_len"] == len(expected.positions)
    assert np.allclose(np.sort(points.radii), np.sort(expected.radii))
    assert np.allclose(np.sort(points.colors[:, 3]), np.sort(expected.colors[:, 3]), atol=1e-6)


def test_points_without_radius_get_a_visible_default(tmp_path):
    import trimesh

    path = tmp_path / "bare.ply"
    trimesh.PointCloud(np.random.default_rng(0).random((50, 3))).export(path)
    (points,) = load_input(path).points
    assert np.all(points.radii > 0)


@pytest.mark.parametrize("name,content,message", [
    ("broken.glb", b"glTF\x02\x00\x00\x00garbage", "not a readable glTF"),
    ("broken.gltf", b"{not json", "not a readable glTF"),
    ("notes.md", b"hello", "expected an input ending in"),
])
def test_bad_inputs_are_one_line_errors(tmp_path, name, content, message):
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(FishgenError, match=message):
        load_input(path)


def test_gltf_missing_its_bin_names_the_file(assets, tmp_path):
    import shutil

    shutil.copy(assets["fish.gltf"], tmp_path / "lonely.gltf")
    with pytest.raises(FishgenError, match="fish.bin"):
        load_input(tmp_path / "lonely.gltf")
