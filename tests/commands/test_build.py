"""`fishgen build`'s use case: its summary line, and options refused together before any work."""
from __future__ import annotations

from pathlib import Path

from fishgen.assembly.fish import fish_of
from fishgen.commands.build import BuildOptions, summary
from fishgen.species.parser import load_species
from tests.conftest import PARAMS


def test_the_summary_counts_side_files_in_words():
    fish = fish_of(load_species(PARAMS / "bonybream.txt"), BuildOptions())
    one = summary(fish, Path("x.usda"), [Path("x.usda"), Path("x_skin.png")])
    two = summary(fish, Path("x.usda"), [Path("x.usda"), Path("x_skin.png"), Path("x_skin_mask.png")])
    assert one.endswith(" (+1 file)") and two.endswith(" (+2 files)")  # said "(+1 files)"
