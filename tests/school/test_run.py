"""run_school: the warm-up in the file's extras, the measures the run prints, its keyword options."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.exchange.gltf import glb_bytes
from fishgen.exchange.gltf_reader import read_gltf
from fishgen.school.metrics import PRINTED
from fishgen.school.model import Variety, couzin_params
from fishgen.school.run import EXTRAS_KEY, run_school, school_extras, warmup_frames
from fishgen.school.scene_file import SceneFile, SpeciesEntry
from tests.conftest import PARAMS, assert_valid_gltf


def scene(count=12, frames=60, **kw) -> SceneFile:
    return SceneFile(species=(SpeciesEntry(PARAMS / "bonybream.txt", count),), frames=frames, **kw)


def test_the_file_records_its_warmup_for_the_preview(tmp_path):
    run = run_school(scene())
    assert run.warmup_frames == warmup_frames(60, 30.0) == 20
    path = tmp_path / "school.glb"
    path.write_bytes(glb_bytes(run.scene))
    assert_valid_gltf(path)
    record = school_extras(read_gltf(path))
    assert record == {"warmup": pytest.approx(20 / 30), "model": "boids", "fps": 30.0, "frames": 60,
                      "preroll": 0.0}
    # a scene file's (or the caller's) warm-up wins; broken records read as none
    assert run_school(scene(), warmup=0.5).scene.extras[EXTRAS_KEY]["warmup"] == 0.5
    bad = read_gltf(path)
    bad.extras[EXTRAS_KEY] = {"warmup": "soon"}
    assert school_extras(bad) is None


def test_the_warmup_is_a_third_of_a_short_run_and_three_seconds_of_a_long_one():
    assert warmup_frames(60, 30.0) == 20 and warmup_frames(900, 30.0) == 90
    assert warmup_frames(900, 30.0, seconds=12.0) == 360 and warmup_frames(60, 30.0, seconds=99) == 59


def test_the_run_measures_what_its_summary_prints_from_the_warmup_on():
    run = run_school(scene())
    printed = run.measures()
    assert set(printed) <= set(PRINTED) and "rotation" in printed
    assert all(np.isnan(v[:run.warmup_frames]).all() for v in printed.values())
    every = run.measures(every_frame=True)
    assert "heading_angle_max" in every and np.isfinite(every["polarization"]).all()
    table = run.summary(printed).splitlines()
    assert table[0].startswith("after 0.7 s warm-up") and any(line.startswith("rotation") for line in table)


def test_keyword_options_reach_the_simulation_and_the_bake():
    run = run_school(scene(count=20, frames=30, model="couzin"), couzin=couzin_params("highly parallel"),
                     variety=Variety(size=0.0, tints=3), length=0.5)
    assert run.config.couzin.orientation == 12.0 and np.allclose(run.tracks.scale, 1.0)
    assert np.allclose(run.body_lengths, 0.5, rtol=1e-3)
    assert len(run.scene.meshes) == 3 * len(run_school(scene(count=2, frames=30)).scene.meshes)
    assert run.scene.extras[EXTRAS_KEY]["model"] == "couzin"


def test_a_pre_roll_counts_in_whole_steps_as_it_was_simulated():
    """A pre-roll under one frame simulates nothing: it is no pre-roll, and the default warm-up stays
    (the summary said "after 0.001 s pre-roll" and dropped the warm-up). Others are said as run."""
    tiny = run_school(scene(frames=30, preroll=0.001))
    assert tiny.config.preroll_frames == 0 and tiny.warmup_frames == warmup_frames(30, 30.0) == 10
    assert tiny.summary().startswith("after 0.3 s warm-up")
    assert tiny.scene.extras[EXTRAS_KEY]["preroll"] == 0.0
    odd = run_school(scene(frames=30, preroll=0.05))                     # 1.5 frames: 2 steps
    assert odd.config.preroll_frames == 2 and odd.warmup_frames == 0
    assert odd.summary().startswith("after 0.0667 s pre-roll")
    assert odd.scene.extras[EXTRAS_KEY]["preroll"] == pytest.approx(2 / 30, abs=1e-6)
