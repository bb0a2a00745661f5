"""Options every command gets without declaring them: ``--quiet``, ``--verbose`` and ``--json``.

:class:`fishgen.cli.LazyGroup` adds them to each command as it loads it (and the group has them
too, so ``fishgen --json build ...`` works), so a new command gets them for free.

- ``--quiet``: nothing on stdout (no summary line, no progress); warnings and errors still go to
  stderr.
- ``--verbose``: each file written (from :mod:`fishgen.atomic`) and the command's time, on stderr;
  commands may say more (``fishgen batch`` says why each job ran). With ``--quiet`` too, quiet wins.
- ``--json``: an error that ends the command is one JSON object on stderr,
  ``{"error": ..., "file": ..., "line": ..., "exit": ..., "kind": ...}``.

A :class:`fishgen.errors.UsageError` from the use-case layer leaves the command as click's own
usage errors do, so that every bad command line reads ``fishgen COMMAND: ...``; one that names a
file (an ``-o`` the command cannot write) reads ``FILE: ...``, with the same status and kind.
"""
from __future__ import annotations

import functools
import json
import sys
import time
from collections.abc import Iterable
from contextlib import nullcontext, redirect_stdout
from typing import Any

import click

from fishgen.errors import UsageError

QUIET, NORMAL, VERBOSE = 0, 1, 2
_state: dict[str, Any] = {"quiet": False, "verbose": False, "json": False}


def reset(json_errors: bool = False) -> None:
    """Back to the defaults (one process may run several commands: the tests do)."""
    _state.update(quiet=False, verbose=False, json=json_errors)


def verbosity() -> int:
    """QUIET, NORMAL or VERBOSE. --quiet wins over --verbose, wherever each is given: a script
    that asks for silence on stdout gets it (docs/decisions.md)."""
    return QUIET if _state["quiet"] else VERBOSE if _state["verbose"] else NORMAL


def json_errors() -> bool:
    return bool(_state["json"])


def error_text(err: Any, command: str | None = None) -> str:
    """A FishgenError as its one line reads: ``FILE:LINE: …`` where the input is at fault, else
    after ``fishgen COMMAND:`` (a usage error) or ``fishgen:`` (the system's refusal, or no place)."""
    from fishgen.errors import SystemFailure, UsageError

    if isinstance(err, UsageError) and err.file is None and command:
        return f"fishgen {command}: {err}"
    plain = err.file is None or isinstance(err, SystemFailure)  # a system's refusal names its path
    return f"fishgen: {err}" if plain else str(err)


def error_line(message: str, status: int, *, file: str | None = None, line: int | None = None,
               kind: str = "input", **extra: Any) -> str:
    """An error as the user asked for it: the plain one line, or one JSON object."""
    if not json_errors():
        return message
    return json.dumps({"error": message, "file": file, "line": line, "exit": status, "kind": kind, **extra})


def note_line(text: str) -> str:
    """A note (a warning, or what a command wrote besides its summary) as the user asked for it: the
    plain line, or under --json one JSON object, so that every line on stderr parses alike."""
    return json.dumps({"note": text}) if json_errors() else text


def _set(key: str, value: Any):
    def callback(ctx: click.Context, param: click.Parameter, given: bool) -> None:
        if given:
            _state[key] = value
    return callback


def _options() -> list[click.Option]:
    return [
        click.Option(["-q", "--quiet"], is_flag=True, expose_value=False, is_eager=True,
                     callback=_set("quiet", True),
                     help="Print nothing on stdout (no summary) and draw no progress bar; errors and "
                          "warnings still go to stderr. Wins over --verbose.  [default: off]"),
        click.Option(["-v", "--verbose"], is_flag=True, expose_value=False, is_eager=True,
                     callback=_set("verbose", True),
                     help="Also print each file written and the time taken, on stderr.  [default: off]"),
        click.Option(["--json"], is_flag=True, expose_value=False, is_eager=True, callback=_set("json", True),
                     help='Print an error as one JSON object on stderr: {"error", "file", "line", "exit", '
                          '"kind"}; and each note or warning as {"note"}.  [default: off]'),
    ]


def add_common_options(command: click.Command, wrap: bool = True) -> click.Command:
    """Give ``command`` the common options (once); ``wrap`` makes them act on its callback."""
    if getattr(command, "_fishgen_common", False):
        return command
    taken = {name for p in command.params for name in getattr(p, "opts", [])}
    command.params.extend(o for o in _options() if not taken & set(o.opts))
    if wrap and command.callback is not None:
        command.callback = _wrapped(command.callback, command.name or "fishgen")
    command._fishgen_common = True  # type: ignore[attr-defined]
    return command


def _wrapped(callback, name: str):
    @functools.wraps(callback)
    def run(*args: Any, **kwargs: Any) -> Any:
        level = verbosity()
        start = time.perf_counter()
        if level >= VERBOSE:
            _log_to_stderr()
        # Quiet: stdout goes nowhere. click.echo looks sys.stdout up at each call, so this catches
        # every summary line without each command checking a flag.
        with _devnull() if level <= QUIET else nullcontext() as sink:
            with redirect_stdout(sink) if sink is not None else nullcontext():
                try:
                    result = callback(*args, **kwargs)
                except UsageError as err:
                    if err.file is not None:  # FILE: ... already says where
                        raise
                    # the use-case layer's own usage errors read as click's: `fishgen COMMAND: ...`
                    raise click.UsageError(err.message, ctx=click.get_current_context()) from None
        if level >= VERBOSE:
            click.echo(f"fishgen {name}: done in {time.perf_counter() - start:.2f} s", err=True)
        return result
    return run


def say(lines: Iterable[str], err: bool = False) -> None:
    """Print ``lines`` (stdout, or stderr with ``err``) and flush them. A reader that has gone (a
    closed pipe: `fishgen school … | head -1`) stops only the printing: the stream goes to
    /dev/null from then on and the command carries on, its files landing as they would; click's
    own handling exited 1 in silence, and a school's staged files never landed. Any other failure
    to print (stdout on a full disk) fails the command, saying so."""
    stream = sys.stderr if err else sys.stdout
    try:
        for line in lines:
            click.echo(line, err=err)
        stream.flush()
    except BrokenPipeError:
        _gone(stream)
    except OSError as error:
        from fishgen.errors import SystemFailure

        raise SystemFailure(f"cannot write to {'stderr' if err else 'stdout'}: "
                            f"{error.strerror or error}") from None


def _gone(stream: Any) -> None:
    """Point a stream whose reader has gone at /dev/null, its unwritten bytes dropped."""
    import os

    try:
        fd = stream.fileno()
    except (OSError, ValueError):   # not a file (a test's buffer): nothing to point anywhere
        return
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, fd)
    os.close(null)


def _devnull():
    import os

    # surrogateescape: a summary naming a file whose name is not UTF-8 is discarded, not an error
    return open(os.devnull, "w", encoding="utf-8", errors="surrogateescape")


def _log_to_stderr() -> None:
    import logging

    logger = logging.getLogger("fishgen")
    if not any(getattr(h, "_fishgen", False) for h in logger.handlers):
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("fishgen: %(message)s"))
        handler._fishgen = True  # type: ignore[attr-defined]
        logger.addHandler(handler)
    logger.setLevel(logging.INFO)
