"""`fishgen species --random`: one species or a folder of them, deterministic, buildable."""
from __future__ import annotations

import pytest

from tests.conftest import assert_valid_gltf


def test_one_random_species_builds_clean(tmp_path, cli):
    r = cli("species", "--random", "--seed", "7", "-o", tmp_path / "fish7.txt")
    assert r.returncode == 0, r.stderr
    for name in ("fish7.txt", "fish7.png", "fish7_mask.png"):
        assert (tmp_path / name).is_file()
    b = cli("build", tmp_path / "fish7.txt", "-o", tmp_path / "fish7.glb")
    assert b.returncode == 0, b.stderr
    assert_valid_gltf(tmp_path / "fish7.glb")


def test_same_seed_same_files(tmp_path, cli):
    for folder in ("a", "b"):
        assert cli("species", "--random", "--seed", "3", "-o", tmp_path / folder / "f.txt").returncode == 0
    for name in ("f.txt", "f.png", "f_mask.png"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


def test_count_writes_a_folder(tmp_path, cli):
    r = cli("species", "--random", "--seed", "10", "--count", "3", "-o", f"{tmp_path}/reef/")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in (tmp_path / "reef").glob("*.txt")) == \
        ["species_10.txt", "species_11.txt", "species_12.txt"]


def test_several_species_need_a_folder_not_a_file_name(tmp_path, cli):
    """Issue 19: `--count 2 -o out/sp2.txt` made a folder named sp2.txt."""
    r = cli("species", "--random", "--count", "2", "-o", tmp_path / "sp2.txt")
    assert r.returncode == 2 and "expected a folder for --count 2" in r.stderr
    assert list(tmp_path.iterdir()) == []


def test_mistakes_are_one_line(tmp_path, cli):
    r = cli("species", "--seed", "1", "-o", tmp_path / "x.txt")
    assert r.returncode == 2 and "--random" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    r = cli("species", "--random", "-o", tmp_path / "x.glb")
    assert r.returncode == 2 and "species file (.txt)" in r.stderr
    (tmp_path / "file").write_text("")
    r = cli("species", "--random", "--count", "2", "-o", tmp_path / "file")
    assert r.returncode == 2 and "expected a folder" in r.stderr


def test_a_count_running_past_the_last_seed_is_refused_not_wrapped(tmp_path, cli):
    """--seed 2^63-1 --count 2 wrote species_9223372036854775808.txt, a seed outside 0..2^63-1."""
    last = 2**63 - 1
    r = cli("species", "--random", "--seed", str(last), "--count", "2", "-o", f"{tmp_path}/s/")
    assert r.returncode == 2 and r.stderr == (
        f"fishgen species: expected seeds within 0..2^63-1 (--seed {last - 1} at most for --count 2), "
        f"found --seed {last} --count 2 reaching {last + 1}\n")
    assert not (tmp_path / "s").exists() or list((tmp_path / "s").iterdir()) == []
    ok = cli("species", "--random", "--seed", str(last - 1), "--count", "2", "-o", f"{tmp_path}/t/")
    assert ok.returncode == 0 and (tmp_path / "t" / f"species_{last}.txt").is_file(), ok.stderr


def test_o_names_the_species_file_exactly_and_its_textures_beside_it(tmp_path, cli):
    """QA: `-o "out/my fish.txt"` wrote out/my_fish.txt, `-o out/ünï🐟.txt` out/n.txt."""
    for name in ("Ab-c.d.txt", "ünï🐟.txt"):
        r = cli("species", "--random", "-o", tmp_path / name)
        assert r.returncode == 0 and r.stderr == "", r.stderr
        stem = name[:-4]
        assert {p.name for p in tmp_path.glob(f"{stem}*")} == {name, f"{stem}.png", f"{stem}_mask.png"}
    r = cli("species", "--random", "-o", tmp_path / "sp" / "my fish.txt")
    assert r.returncode == 0, r.stderr
    assert r.stderr.count("\n") == 1 and "my_fish.png" in r.stderr   # a note says so, in one line
    assert sorted(p.name for p in (tmp_path / "sp").iterdir()) == ["my fish.txt", "my_fish.png",
                                                                    "my_fish_mask.png"]
    b = cli("build", tmp_path / "sp" / "my fish.txt", "-o", tmp_path / "sp.glb")
    assert b.returncode == 0, b.stderr


def test_a_derived_texture_name_never_replaces_another_species_texture(tmp_path, cli):
    assert cli("species", "--random", "--seed", "1", "-o", tmp_path / "my_fish.txt").returncode == 0
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    r = cli("species", "--random", "--seed", "2", "-o", tmp_path / "my fish.txt")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "my_fish.png" in r.stderr
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


@pytest.mark.parametrize("written", ["shared.png", "./shared.png"])
def test_a_texture_another_species_file_names_under_any_name_is_never_replaced(tmp_path, cli, written):
    """y.txt names shared.png: `species -o shared.txt` replaced it and y.txt built another fish
    (QA pass 10). The documented pair's owner alone was looked up."""
    assert cli("species", "--random", "--seed", "7", "-o", tmp_path / "y.txt").returncode == 0
    (tmp_path / "y.png").rename(tmp_path / "shared.png")
    text = (tmp_path / "y.txt").read_text()
    assert text.count("y.png y_mask.png") == 1
    (tmp_path / "y.txt").write_text(text.replace("y.png y_mask.png", f"{written} y_mask.png"))
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    r = cli("species", "--random", "--seed", "8", "-o", tmp_path / "shared.txt")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "'shared.png', named by 'y.txt'" in r.stderr
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    # a rerun over its own textures is no such case
    assert cli("species", "--random", "--seed", "8", "-o", tmp_path / "z.txt").returncode == 0
    assert cli("species", "--random", "--seed", "9", "-o", tmp_path / "z.txt").returncode == 0


def test_an_interrupted_count_leaves_none_of_its_files(tmp_path):
    """QA: SIGTERM after minutes of `--count 10000` left ~17,900 files of a set promised whole."""
    import signal
    import subprocess
    import sys
    import time

    from tests.cli.test_interrupt import _wait_for_handlers
    from tests.conftest import ROOT

    out = tmp_path / "many"
    proc = subprocess.Popen([sys.executable, "-m", "fishgen", "species", "--random", "--count", "10000", "-o",
                             f"{out}/"], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_for_handlers(proc)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and proc.poll() is None and len(list(out.glob("*species_1?*"))) < 30:
        time.sleep(0.05)   # a partial set is there as whole files (before) or as temporary files
    assert proc.poll() is None, "the command ended before it could be interrupted"
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 143 and stderr == "fishgen: interrupted\n"
    assert list(tmp_path.iterdir()) == []   # no species, no temporary file, not even the folder
