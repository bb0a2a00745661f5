"""What the preview reads: a point set bigger than a preview draws is thinned, and says so."""
from __future__ import annotations

import numpy as np

import fishgen.clouds.pipeline as pipeline
from fishgen.clouds import export_cloud, fill_cloud, light_cloud, load_cubes
from fishgen.preview.inputs import load_input, thin_particles
from fishgen.scene.model import Mesh, Node, Primitive, Scene
from tests.conftest import PARAMS


def _points(n: int) -> Scene:
    scene = Scene(name="points")
    prim = Primitive({"POSITION": np.arange(3 * n, dtype=np.float32).reshape(n, 3),
                      "_RADIUS": np.full(n, 0.5, np.float32)}, mode="POINTS")
    scene.add_node(Node(name="p", mesh=scene.add_mesh(Mesh("p", [prim]))))
    return scene


def test_every_kth_particle_is_kept_at_its_own_size():
    scene = _points(25)
    assert thin_particles(scene, most=10) == "previewing 9 of its 25 particles"
    (prim,) = scene.meshes[0].primitives
    np.testing.assert_array_equal(prim.positions[:, 0], np.arange(0, 75, 9))
    np.testing.assert_array_equal(prim.attributes["_RADIUS"], 0.5)


def test_a_set_a_preview_can_draw_is_left_alone():
    scene = _points(10)
    assert thin_particles(scene, most=10) is None
    assert scene.meshes[0].primitives[0].vertex_count == 10


def test_a_big_ply_cloud_is_previewed_thinned_and_says_so(tmp_path, monkeypatch):
    """A 10^7-particle PLY was drawn whole: over 8 minutes of CPU and 4.4 GB before it was stopped."""
    cloud = light_cloud(fill_cloud(load_cubes(PARAMS / "clouds" / "table_4_3.awn"), seed=0))
    export_cloud(cloud, tmp_path / "cloud.ply")
    monkeypatch.setattr(pipeline, "PREVIEW_PARTICLES", 100)
    scene = load_input(tmp_path / "cloud.ply")
    assert scene.note == f"{tmp_path / 'cloud.ply'}: previewing 93 of its 554 particles"
    assert scene.meshes[0].primitives[0].vertex_count == 93
