"""A command's declaration (:class:`fishgen.commands.Command`) as a click command.

Nothing here knows what a command does: its arguments, ``-o`` and options come from the
declaration, its work from the use-case function, and this module only turns the function's
:class:`~fishgen.commands.Made` and events into what a person at a terminal sees.
"""
from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager, nullcontext
from pathlib import Path
from typing import Any

import click

from fishgen.cli.common import QUIET, VERBOSE, error_line, error_text, json_errors, note_line, say, verbosity
from fishgen.commands import Command, Events, Progress
from fishgen.options import click_params, from_values


class InputPath(click.Path):
    """An input's path, never empty: ``Path("")`` is the working folder, and `batch ""` (a script's
    unset variable) had batched everything under it."""

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        if isinstance(value, str) and not value:
            self.fail("expected a path, found an empty one", param, ctx)
        return super().convert(value, param, ctx)


def click_command(cmd: Command) -> click.Command:
    """The click command of ``cmd``: its inputs, ``-o``, and every declared option with its default."""
    params: list[click.Parameter] = []
    if cmd.inputs is not None:
        kind = InputPath(path_type=Path) if cmd.inputs.path else None
        params.append(click.Argument(["inputs"], nargs=-1 if cmd.inputs.many else 1,
                                     required=cmd.inputs.required, type=kind, metavar=cmd.inputs.metavar))
    if cmd.output is not None:
        shown = f"  [default: {cmd.output.shown_default}]" if cmd.output.shown_default else ""
        # a str, not a Path: `-o out/` keeps the slash that makes it a folder
        # no default when required: click 8.3 takes an explicit default=None as a value given
        default: dict[str, Any] = {} if cmd.output.required else {"default": None}
        params.append(click.Option(["-o", "--output"], type=click.Path(), required=cmd.output.required,
                                   metavar=cmd.output.metavar, help=cmd.output.help + shown, **default))
    params += click_params(cmd.options)

    def callback(inputs: Any = (), output: str | None = None, **values: Any) -> None:
        given = tuple(inputs) if cmd.inputs is not None and cmd.inputs.many else (inputs,) if inputs else ()
        execute(cmd, given, output, from_values(cmd.options, values))

    return click.Command(cmd.name, params=params, callback=callback, help=cmd.help, short_help=cmd.summary,
                         context_settings={"help_option_names": ["-h", "--help"]})


def execute(cmd: Command, inputs: tuple[Path, ...], output: str | None, options: Any) -> None:
    """Run the command's function and show what it made: the summary on stdout, notes and each
    failed input on stderr, a bar on a terminal; serve its server until Ctrl-C."""
    from fishgen.atomic import together
    from fishgen.commands import run

    events = TerminalEvents(cmd.name)
    # A summary that cannot be printed (stdout on a full disk) fails the run: with `together`, its
    # files are still staged then, and none lands. A reader that has gone (`| head -1`) fails nothing.
    with together() if cmd.together else nullcontext(), _warnings_as_notes(events):
        made = run(cmd, inputs, output, options, events.as_events())
        say(made.lines)
    if made.server is not None and verbosity() <= QUIET and sys.__stdout__ is not None:
        # --quiet drops the summary, not the address: without it and its token the page cannot be
        # opened (QA pass 15: `edit -q` served on a random port and said nothing)
        from contextlib import redirect_stdout

        with redirect_stdout(sys.__stdout__):
            say([line for line in made.lines if made.server.token in line])
    if made.verdict is not None:
        raise made.verdict
    if made.failed:
        raise SystemExit(max(err.status for err in made.failed))
    if made.server is not None:
        sys.stdout.flush()
        try:
            made.server.serve_forever()
        except KeyboardInterrupt:
            pass
        finally:
            made.server.server_close()


@contextmanager
def _warnings_as_notes(events: TerminalEvents) -> Iterator[None]:
    """A cube file's warning (``CubeFileWarning``, already ``FILE:LINE: warning: …``) said as a
    note, in one line, by whichever command read the file: Python's own form added the warning's
    class and the line of fishgen's source that raised it (sky, preview, fly)."""
    import warnings

    from fishgen.clouds.parser import CubeFileWarning
    from fishgen.reading import unheeded

    with warnings.catch_warnings():
        shown = warnings.showwarning

        def show(message, category, filename, lineno, file=None, line=None):
            if unheeded(category, filename):
                return
            # under --json every line on stderr is an object: any warning, said as a batch job says it
            if issubclass(category, CubeFileWarning) or json_errors():
                events.note(str(message))
            else:
                shown(message, category, filename, lineno, file, line)

        warnings.showwarning = show
        yield


class TerminalEvents:
    """Notes and failures on stderr; a progress bar when a person watches (stderr is a terminal and
    not --quiet), else one plain line per step on stdout, with the reason under --verbose."""

    def __init__(self, command: str = "") -> None:
        self.bars: list[Any] = []     # the bars drawn, innermost last
        self.command = command

    def as_events(self) -> Events:
        return Events(note=self.note, failed=self.failed,
                      progress=self.progress,
                      line=self.line)

    def note(self, text: str) -> None:
        self._above_bar(note_line(text))

    def _above_bar(self, text: str) -> None:
        """``text`` on stderr; while a bar is drawn, in the bar's place, and the bar again below it
        (as tqdm's write): no line of the bar left half drawn, no blank line when it ends."""
        if self.bars:
            sys.stderr.write("\r\x1b[K")
        say([text], err=True)
        if self.bars:
            bar = self.bars[-1]
            bar._last_line = None       # click skips drawing the line it drew last: it was cleared
            bar.render_progress()

    def failed(self, err: Any) -> None:
        message = error_text(err, self.command)    # as the error that stops a command reads
        detail = getattr(err, "detail", "")
        self._above_bar(error_line(message, err.status, file=err.file, line=err.line, kind=err.kind,
                                   **({"job": err.job} if err.job else {}))
                        + (f"\n{detail}" if detail and verbosity() >= VERBOSE else ""))

    def line(self, text: str, detail: str | None) -> None:
        if self.bars or verbosity() <= QUIET:
            return
        say([text + (f": {detail}" if detail and verbosity() >= VERBOSE else "")])

    @contextmanager
    def progress(self, label: str, total: int) -> Iterator[Progress]:
        width = _bar_width(label) if watched() and total > 0 else None
        if width is None:
            yield Progress()
            return
        bar = click.progressbar(length=total, label=label, file=sys.stderr, width=width)
        self.bars.append(bar)
        try:
            bar.__enter__()
            try:
                yield _Bar(bar)
            except BaseException:
                # the error's one line takes the bar's place: a refusal found once the bar was up
                # (a total past --max-particles over several files) left "[---] 0%" above it
                sys.stderr.write("\r\x1b[K\x1b[?25h")
                sys.stderr.flush()
                raise
            bar.render_finish()
        finally:
            self.bars.pop()


def watched() -> bool:
    """Whether a person watches the command: stderr is a terminal that can redraw a line, not --quiet
    or --verbose, and not a CI runner (some give their jobs a pseudo-terminal)."""
    return (sys.stderr.isatty() and verbosity() == 1 and os.environ.get("TERM") != "dumb"
            and os.environ.get("CI", "").strip().lower() in ("", "0", "false", "no"))


BAR_WIDTH = 36
_AROUND_BAR = len("  []  100%  10d 00:00:00") + 1
"""Columns of click's bar line besides its label and bar (percent, and an ETA of up to 12: click
writes one of a day or more as "1d 00:00:00"), and one spare: a line that reaches the last column
wraps on some terminals, and every redraw then starts a new row."""


def _bar_width(label: str) -> int | None:
    """The bar's width, so that its whole line fits the terminal; None when even a short bar
    would not (a bar that wraps is drawn again on a new row at every step)."""
    try:
        columns = os.get_terminal_size(sys.stderr.fileno()).columns
    except (OSError, ValueError, AttributeError):  # not a real terminal (a test's stand-in)
        columns = 0
    columns = columns or 80     # a pseudo-terminal no one sized says 0, as shutil's fallback takes
    width = min(BAR_WIDTH, columns - len(label) - _AROUND_BAR)
    return width if width >= 4 else None


class _Bar(Progress):
    def __init__(self, bar: Any):
        self.bar = bar
        self.width = len(bar.label)     # the bar's width was fitted to the terminal with this label

    def update(self, n: int) -> None:
        self.bar.update(n)

    def stage(self, label: str) -> None:
        self.bar.label = label[:self.width].ljust(self.width)
        self.bar.render_progress()
