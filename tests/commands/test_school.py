"""fishgen.commands.school: what the use case tells a terminal while it works."""
from __future__ import annotations

from fishgen.commands import Events
from fishgen.commands.school import SchoolOptions, school
from tests.conftest import PARAMS
from tests.progress_bars import recorded_bars


def test_the_progress_bar_counts_each_step_once_pre_roll_included(tmp_path):
    """The bar's total is every step simulated, and each step adds one: the simulation used to
    hand the bar its running count, which a bar adds up, so it filled after a tenth of the run."""
    bars, progress = recorded_bars()
    options = SchoolOptions(count=6, frames=20, model="couzin", preroll=1.0)
    school([PARAMS / "bonybream.txt"], tmp_path / "s.glb", options, Events(progress=progress))
    # 30 pre-roll steps and 20 frames, then the bake and the files, a frame's weight each
    assert bars == [("simulating", 50 + 2 * 20, [1] * 50 + ["baking", 20, "writing", 20])]
