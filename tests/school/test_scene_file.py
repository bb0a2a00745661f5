"""School scene files: every mistake is one FILE:LINE line; absurd sizes refused before allocating."""
from __future__ import annotations

import pytest

from fishgen.errors import FishgenError
from fishgen.school.scene_file import load_scene_file
from tests.conftest import PARAMS


def test_the_shipped_reef_has_two_species_and_a_predator():
    scene = load_scene_file(PARAMS / "reef.toml")
    assert [e.file.name for e in scene.species] == ["bonybream.txt", "threadfingoldie.txt"]
    assert [e.count for e in scene.species] == [60, 40] and scene.predator is not None
    assert scene.predator.kind == "figure8" and scene.frames == 300 and scene.seed == 7


@pytest.mark.parametrize("text,line,message", [
    ('model = "swarm"\n[[species]]\nfile = "bonybream.txt"\n', 1, "model as one of boids, pso"),
    ('frames = 1000000000\n[[species]]\nfile = "a.txt"\n', 1, "frames as a whole number from 2 to 100000"),
    ('[[species]]\nfile = "a.txt"\ncount = 1000000000\n', 3, "count as a whole number from 1 to 100000"),
    ('[[species]]\nfile = "a.txt"\n[[species]]\nfile = "b.txt"\ncount = -1\n', 5, "count as a whole number"),
    ('[[species]]\nfile = "a.txt"\nspeed = nan\n', 3, "speed as a number from 0.05 to 20"),
    ('bounds = [[0, 0, 0], [0, 1, 1]]\n[[species]]\nfile = "a.txt"\n', 1, "max corner exceeds the min"),
    ('fish = 3\n', 1, "one of bounds, fps, frames"),
    ('[[species]]\nfile = "a.txt"\n[target]\npath = "zigzag.csv"\n', 4, "an existing CSV file"),
    ('[[species]]\nfile = "a.txt"\n[pso]\ninertia = "high"\n', 4, "inertia as a number"),
    ('[[species]\nfile = "a.txt"\n', 1, "expected TOML"),
    ('model = "boids"\n', None, "one or more [[species]] tables"),
])
def test_bad_scene_files_are_one_line_errors(tmp_path, text, line, message):
    path = tmp_path / "scene.toml"
    path.write_text(text)
    with pytest.raises(FishgenError) as info:
        load_scene_file(path)
    assert message in str(info.value) and info.value.line == line, str(info.value)
    assert "\n" not in str(info.value)


def test_fish_times_frames_are_refused_before_anything_is_built(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text('frames = 100000\n[[species]]\nfile = "a.txt"\ncount = 100000\n')
    with pytest.raises(FishgenError, match="at most 100,000 fish and 200,000,000 fish x frames"):
        load_scene_file(path)


def test_a_csv_target_path(tmp_path):
    (tmp_path / "path.csv").write_text("t,x,y,z\n0,0,0,0\n5,1,0,0\n10,1,0,1\n")
    path = tmp_path / "scene.toml"
    path.write_text('model = "pso"\n[[species]]\nfile = "a.txt"\n[target]\npath = "path.csv"\n')
    scene = load_scene_file(path)
    assert scene.target.kind == "points" and scene.target.points[-1] == (10.0, 1.0, 0.0, 1.0)
    (tmp_path / "path.csv").write_text("0,0,0,0\n0,1,0,0\n")
    with pytest.raises(FishgenError, match=r"path.csv:2: expected increasing times"):
        load_scene_file(path)
