"""fishgen.commands.school: what the use case tells a terminal while it works."""
from __future__ import annotations

from contextlib import contextmanager

from fishgen.commands import Events, Progress
from fishgen.commands.school import SchoolOptions, school
from tests.conftest import PARAMS


def test_the_progress_bar_counts_each_step_once_pre_roll_included(tmp_path):
    """The bar's total is every step simulated, and each step adds one: the simulation used to
    hand the bar its running count, which a bar adds up, so it filled after a tenth of the run."""
    bars: list[tuple[str, int, list[int]]] = []

    class Counter(Progress):
        def __init__(self, updates: list[int]):
            self.updates = updates

        def update(self, n: int) -> None:
            self.updates.append(n)

    @contextmanager
    def progress(label: str, total: int):
        bars.append((label, total, []))
        yield Counter(bars[-1][2])

    options = SchoolOptions(count=6, frames=20, model="couzin", preroll=1.0)
    school([PARAMS / "bonybream.txt"], tmp_path / "s.glb", options, Events(progress=progress))
    assert bars == [("simulating", 50, [1] * 50)]                  # 30 pre-roll steps and 20 frames
