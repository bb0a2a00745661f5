"""Every input kind reaches the renderer with what an engine would use: materials, clips, radii."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.errors import FishgenError
from fishgen.preview.inputs import load_input
from fishgen.preview.render import particles
from fishgen.scene.pose import pose
from tests.conftest import PARAMS


def drawn_meshes(scene):
    """(node name, primitive, material) for every drawn triangle primitive."""
    return [(scene.nodes[n].name, p, scene.materials[p.material] if p.material is not None else None)
            for n, p in scene.drawn() if p.mode == "TRIANGLES"]


def point_sets(scene):
    posed = pose(scene)
    return [particles(scene, n, p, posed) for n, p in scene.drawn() if p.mode == "POINTS"]


def test_species_scene_has_textured_body_fins_and_swim_clip():
    scene = load_input(PARAMS / "bonybream.txt")
    assert [a.name for a in scene.clips] == ["swim"]
    body = [(p, m) for name, p, m in drawn_meshes(scene) if name == "body"]
    fins = [m for name, _, m in drawn_meshes(scene) if "fin" in name]
    assert body and body[0][1].texture is not None and "TEXCOORD_0" in body[0][0].attributes
    assert len(fins) >= 5 and all(f.double_sided for f in fins)
    assert {f.alpha_mode for f in fins} <= {"MASK", "BLEND", "OPAQUE"}


def test_posing_swings_the_fins_and_bends_the_body():
    from fishgen.scene.pose import deformed

    scene = load_input(PARAMS / "bonybream.txt")
    fin = next(i for i, n in enumerate(scene.nodes) if n.name == "pelvic_fin_left")
    body = next(i for i, n in enumerate(scene.nodes) if n.name == "body")
    duration = scene.clip().duration
    a, b = pose(scene, 0.0), pose(scene, duration / 16)             # a quarter of the pelvic cycle
    assert not np.allclose(a.world[fin], b.world[fin])                # the fin swings on its hinge
    assert np.allclose(a.world[body], b.world[body])                  # the body node stays put...
    prim = scene.meshes[scene.nodes[body].mesh].primitives[0]
    bend = deformed(scene, body, prim, b)[0] - deformed(scene, body, prim, a)[0]
    assert (np.abs(bend[:, 0]).max() > 0.02
            and np.abs(bend[:, 1:]).max() == 0)                       # ...and its mesh bends sideways


@pytest.mark.parametrize("ext", ["glb", "gltf", "obj", "ply"])
def test_fish_in_every_format_keeps_geometry_and_texture(assets, ext):
    scene = load_input(assets[f"fish.{ext}"])
    reference = load_input(assets["fish.glb"]).counts()
    assert scene.counts()["triangles"] == reference["triangles"]
    if ext != "ply":  # PLY carries no material: texture coordinates at most
        assert any(m is not None and m.texture is not None for _, _, m in drawn_meshes(scene))
    if ext == "obj":  # the MTL's map_d makes the fins a cut-out, as in the glb
        assert {m.alpha_mode for _, _, m in drawn_meshes(scene)} == {"OPAQUE", "MASK"}
    if ext in ("glb", "gltf"):
        assert scene.clip("swim") is not None


@pytest.mark.parametrize("ext", ["glb", "ply"])
def test_cloud_assets_carry_radius_and_density(assets, ext):
    scene = load_input(assets[f"cloud.{ext}"])
    direct = load_input(PARAMS / "clouds" / "table_4_3.awn")
    (points,), (expected,) = point_sets(scene), point_sets(direct)
    assert len(points[0]) == assets["cloud_len"] == len(expected[0])
    assert np.allclose(np.sort(points[1]), np.sort(expected[1]))
    assert np.allclose(np.sort(points[2][:, 3]), np.sort(expected[2][:, 3]), atol=1e-6)
    assert np.allclose(np.sort(points[2][:, 0]), np.sort(expected[2][:, 0]), atol=2e-3)


def test_points_without_radius_get_a_visible_default(tmp_path):
    import trimesh

    path = tmp_path / "bare.ply"
    trimesh.PointCloud(np.random.default_rng(0).random((50, 3))).export(path)
    (points,) = point_sets(load_input(path))
    assert np.all(points[1] > 0)


@pytest.mark.parametrize("name,content,message", [
    ("broken.glb", b"glTF\x02\x00\x00\x00garbage", r"expected a GLB of [\d,]+ bytes, as its header says, "
                                                 r"found 15 bytes$"),
    ("short.glb", b"glTF\x02\x00", r"expected a glTF 2\.0 file \(JSON, or GLB with a 12-byte header\), "
                                  r"found 6 bytes$"),
    ("broken.gltf", b"{not json", r"expected a glTF 2\.0 file \(JSON, or GLB with a 12-byte header\), "
                                  r"found invalid JSON at line 1 column 2"),
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


def _points_gltf(path, mode: int, indices: list[int] | None):
    """A .gltf of four points on the x axis (an embedded buffer), drawn in ``mode``, maybe indexed."""
    import base64
    import json

    blob = np.arange(12, dtype=np.float32).reshape(4, 3) * np.float32([1, 0, 0])
    data = blob.tobytes()
    prim: dict = {"attributes": {"POSITION": 0}, "mode": mode}
    accessors = [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                  "min": [0, 0, 0], "max": [9, 0, 0]}]
    views = [{"buffer": 0, "byteLength": 48}]
    if indices is not None:
        data += np.array(indices, np.uint16).tobytes() + b"\0" * (len(indices) % 2 * 2)
        views.append({"buffer": 0, "byteOffset": 48, "byteLength": 2 * len(indices)})
        accessors.append({"bufferView": 1, "componentType": 5123, "count": len(indices), "type": "SCALAR"})
        prim["indices"] = 1
    doc = {"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "scene": 0, "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [prim]}], "accessors": accessors, "bufferViews": views,
           "buffers": [{"byteLength": len(data),
                        "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}]}
    path.write_text(json.dumps(doc))
    return path


def test_indexed_points_draw_only_the_vertices_they_name(tmp_path):
    """glTF draws an indexed primitive's indices, not its vertices: all were drawn (a QA pass)."""
    (points,) = point_sets(load_input(_points_gltf(tmp_path / "indexed.gltf", 0, [1, 3])))
    np.testing.assert_array_equal(points[0][:, 0], [3, 9])


@pytest.mark.parametrize("mode, indices", [(1, None), (4, [0, 1])])   # lines; triangles of 2 indices
def test_an_asset_with_nothing_to_draw_is_an_error_not_a_blank_picture(tmp_path, mode, indices):
    with pytest.raises(FishgenError, match=r"nothing.gltf: expected triangles or points to draw "
                                           r"\(a preview draws no lines\), found none$"):
        load_input(_points_gltf(tmp_path / "nothing.gltf", mode, indices))


_ASCII_HEAD = ("ply\nformat ascii 1.0\nelement vertex 3\n"
               "property float x\nproperty float y\nproperty float z\n")


@pytest.mark.parametrize("text, message", [
    (_ASCII_HEAD + "end_header\n0 0 0\n1 1 1\n", r"short.ply:10: expected 3 rows of vertex \(x y z\), "
                                                 r"found the file ending after 2$"),
    (_ASCII_HEAD + "property float radius\nend_header\n0 0 0 0.5\n1 1 1 nan\n2 2 2 0.5\n",
     r"short.ply:10: expected finite radius values, found nan at vertex 2$"),
    (_ASCII_HEAD + "end_header\n0 0 0\n1 inf 1\n2 2 2\n",
     r"short.ply:9: expected finite vertex coordinates, found \[1.0, inf, 1.0\] at vertex 2$"),
    (_ASCII_HEAD + "end_header\n0 0 0 1 1 1 2 2 2\n",       # read as 1 vertex, silently
     r"short.ply:8: expected 3 numbers for a vertex \(x y z\), found 9: '0 0 0 1 1 1 2 2 2'$"),
    (_ASCII_HEAD + "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 nan 1\n"
     "2 2 2\n3 0 1 2\n",
     r"short.ply:11: expected finite vertex coordinates, found \[1.0, nan, 1.0\] at vertex 2$"),
])
def test_an_ascii_ply_is_faulted_at_its_line(tmp_path, text, message):
    """A QA pass: a short file was said in bytes after the header, a NaN radius at no line."""
    path = tmp_path / "short.ply"
    path.write_text(text)
    with pytest.raises(FishgenError, match=message):
        load_input(path)
