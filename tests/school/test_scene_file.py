"""School scene files: every mistake is one FILE:LINE line; absurd sizes refused before allocating."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from fishgen.errors import FishgenError
from fishgen.school.model import COUZIN_PRESETS, Variety, couzin_params
from fishgen.school.scene_file import SceneFile, SpeciesEntry, load_scene_file, with_options
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
    ('fish = 3\n', 1, "one of bounds, couzin, fps, frames"),
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


@pytest.mark.parametrize("head,table,model", [("", '[couzin]\npreset = "torus"', "couzin"),
                                              ("", "[pso]\ninertia = 0.1", "pso"),
                                              ('model = "couzin"\n', '[couzin]\npreset = "swarm"', "couzin")])
def test_a_model_s_table_picks_its_model_when_the_file_names_none(tmp_path, head, table, model):
    """As --preset sets --model couzin: a [couzin] table alone ran boids, read and then ignored."""
    (tmp_path / "a.txt").write_text("")
    (tmp_path / "s.toml").write_text(f'{head}[[species]]\nfile = "a.txt"\n{table}\n')
    assert load_scene_file(tmp_path / "s.toml").model == model


_PICKS = r'model = "{}" \(or no model\) with a \[{}\] table, found '


@pytest.mark.parametrize("head,tables,message", [
    ('model = "boids"\n', '[couzin]\npreset = "torus"', _PICKS.format("couzin", "couzin") + "'boids'"),
    ('model = "couzin"\n', "[pso]\ninertia = 0.1", _PICKS.format("pso", "pso") + "'couzin'"),
    ("", '[pso]\ninertia = 0.1\n[couzin]\npreset = "swarm"',
     r"one model's table, \[pso\] or \[couzin\], found a \[pso\] and"),
])
def test_a_model_s_table_under_another_model_is_refused_at_its_header(tmp_path, head, tables, message):
    (tmp_path / "a.txt").write_text("")
    text = f'{head}[[species]]\nfile = "a.txt"\n{tables}\n'
    (tmp_path / "s.toml").write_text(text)
    with pytest.raises(FishgenError, match=message) as err:
        load_scene_file(tmp_path / "s.toml")
    header = "[couzin]" if "couzin]" in tables else "[pso]"
    assert err.value.line == text.splitlines().index(header) + 1


@pytest.mark.parametrize("table,override", [('[couzin]\npreset = "torus"', {"model": "boids"}),
                                            ("[pso]\ninertia = 0.1", {"preset": "torus"}),
                                            ("[pso]\ninertia = 0.1", {"model": "couzin"})])
def test_a_model_s_table_is_refused_when_the_command_line_picks_another_model(tmp_path, table, override):
    """`school s.toml --model boids` with a [couzin] table ran boids, the table ignored."""
    import shutil

    from fishgen.commands import command, run

    for name in ("bonybream.txt", "bonybream.png", "bonybream_mask.png"):
        shutil.copy(PARAMS.parent / ("params" if name.endswith(".txt") else "textures") / name, tmp_path)
    (tmp_path / "s.toml").write_text(f'[[species]]\nfile = "bonybream.txt"\ncount = 3\n{table}\n')
    school = command("school")
    name = table[1:table.index("]")]
    with pytest.raises(FishgenError, match=f"expected the {name} model with a \\[{name}\\] table, found the "
                                           "(boids|couzin) model from the command line") as err:
        run(school, (tmp_path / "s.toml",), tmp_path / "s.glb", school.options(frames=3, **override))
    assert err.value.line == 4 and not (tmp_path / "s.glb").exists()


def test_couzin_variety_warmup_and_length_keys_are_read_and_checked(tmp_path):
    (tmp_path / "a.txt").write_text("")
    scene = tmp_path / "ball.toml"
    scene.write_text('model = "couzin"\nwarmup = 2.5\nlength = 0.3\nbounds = [[-5, -2, -5], [5, 2, 5]]\n'
                     '[[species]]\nfile = "a.txt"\n[couzin]\npreset = "torus"\nrepulsion = 0.75\n'
                     'neighbours = 30\n[variety]\ntints = 3\nsize = 0\n')
    loaded = load_scene_file(scene)
    assert loaded.couzin == couzin_params("torus", repulsion=0.75, neighbours=30)
    assert loaded.variety == Variety(size=0.0, tints=3)
    assert (loaded.warmup, loaded.length) == (2.5, 0.3)
    assert loaded.bounds == ((-5.0, -2.0, -5.0), (5.0, 2.0, 5.0))
    for bad, expected in (('[couzin]\npreset = "mill"', "preset as one of swarm, torus"),
                          ("[couzin]\nneighbours = 2.5", "neighbours as a whole number"),
                          ("[variety]\ntints = 99", "tints as"),
                          ("[variety]\nhue = 1", r"one of size, tints, tint in \[variety\]")):
        scene.write_text(f'[[species]]\nfile = "a.txt"\n{bad}\n')
        with pytest.raises(FishgenError, match=expected) as err:
            load_scene_file(scene)
        assert err.value.line == 4


def test_options_override_the_scene_file_as_the_command_line_does():
    scene = SceneFile(species=(SpeciesEntry(Path("a.txt")), SpeciesEntry(Path("b.txt"))))
    changed = with_options(scene, speed=2.0, preset="swarm", variety={"tints": 4})
    assert [e.speed for e in changed.species] == [2.0, 2.0]
    assert changed.model == "couzin" and changed.couzin == COUZIN_PRESETS["swarm"]
    assert changed.variety == Variety(tints=4)
    assert with_options(scene, preset="torus", model="couzin").model == "couzin"


def test_the_torus_preset_starts_as_a_ring_unless_a_layout_is_given(tmp_path):
    """From a random ball in the default region the torus milled for 1 seed of 8 (docs/decisions.md):
    named as a preset (--preset or the scene file's [couzin] preset), it starts as a milling ring; a
    layout given (--layout or the scene file's `layout`) wins, and other presets start as a ball."""
    from fishgen.school.scene_file import start_layout

    bream = SceneFile(species=(SpeciesEntry(Path("a.txt")),))
    assert start_layout(bream) == "sphere"
    assert start_layout(with_options(bream, preset="torus")) == "ring"
    assert start_layout(with_options(bream, preset="torus", layout="sphere")) == "sphere"
    assert start_layout(with_options(bream, layout="line")) == "line"
    # the model's own zones are the torus's, named or not; other zones with no preset start as a ball
    assert start_layout(with_options(bream, model="couzin")) == "ring"
    assert start_layout(replace(bream, model="couzin", couzin=COUZIN_PRESETS["torus"])) == "ring"
    assert start_layout(replace(bream, model="couzin", couzin=COUZIN_PRESETS["swarm"])) == "sphere"
    assert {start_layout(with_options(bream, preset=p)) for p in COUZIN_PRESETS if p != "torus"} == {"sphere"}
    (tmp_path / "a.txt").write_text("")
    file = tmp_path / "s.toml"
    file.write_text('model = "couzin"\n[[species]]\nfile = "a.txt"\n'
                    '[couzin]\npreset = "torus"\nrepulsion = 0.75\n')
    torus = load_scene_file(file)
    assert torus.layout is None and start_layout(torus) == "ring"
    assert start_layout(with_options(torus, preset="swarm")) == "sphere"   # the command line's preset wins
    assert start_layout(with_options(torus, model="boids")) == "sphere"    # [couzin] is the couzin model's
    assert start_layout(with_options(torus, layout="box")) == "box"
    file.write_text('layout = "box"\nmodel = "couzin"\n[[species]]\nfile = "a.txt"\n'
                    '[couzin]\npreset = "torus"\n')
    assert start_layout(load_scene_file(file)) == "box"
    # the key is checked by the --layout option's declaration, at its line
    file.write_text('layout = "donut"\n[[species]]\nfile = "a.txt"\n')
    with pytest.raises(FishgenError, match=r"s.toml:1: expected layout as one of sphere, box, line, ring, "
                                           r"found 'donut'$"):
        load_scene_file(file)


def test_a_couzin_school_pre_rolls_twenty_of_the_papers_seconds_at_its_own_speed(tmp_path):
    """The paper's clock runs at its speed (3 body lengths/s) over the fish's: 20 of its seconds are
    60 s at 1 body length/s, 20 s at 3; the slowest species sets it. Other models start at once, and
    a scene file's `preroll` (or --preroll) wins."""
    from fishgen.errors import UsageError
    from fishgen.school.scene_file import check_size, preroll_seconds

    bream = SpeciesEntry(PARAMS / "bonybream.txt")
    couzin = SceneFile(species=(bream,), model="couzin")
    assert preroll_seconds(couzin) == 60.0
    assert preroll_seconds(with_options(couzin, speed=3.0)) == 20.0
    two = SceneFile(species=(bream, SpeciesEntry(bream.file, speed=2.0)), model="couzin")
    assert preroll_seconds(two) == 60.0
    assert preroll_seconds(SceneFile(species=(bream,))) == 0.0
    assert preroll_seconds(with_options(couzin, preroll=5.0)) == 5.0
    assert preroll_seconds(with_options(couzin, speed=0.05)) == 600.0          # at most MAX_PREROLL
    (tmp_path / "a.txt").write_text("")
    scene = tmp_path / "s.toml"
    scene.write_text('model = "couzin"\npreroll = 12.5\n[[species]]\nfile = "a.txt"\n')
    assert load_scene_file(scene).preroll == 12.5
    scene.write_text('model = "couzin"\n[[species]]\nfile = "a.txt"\n\npreroll = -1\n')
    with pytest.raises(FishgenError, match="preroll"):
        load_scene_file(scene)
    # a wrong value is shown as TOML writes it ('True', Python's spelling, before)
    scene.write_text('preroll = true\n[[species]]\nfile = "a.txt"\n')
    with pytest.raises(FishgenError, match=r"s.toml:1: expected preroll as a number from 0 to 600, "
                                           r"found 'true'$"):
        load_scene_file(scene)
    # the pre-roll's steps count towards the work refused before it starts
    big = with_options(couzin, count=1_000, frames=2, fps=1000.0, speed=0.1)    # 600 s at 1,000 frames/s
    check_size(with_options(big, preroll=0.0))
    with pytest.raises(UsageError, match="1,000 fish x 2 frames and 600,000 pre-roll steps"):
        check_size(big)



def test_every_scene_file_key_is_in_the_users_documentation():
    """The [couzin], [pso], [target] and [variety] keys were listed only in error messages."""
    from dataclasses import fields

    from fishgen.school.model import CouzinParams, PsoParams, Variety

    text = (PARAMS.parent / "docs" / "commands.md").read_text()
    section = text[text.index("**Scene-file keys.**"):text.index("**Outputs besides the glb:**")]
    keys = {f.name for record in (CouzinParams, PsoParams, Variety) for f in fields(record)}
    keys |= {"model", "frames", "fps", "seed", "bounds", "layout", "warmup", "preroll", "length", "file",
             "count", "speed", "preset", "path", "centre", "radius", "period"}
    assert not {key for key in keys if f"`{key}`" not in section}
