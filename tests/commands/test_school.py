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


def test_a_library_callers_bar_without_stages_is_only_counted(tmp_path):
    """A caller's own counter with ``update`` alone (tqdm's has no stages): the school named its
    stages on it and ended in an AttributeError at the bake (a QA pass left it; fixed since)."""
    from contextlib import contextmanager

    class Plain:
        def __init__(self) -> None:
            self.n = 0

        def update(self, n: int) -> None:
            self.n += n

    plain = Plain()

    @contextmanager
    def progress(label, total):
        yield plain

    options = SchoolOptions(count=6, frames=20, model="couzin", preroll=1.0)
    made = school([PARAMS / "bonybream.txt"], tmp_path / "s.glb", options, Events(progress=progress))
    assert plain.n == 50 + 2 * 20 and made.written
