"""The one cube-file pipeline (fishgen.clouds.pipeline): every caller reads and fills through it, and
an empty cube stays empty however the file is scaled."""
from __future__ import annotations

import numpy as np
import pytest

import fishgen.clouds.pipeline as pipeline
from fishgen.clouds.lighting import Lighting
from fishgen.clouds.parser import load_cubes
from fishgen.clouds.pipeline import cube_clouds, read_cube_files, scaled
from fishgen.errors import UsageError

# 500 particles, the middle cube empty (as Table 4.3's line 16)
HOLLOW = "500\n3\n400, 4, 2, 2, 0, 0, 0, 0.8\n0, 1, 1, 1, 3, 0, 0, 0.5\n100, 2, 2, 2, 6, 0, 0, 0.6\n"
SCALED = [40, 0, 10]      # to 50 particles: every cube alike, the empty one still empty


def per_cube(cube_index: np.ndarray, cubes: int = 3) -> list[int]:
    return np.bincount(np.asarray(cube_index, np.int64), minlength=cubes).tolist()


def test_scaling_down_keeps_an_empty_cube_empty_and_a_small_one_alive(write_awn):
    model = load_cubes(write_awn(HOLLOW))
    assert [c.particles for c in scaled(model, 50).cubes] == SCALED
    assert [c.particles for c in scaled(model, 2).cubes] == [1, 0, 1]     # never a cube's last particle


def test_the_fill_is_seeded_per_input_offset_and_refused_over_the_limit(write_awn, tables):
    models = read_cube_files([tables["4.3"], write_awn(HOLLOW)])
    places = [(0, 0, 0), (30, 0, 0)]
    made = cube_clouds(models, seed=4, offsets=places, lighting=Lighting())
    apart = cube_clouds(models, seed=4, offsets=places, light=False)
    assert [len(c) for c in apart.clouds] == [554, 500] and apart.lit is None and made.clouds == ()
    assert np.array_equal(made.cloud.centers, np.concatenate([c.centers for c in apart.clouds]))
    assert made.cloud.light is not None and made.note is None
    alone = cube_clouds(models[1:], seed=5, light=False)      # input 1 is filled with seed 4 + 1
    assert np.allclose(alone.clouds[0].centers + [30, 0, 0], apart.clouds[1].centers, atol=1e-5)
    with pytest.raises(ValueError, match="unlit"):
        _ = alone.cloud
    with pytest.raises(UsageError, match="expected at most 1,000 particles in the scene .* in 2 files"):
        cube_clouds(models, max_particles=1000)


@pytest.fixture
def through(monkeypatch):
    """Record what goes through the pipeline: the files read and every fill's result."""
    seen: dict[str, list] = {"read": [], "filled": []}
    read, fill = pipeline.read_cube_files, pipeline.cube_clouds

    def reading(paths, **kw):
        seen["read"].append(out := read(paths, **kw))
        return out

    def filling(models, **kw):
        seen["filled"].append(out := fill(models, **kw))
        return out

    monkeypatch.setattr(pipeline, "read_cube_files", reading)
    monkeypatch.setattr(pipeline, "cube_clouds", filling)
    return seen


def test_the_five_callers_go_through_the_one_pipeline_and_agree_on_an_empty_cube(
        through, write_awn, tmp_path, monkeypatch):
    from fishgen.clouds.scene import cube_file_scene
    from fishgen.commands.clouds import CloudsOptions, clouds
    from fishgen.editor import session
    from fishgen.fly.assets import prepare_assets
    from fishgen.sky.build import build_sky

    hollow = write_awn(HOLLOW)
    full = [400, 0, 100]

    clouds([hollow], tmp_path / "c.ply", CloudsOptions(seed=3))                         # the command
    assert per_cube(through["filled"][-1].cloud.cube_index) == full

    scene = cube_file_scene(hollow, most=50)                                              # its preview
    assert per_cube(through["filled"][-1].cloud.cube_index) == SCALED
    assert per_cube(scene.meshes[0].primitives[0].attributes["_CUBE"]) == SCALED
    assert scene.note == f"{hollow}: previewing 50 of its 500 particles"

    monkeypatch.setattr(session, "PREVIEW_PARTICLES", 50)                                 # the editor
    _, facts = session.fill_glb(load_cubes(hollow), "particles", 0, Lighting())
    assert per_cube(through["filled"][-1].cloud.cube_index) == SCALED and facts["particles"] == 50

    prepare_assets([hollow], seed=2)                                                      # fly
    assert [per_cube(c.cube_index) for c in through["filled"][-1].clouds] == [full]

    sky = build_sky("thin", models=[hollow], particles=600, lod=False)                    # sky
    assert through["read"][-1][0].cubes == load_cubes(hollow).cubes
    counts = [per_cube(prim.attributes["_CUBE"]) for mesh in sky.scene.meshes for prim in mesh.primitives]
    assert len(counts) == 16 and all(c[1] == 0 and c[0] > c[2] > 0 for c in counts)
    # the editor fills the page's cubes, parsed already; sky fills each cloud, its model scaled by the plan
    assert (len(through["read"]), len(through["filled"])) == (4, 4 + 16)
    assert [per_cube(made.clouds[0].cube_index) for made in through["filled"][4:]] == counts
    assert all(made.lit is None for made in through["filled"][4:])
