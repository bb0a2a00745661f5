"""Scene files and path CSVs that a fuzzer made (issue 26): one line at the place, never a traceback."""
from __future__ import annotations

import pytest

from fishgen.errors import FishgenError
from fishgen.school.scene_file import load_scene_file


@pytest.mark.parametrize("row", ["1,1e308,0,0", "1,0,-2e4,0", "1e300,0,0,0"])
def test_path_points_are_bounded_as_a_scenes_bounds_are(tmp_path, row):
    """Fault 11: a target path at 1e308 overflowed the neighbour search (a traceback) or wrote
    Infinity into the metrics."""
    (tmp_path / "p.csv").write_text(f"t,x,y,z\n0,0,0,0\n{row}\n")
    scene = tmp_path / "s.toml"
    scene.write_text('model = "pso"\n[[species]]\nfile = "a.txt"\n[target]\npath = "p.csv"\n')
    with pytest.raises(FishgenError) as caught:
        load_scene_file(scene)
    assert caught.value.file == str(tmp_path / "p.csv") and caught.value.line == 3
    assert "x,y,z within 10000 m" in caught.value.message


def test_the_csv_a_scene_reads_is_among_what_it_read(tmp_path):
    (tmp_path / "p.csv").write_text("t,x,y,z\n0,0,0,0\n1,1,0,0\n")
    scene = tmp_path / "s.toml"
    scene.write_text('model = "pso"\n[[species]]\nfile = "a.txt"\n[predator]\npath = "p.csv"\n')
    assert load_scene_file(scene).read == (tmp_path / "p.csv",)
