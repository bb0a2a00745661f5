"""A progress-bar recorder for the use cases' Events: which bars a command opened and what it added."""
from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from fishgen.commands import Progress


class _Counter(Progress):
    def __init__(self, updates: list[int]):
        self.updates = updates

    def update(self, n: int) -> None:
        self.updates.append(n)

    def stage(self, label: str) -> None:
        self.updates.append(label)      # type: ignore[arg-type]  # in order among the counts


def recorded_bars() -> tuple[list[tuple[str, int, list[int]]], object]:
    """(bars, progress): pass ``progress`` as ``Events(progress=...)``; ``bars`` then holds each bar
    opened, as (label, total, every update and stage label in order)."""
    bars: list[tuple[str, int, list[int]]] = []

    @contextmanager
    def progress(label: str, total: int) -> Iterator[Progress]:
        bars.append((label, total, []))
        yield _Counter(bars[-1][2])

    return bars, progress
