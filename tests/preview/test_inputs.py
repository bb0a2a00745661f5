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


def test_particles_that_lie_apart_are_kept_at_their_own_size():
    """Merging dots that do not overlap would draw one wide blob over the gaps between them."""
    scene = _points(25)
    assert thin_particles(scene, most=10) == "previewing its 25 particles as 9"
    (prim,) = scene.meshes[0].primitives
    assert set(prim.positions[:, 0].tolist()) <= set(range(0, 75, 3))
    np.testing.assert_array_equal(prim.attributes["_RADIUS"], 0.5)


def _blob(n: int = 4000) -> Scene:
    rng = np.random.default_rng(3)
    scene = Scene(name="blob")
    prim = Primitive({"POSITION": rng.normal(0, 1, (n, 3)).astype(np.float32),
                      "_RADIUS": rng.uniform(0.5, 1.5, n).astype(np.float32),
                      "_DENSITY": rng.uniform(0.001, 0.01, n).astype(np.float32),
                      "_LIGHT": rng.uniform(0, 1, n).astype(np.float32),
                      "COLOR_0": rng.integers(0, 256, (n, 4)).astype(np.uint8)}, mode="POINTS")
    scene.add_node(Node(name="p", mesh=scene.add_mesh(Mesh("p", [prim]))))
    return scene


def _mass(prim: Primitive) -> np.ndarray:
    r = prim.attributes["_RADIUS"].astype(np.float64)
    return prim.attributes["_DENSITY"] * r * r


def test_overlapping_particles_merge_keeping_their_optical_mass_light_and_colour():
    scene = _blob()
    before = scene.meshes[0].primitives[0]
    note = thin_particles(scene, most=400)
    after = scene.meshes[0].primitives[0]
    assert note == f"previewing its 4,000 particles as {after.vertex_count:,}"
    assert after.vertex_count <= 400
    assert after.attributes["_RADIUS"].mean() > before.attributes["_RADIUS"].mean()   # wider, fewer
    m0, m1 = _mass(before), _mass(after)
    np.testing.assert_allclose(m1.sum(), m0.sum(), rtol=1e-5)
    np.testing.assert_allclose((m1 * after.attributes["_LIGHT"]).sum() / m1.sum(),
                               (m0 * before.attributes["_LIGHT"]).sum() / m0.sum(), rtol=1e-5)
    rgba = before.attributes["COLOR_0"] / np.float32(255)
    np.testing.assert_allclose((m1[:, None] * after.attributes["COLOR_0"]).sum(axis=0) / m1.sum(),
                               (m0[:, None] * rgba).sum(axis=0) / m0.sum(), rtol=1e-5)


def test_a_thinned_dense_cloud_looks_like_the_whole_cloud():
    """Every k-th particle let the eye through to a dense cloud's grey inside (a thick sky came out
    up to 13 sRGB levels darker): merged, the picture stays near the whole cloud's from every side."""
    from dataclasses import replace

    from fishgen.clouds.scene import cloud_scene
    from fishgen.preview.inputs import _every
    from fishgen.preview.pipeline import frame_scene
    from fishgen.preview.render import Renderer

    model = load_cubes(PARAMS / "clouds" / "table_4_4.awn")
    model = replace(model, cubes=tuple(replace(c, particles=c.particles * 32) for c in model.cubes))
    cloud = light_cloud(fill_cloud(model, seed=0))
    renderer = Renderer(128, 96, fine_blending=True)
    sky = np.array([140, 173, 204], np.float64)

    def look(scene: Scene, view: str) -> np.ndarray:
        camera = frame_scene(scene, view, 128 / 96, [None], None)
        (image,) = renderer.render_all(scene, [(camera, None)], (0, 0, 0, 0), None)
        image = image.astype(np.float64)
        alpha = image[..., 3:] / 255
        return image[..., :3] * alpha + sky * (1 - alpha)

    merged, every = [], []
    try:
        for view in ("top", "side", "three-quarter"):
            whole = look(cloud_scene(cloud), view)
            thinned = cloud_scene(cloud)
            thin_particles(thinned, most=len(cloud) // 10)
            sparse = cloud_scene(cloud)
            sparse.meshes[0].primitives[0] = _every(sparse.meshes[0].primitives[0], 10)
            for errors, scene in ((merged, thinned), (every, sparse)):
                errors.append(float(np.sqrt(np.mean((look(scene, view) - whole) ** 2))))
    finally:
        renderer.release()
    assert np.mean(merged) <= 7, merged            # sRGB levels, RMS over the picture: 4.9 here
    assert np.mean(merged) <= 0.7 * np.mean(every), (merged, every)   # every k-th: 10.1


def _picture(scene: Scene, size: int = 64) -> np.ndarray:
    """The scene drawn from its side by the preview's renderer, over a transparent background (RGBA)."""
    from fishgen.preview.pipeline import frame_scene
    from fishgen.preview.render import Renderer

    renderer = Renderer(size, size, fine_blending=True)
    try:
        (image,) = renderer.render_all(scene, [(frame_scene(scene, "side", 1.0), None)], (0, 0, 0, 0), None)
    finally:
        renderer.release()
    return image.astype(np.float64)


def test_a_density_past_1_draws_as_that_many_stacked_particles():
    """How a merged stack keeps its opacity: one particle of density 3 is three drawn on each other."""
    def particles(density: float, n: int) -> Scene:
        scene = Scene(name="stack")
        prim = Primitive({"POSITION": np.zeros((n, 3), np.float32), "_RADIUS": np.ones(n, np.float32),
                          "_DENSITY": np.full(n, density, np.float32)}, mode="POINTS")
        scene.add_node(Node(name="p", mesh=scene.add_mesh(Mesh("p", [prim]))))
        return scene

    one, three = _picture(particles(3.0, 1)), _picture(particles(1.0, 3))
    assert np.abs(one[..., 3] - three[..., 3]).max() <= 2
    assert one[..., 3].max() > _picture(particles(1.0, 1))[..., 3].max() + 20
    # a colour's own alpha is each stacked sprite's, not part of the count (a review)
    for scene in (one_faint := particles(2.0, 1), two_faint := particles(1.0, 2)):
        prim = scene.meshes[0].primitives[0]
        prim.attributes["COLOR_0"] = np.tile(np.float32([1, 1, 1, 0.5]), (prim.vertex_count, 1))
    assert np.abs(_picture(one_faint)[..., 3] - _picture(two_faint)[..., 3]).max() <= 2


def test_points_strung_along_a_line_are_not_merged_away():
    """Merging a line widens its particles as fast as it thins them: merged again and again, 2,000
    points came out as one (a review). A further merge is kept only where it draws less."""
    scene = Scene(name="line")
    n = 2_000
    line = np.zeros((n, 3), np.float32)
    line[:, 0] = np.linspace(0, 10, n)
    points = Primitive({"POSITION": line}, mode="POINTS")
    scene.add_node(Node(name="p", mesh=scene.add_mesh(Mesh("p", [points]))))
    thin_particles(scene, most=100)
    prim = scene.meshes[0].primitives[0]
    assert 50 <= prim.vertex_count <= 100
    assert np.ptp(prim.positions[:, 0]) > 9


def test_coincident_particles_merged_stay_as_opaque_as_their_stack():
    """20,000 points on one spot drew a faint disc once merged (density capped at 1), an opaque one whole."""
    scene = Scene(name="spot")
    n = 20_000
    prim = Primitive({"POSITION": np.zeros((n, 3), np.float32), "_RADIUS": np.full(n, 0.3, np.float32)},
                     mode="POINTS")
    scene.add_node(Node(name="p", mesh=scene.add_mesh(Mesh("p", [prim]))))
    whole = _picture(scene)
    thin_particles(scene, most=1_000)
    assert scene.meshes[0].primitives[0].vertex_count == 1
    assert np.abs(_picture(scene)[..., 3] - whole[..., 3]).mean() < 8


def test_negative_and_unstated_radii_are_drawn_at_their_size():
    """A negative radius draws as its size, merged or not; a set 1e20 wide with no radii got infinite
    ones (its extent squared past float32)."""
    from fishgen.preview.render import point_radii

    scene = _blob()
    prim = scene.meshes[0].primitives[0]
    prim.attributes["_RADIUS"] = -prim.attributes["_RADIUS"]
    whole = _picture(scene)
    thin_particles(scene, most=400)
    assert (scene.meshes[0].primitives[0].attributes["_RADIUS"] > 0).all()
    assert abs((_picture(scene)[..., 3] > 0).mean() - (whole[..., 3] > 0).mean()) < 0.05
    wide = Primitive({"POSITION": np.array([[-1e20, 0, 0], [1e20, 0, 0]], np.float32)}, mode="POINTS")
    assert np.isfinite(point_radii(wide)).all()


def test_only_the_point_sets_a_renderer_draws_are_counted_and_thinned():
    """A sky's lower levels of detail stand in its second scene: not drawn, not counted."""
    scene = _points(25)
    hidden = Primitive({"POSITION": np.zeros((100, 3), np.float32)}, mode="POINTS")
    scene.add_mesh(Mesh("lod1", [hidden]))
    assert thin_particles(scene, most=10) == "previewing its 25 particles as 9"
    assert scene.meshes[1].primitives[0] is hidden


def test_a_moving_point_set_keeps_every_kth_particle():
    scene = _points(25)
    prim = scene.meshes[0].primitives[0]
    scene.meshes[0].primitives[0] = Primitive(prim.attributes, mode="POINTS",
                                              targets=[{"POSITION": np.ones((25, 3), np.float32)}])
    assert thin_particles(scene, most=10) == "previewing its 25 particles as 9"
    (prim,) = scene.meshes[0].primitives
    np.testing.assert_array_equal(prim.positions[:, 0], np.arange(0, 75, 9))
    assert len(prim.targets[0]["POSITION"]) == 9


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
    kept = scene.meshes[0].primitives[0].vertex_count
    assert scene.note == f"{tmp_path / 'cloud.ply'}: previewing its 554 particles as {kept}"
    assert kept <= 100
