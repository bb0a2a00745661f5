"""`fishgen build`'s use case: its summary line, and options refused together before any work."""
from __future__ import annotations

from pathlib import Path

import pytest

from fishgen.assembly.fish import fish_of
from fishgen.commands.build import BuildOptions, summary
from fishgen.errors import UsageError
from fishgen.species.parser import load_species
from tests.conftest import PARAMS


def test_the_summary_counts_side_files_in_words():
    fish = fish_of(load_species(PARAMS / "bonybream.txt"), BuildOptions())
    one = summary(fish, Path("x.usda"), [Path("x.usda"), Path("x_skin.png")])
    two = summary(fish, Path("x.usda"), [Path("x.usda"), Path("x_skin.png"), Path("x_skin_mask.png")])
    assert one.endswith(" (+1 file)") and two.endswith(" (+2 files)")  # said "(+1 files)"


def _build(tmp_path, output, **options):
    from fishgen.commands.build import build

    return build([PARAMS / "bonybream.txt"], output, BuildOptions(**options))


@pytest.mark.parametrize("output, options, message", [
    # --speed sets the body wave; a rigid body swims the same at any speed (the files were identical)
    ("x.glb", {"swim": "fins", "speed": 3.0}, "expected --swim body with --speed"),
    # --format is the format inside a folder: -o x.glb --format obj wrote a glb without a word
    ("x.glb", {"format": "obj"}, "expected --format with -o naming a folder, or a file of that format"),
])
def test_an_option_that_would_be_ignored_is_refused_before_any_work(tmp_path, output, options, message):
    with pytest.raises(UsageError, match=message):
        _build(tmp_path, tmp_path / output, **options)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("output, options", [
    ("x.glb", {"swim": "fins"}),                 # --speed's default is no --speed
    ("x.obj", {"format": "obj"}),                # the file's extension says the same
    ("folder/", {"format": "obj"}),
])
def test_an_option_that_applies_is_taken(tmp_path, output, options):
    made = _build(tmp_path, f"{tmp_path}/{output}", **options)
    assert made.written and not made.failed


def test_the_summary_says_when_the_tail_beat_cap_binds():
    species = load_species(PARAMS / "bonybream.txt")
    fast = summary(fish_of(species, BuildOptions(speed=7.0)), Path("x.glb"), [Path("x.glb")])
    cruising = summary(fish_of(species, BuildOptions()), Path("x.glb"), [Path("x.glb")])
    assert "body wave 7.81 Hz (--speed 7 capped at 8 Hz)" in fast      # was 8.12 Hz, said nothing
    assert "body wave 1.56 Hz" in cruising and "capped" not in cruising


def test_the_speed_help_states_the_cap():
    from fishgen.commands.build import COMMAND
    from fishgen.options import declared

    speed = next(spec for f, spec in declared(COMMAND.options) if f.name == "speed")
    assert "at most 8 Hz (from 5.33 BL/s up" in speed.help


@pytest.mark.parametrize("fins, said", [
    (("anal_fin",), "; no anal fin"), (("pectoral_fin_left", "pectoral_fin_right"), "; no pectoral fins"),
    (("adipose_fin", "anal_fin"), "; no adipose or anal fins"),
    (("dorsal_fin", "adipose_fin", "anal_fin"), "; no dorsal, adipose or anal fins"), ((), "")])
def test_a_levels_lost_fins_are_said_as_a_sentence_says_them(fins, said):
    from fishgen.commands.build import _lost

    assert _lost(fins) == said
