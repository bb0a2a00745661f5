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


@pytest.mark.parametrize("name", ["/etc/passwd", "../elsewhere/a.txt", "link.txt"])
def test_a_scene_file_reads_only_files_in_its_own_folder(tmp_path, name):
    """Issue 26: a scene file named species anywhere, and the error echoed the first line of
    whatever it named (/etc/passwd)."""
    import os

    (tmp_path / "outside").mkdir()
    (tmp_path / "outside" / "secret.txt").write_text("hunter2:x:0:0:hunter2:/home:/bin/bash\n")
    folder = tmp_path / "scene"
    folder.mkdir()
    os.symlink(tmp_path / "outside" / "secret.txt", folder / "link.txt")
    scene = folder / "s.toml"
    scene.write_text(f'frames = 10\n[[species]]\ncount = 3\nfile = "{name}"\n')
    with pytest.raises(FishgenError) as caught:
        load_scene_file(scene)
    assert caught.value.file == str(scene) and caught.value.line == 4
    assert "inside the scene file's folder" in caught.value.message and "hunter2" not in str(caught.value)


def test_a_file_that_is_not_a_species_file_is_not_echoed(tmp_path):
    from fishgen.species.parser import load_species

    (tmp_path / "secret.txt").write_text("hunter2:x:0:0:hunter2:/home:/bin/bash\ndaemon:x:1:1\n")
    with pytest.raises(FishgenError) as caught:
        load_species(tmp_path / "secret.txt")
    assert "hunter2" not in str(caught.value) and "not one" in str(caught.value)


def test_a_scene_holds_at_most_64_species_tables_each_building_its_own_fish(tmp_path):
    """QA pass 12: 1,000 one-fish tables of one file took 126 s and 96 MB of glb where one table of
    1,000 fish took 2.5 s and 2.5 MB; 40,000 of them (a 920 KB scene) ran past 1.7 GB. Refused at
    the first table too many, before any fish is built."""
    from fishgen.school.scene_file import MAX_SPECIES

    scene = tmp_path / "s.toml"
    table = '[[species]]\nfile = "bonybream.txt"\ncount = 1\n'
    scene.write_text("frames = 2\n" + table * MAX_SPECIES)
    assert len(load_scene_file(scene).species) == MAX_SPECIES
    scene.write_text("frames = 2\n" + table * 1000)
    with pytest.raises(FishgenError) as caught:
        load_scene_file(scene)
    assert caught.value.line == 2 + 3 * MAX_SPECIES + 1   # the 65th table's file key
    assert caught.value.message == ("expected at most 64 [[species]] tables (each builds its own fish; one "
                                    "table's count gives a species many fish), found 1,000")
