"""`fishgen build --lods/--merge/--clips/--compact`: checked by their declarations before any work,
and the issue's command line gives one valid file that says what it holds."""
from __future__ import annotations

import click
import pytest

from fishgen.options import Lods, Names
from tests.conftest import PARAMS, assert_valid_gltf, run_cli


@pytest.mark.parametrize("text,levels", [("32x24,16x12,8x6", ((32, 24), (16, 12), (8, 6))),
                                         ("12X8", ((12, 8),)),
                                         (" 24 x 16 , 8x6 ", ((24, 16), (8, 6)))])
def test_levels_parse_finest_first(text, levels):
    assert Lods().convert(text, None, None) == levels


@pytest.mark.parametrize("text", ["8x6,16x12", "16x12,16x12", "2x6", "16x12,", "sixteen", "9" * 6 + "x6",
                                  ",".join(["64x48"] + [f"{40 - k}x6" for k in range(8)])])
def test_bad_levels_are_refused_in_one_line(text):
    with pytest.raises(click.BadParameter, match="finest to coarsest"):
        Lods().convert(text, None, None)


def test_clip_names_are_checked():
    names = Names(("swim", "idle"))
    assert names.convert("idle,swim", None, None) == ("idle", "swim")
    for bad in ("swim,swim", "glide", ""):
        with pytest.raises(click.BadParameter, match="names from swim, idle"):
            names.convert(bad, None, None)


def test_the_issues_command_line(tmp_path):
    out = tmp_path / "fish.glb"
    run = run_cli("build", PARAMS / "bonybream.txt", "--lods", "32x24,16x12,8x6", "--merge",
                  "--clips", "swim,idle,turn_left,turn_right,burst", "-o", out)
    assert run.returncode == 0, run.stderr
    assert ("levels 32x24 (1518), 16x12 (376), 8x6 (92; no adipose or anal fins)" in run.stdout
            and "merged (2 draw calls)" in run.stdout)
    assert "clips idle 2.00 s, turn_left 3.20 s, turn_right 3.20 s, burst 0.60 s" in run.stdout
    assert_valid_gltf(out)


@pytest.mark.parametrize("args,words", [(["--lods", "8x6,16x12"], "Invalid value for '--lods'"),
                                        (["--clips", "swim,dance"], "Invalid value for '--clips'"),
                                        (["--swim", "fins", "--clips", "swim,burst"],
                                         "a rigid body cannot bend")])
def test_bad_engine_options_are_one_line_and_write_nothing(tmp_path, args, words):
    out = tmp_path / "fish.glb"
    run = run_cli("build", PARAMS / "bonybream.txt", *args, "-o", out)
    assert run.returncode == 2 and words in run.stderr and len(run.stderr.strip().splitlines()) == 1
    assert not out.exists()


def test_a_manifest_sets_them_too(tmp_path):
    from fishgen.batch import run_batch
    from fishgen.batch.manifest import load_manifest
    from fishgen.commands.batch import job_kinds, run_job

    manifest = tmp_path / "assets.toml"
    manifest.write_text(f'[[build]]\ninput = "{PARAMS / "bonybream.txt"}"\noutput = "fish.glb"\n'
                        'lods = "16x12,8x6"\nmerge = true\nclips = "swim,burst"\ncompact = true\n')
    outcomes = run_batch(load_manifest(manifest, tmp_path / "out", kinds=job_kinds()), run_job, workers=1)
    assert [o.status for o in outcomes] == ["built"]
    assert_valid_gltf(tmp_path / "out" / "fish.glb")


def test_python_meets_the_cap_on_sections_the_command_line_meets(tmp_path):
    """1024x1024 is 16 times the 65,536 points a level may have (1000x1000 took 14 s and 1 GB): refused
    by the one declaration, from Python as on the command line, before any work, in the same words."""
    from fishgen.assembly.fish import make_fish
    from fishgen.errors import FishgenError
    from fishgen.species.parser import load_species

    run = run_cli("build", PARAMS / "bonybream.txt", "--lods", "1024x1024", "-o", tmp_path / "x.glb")
    assert run.returncode == 2 and not (tmp_path / "x.glb").exists()
    with pytest.raises(FishgenError) as caught:
        make_fish(load_species(PARAMS / "bonybream.txt"), lods=[(1024, 1024)])
    message = str(caught.value)
    assert message.startswith("Invalid value for '--lods': ")
    assert message.endswith("at most 65,536, found '1024x1024'")
    assert message in run.stderr


def test_the_build_options_check_each_value_by_its_declaration():
    from fishgen.assembly.fish_options import FishOptions
    from fishgen.commands.build import BuildOptions
    from fishgen.errors import FishgenError

    made = FishOptions(lods=[[32, 24], (8, 6)], clips=["idle", "swim"], fps=60)   # as Python may give them
    assert made.lods == ((32, 24), (8, 6)) and made.clips == ("idle", "swim") and made.fps == 60.0
    assert BuildOptions(fps=24).fps == 24.0 and isinstance(BuildOptions(), FishOptions)
    for bad, words in (({"fps": 0}, "'--fps'"), ({"speed": 1e9}, "'--speed'"),
                       ({"length": -1}, "'--length'"),
                       ({"fins": "glass"}, "'--fins'"), ({"swim": "crawl"}, "'--swim'"),
                       ({"lods": [(16, 12), (16, 12)]}, "finest to coarsest"),
                       ({"lods": [(16,)]}, "'--lods'"),
                       ({"lods": [(9, 8)] * 9}, "at most 8"), ({"clips": ("swim", "swim")}, "'--clips'"),
                       ({"merge": "yes"}, "'--merge': expected true or false"),
                       ({"swim": "fins", "clips": ("burst",)}, "--swim body")):
        with pytest.raises(FishgenError, match=words):
            FishOptions(**bad)
        with pytest.raises(FishgenError, match=words):
            BuildOptions(**bad)
