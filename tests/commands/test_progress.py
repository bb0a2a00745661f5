"""Long work shows a bar on a terminal: what each command counts, and that a note does not land
on the bar's line (the school's and the preview's bars are tested with them)."""
from __future__ import annotations

import pytest

from fishgen.commands import Events
from fishgen.commands.build import build
from fishgen.commands.species import SpeciesOptions, species
from tests.conftest import PARAMS
from tests.progress_bars import recorded_bars


def test_species_counts_each_species_written(tmp_path):
    """`species --count 2000` takes about a minute: one step a species."""
    bars, progress = recorded_bars()
    made = species([], f"{tmp_path}/out/", SpeciesOptions(random=True, seed=3, count=3),
                   Events(progress=progress))
    assert bars == [("sampling", 3, [1, 1, 1])] and len(made.written) == 3


def test_one_species_draws_no_bar(tmp_path):
    bars, progress = recorded_bars()
    species([], tmp_path / "one.txt", SpeciesOptions(random=True), Events(progress=progress))
    assert [(label, total) for label, total, _ in bars] == [("sampling", 0)]   # a total of 0 draws nothing


def test_build_counts_each_input_the_bad_ones_too(tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("not a species\n")
    failed: list = []
    bars, progress = recorded_bars()
    made = build([PARAMS / "bonybream.txt", bad, PARAMS / "centroberyx.txt"], f"{tmp_path}/out/",
                 events=Events(progress=progress, failed=failed.append))
    assert bars == [("building", 3, [1, 1, 1])]
    assert len(failed) == 1 and len(made.lines) == 2


class _DrawnBar:
    """A bar as click draws one: it skips a redraw of the line it drew last."""

    def __init__(self) -> None:
        self._last_line: str | None = "[###---]"
        self.drawn = 0

    def render_progress(self) -> None:
        if self._last_line != "[###---]":
            self._last_line = "[###---]"
            self.drawn += 1


def test_a_note_during_a_bar_takes_the_bar_s_line_and_the_bar_is_drawn_again_below(capsys):
    """No half-drawn bar before the note, and no blank line when the bar ends (its line is the
    bar's, ended by click)."""
    from fishgen.cli.adapter import TerminalEvents
    from fishgen.errors import FishgenError

    events = TerminalEvents("texture")
    events.note("before")
    bar = _DrawnBar()
    events.bars.append(bar)          # as while a bar is drawn
    events.note("during")
    events.failed(FishgenError("expected a fish, found none", "p.png"))
    err = capsys.readouterr().err
    assert err.startswith("before\n\r\x1b[Kduring\n\r\x1b[Kp.png: ") and err.count("\n") == 3
    assert bar.drawn == 2


def test_click_s_own_bar_is_drawn_again_at_once_below_a_note(monkeypatch):
    """With click's progress bar itself (the redraw clears what click remembers it drew last)."""
    _a_person_watches(monkeypatch)
    import io
    import sys

    from fishgen.cli.adapter import TerminalEvents

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    err = Terminal()
    monkeypatch.setattr(sys, "stderr", err)
    events = TerminalEvents("texture")
    with events.progress("fitting", 4) as bar:
        bar.update(1)
        events.note("hello")
        assert "fitting" in err.getvalue().split("hello\n", 1)[1]     # before the next step
        bar.update(3)
    assert "\n\n" not in err.getvalue() and err.getvalue().count("hello") == 1


class _Terminal:
    """stderr as a terminal of ``columns`` columns."""

    def __init__(self, columns: int = 80):
        import io

        self.text = io.StringIO()
        self.columns = columns

    def isatty(self) -> bool:
        return True

    def fileno(self) -> int:
        return 2

    def write(self, text: str) -> int:
        return self.text.write(text)

    def flush(self) -> None:
        pass


def _a_person_watches(monkeypatch, columns: int = 80) -> _Terminal:
    import os
    import sys

    terminal = _Terminal(columns)
    monkeypatch.setattr(sys, "stderr", terminal)
    monkeypatch.setattr(os, "get_terminal_size", lambda fd=1: os.terminal_size((columns, 24)))
    monkeypatch.delenv("CI", raising=False)
    monkeypatch.setenv("TERM", "xterm")
    return terminal


def _drawn(terminal: _Terminal, label: str = "simulating", total: int = 50) -> list[str]:
    """Every line the bar drew, its redraws apart (each starts with a carriage return)."""
    import re

    from fishgen.cli.adapter import TerminalEvents

    with TerminalEvents("school").progress(label, total) as bar:
        for _ in range(total):
            bar.update(1)
    text = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", terminal.text.getvalue())   # cursor hiding
    return [line for line in re.split(r"[\r\n]", text) if line.strip()]


@pytest.mark.parametrize("columns", [40, 60, 80, 200])
def test_the_bar_s_line_fits_the_terminal_so_each_step_redraws_it_in_place(monkeypatch, columns):
    """A bar 36 wide made a line of 56-66 columns: on a narrower terminal every redraw wrapped onto
    a new row (124 rows of a 40-column terminal for one school, QA pass 21)."""
    lines = _drawn(_a_person_watches(monkeypatch, columns))
    assert lines and all(len(line) < columns for line in lines)
    assert "100%" in lines[-1]


def test_no_bar_where_even_a_short_one_would_not_fit(monkeypatch):
    assert _drawn(_a_person_watches(monkeypatch, 20)) == []


def test_a_terminal_of_no_known_width_is_taken_as_80_columns(monkeypatch):
    """A pseudo-terminal that no one sized (`script` run from a pipe) says 0 columns."""
    lines = _drawn(_a_person_watches(monkeypatch, 0))
    assert lines and all(len(line) < 80 for line in lines)


@pytest.mark.parametrize("variable, value", [("CI", "true"), ("CI", "1"), ("TERM", "dumb")])
def test_no_bar_in_ci_or_on_a_terminal_that_cannot_redraw_a_line(monkeypatch, variable, value):
    """Some CI runners give their jobs a pseudo-terminal; a dumb terminal cannot move its cursor."""
    terminal = _a_person_watches(monkeypatch)
    monkeypatch.setenv(variable, value)
    assert _drawn(terminal) == [] and terminal.text.getvalue() == ""


def test_a_bar_when_ci_is_set_to_false(monkeypatch):
    terminal = _a_person_watches(monkeypatch)
    monkeypatch.setenv("CI", "false")
    assert _drawn(terminal)


@pytest.mark.parametrize("columns", [50, 60, 80])
def test_the_line_fits_with_an_eta_of_days_too(monkeypatch, columns):
    """click writes an ETA of a day or more as "1d 00:00:00", 3-4 columns past "00:00:00" (a review)."""
    import click

    from fishgen.cli.adapter import _bar_width

    _a_person_watches(monkeypatch, columns)
    for label in ("simulating", "building the sky"):
        bar = click.progressbar(length=10_000, label=label, width=_bar_width(label), show_eta=True)
        bar.pos, bar.eta_known = 1, True
        monkeypatch.setattr(type(bar), "format_eta", lambda self: "10d 00:00:00")
        assert len(bar.format_progress_line()) < columns


def test_a_command_that_fails_under_its_bar_leaves_no_bar_above_its_error(monkeypatch):
    """A refusal found once the bar was up left "[----] 0%" on the line above the error (a review)."""
    from fishgen.cli.adapter import TerminalEvents
    from fishgen.errors import UsageError

    terminal = _a_person_watches(monkeypatch)
    with pytest.raises(UsageError):
        with TerminalEvents("clouds").progress("filling and lighting", 10) as bar:
            bar.update(3)
            raise UsageError("expected at most 1,000 particles")
    text = terminal.text.getvalue()
    assert text.endswith("\r\x1b[K\x1b[?25h") and "\n" not in text       # erased, cursor shown again
