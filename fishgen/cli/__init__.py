"""Command-line entry point: a thin, lazily-loaded layer over the library API.

Subcommands live in their own modules and are imported only when invoked, so
``fishgen --help`` stays instant (no numpy/trimesh import).
"""
from __future__ import annotations

import atexit
import importlib
import os
import signal
import sys
import threading

import click

from fishgen.cli.common import add_common_options, error_line, json_errors, reset

# name -> (module, attribute, one-line help shown by `fishgen --help`)
COMMANDS = {
    "build": ("fishgen.cli.build", "build", "Build a species file into a textured, fin-animated fish asset."),
    "clouds": ("fishgen.cli.clouds", "clouds",
               "Fill cloud cube files (.awn) with particles and export them."),
    "preview": ("fishgen.cli.preview", "preview",
                "Render inputs or assets to PNG, contact sheets or swim loops."),
    "view": ("fishgen.cli.view", "view", "Open an asset in a self-contained three.js viewer page."),
    "school": ("fishgen.cli.school", "school",
               "Simulate a fish school and bake it into an animated glb, tracks and measures."),
    "batch": ("fishgen.cli.batch", "batch",
              "Regenerate an asset set from a manifest or folder, incrementally and in parallel."),
    "texture": ("fishgen.cli.texture", "texture",
                "Make a species from a side photo of a fish: texture, texture points, fin mask."),
    "species": ("fishgen.cli.species", "species",
                "Sample plausible new species (shape, fins, motion) with painted textures."),
}


class LazyGroup(click.Group):
    def list_commands(self, ctx):
        return sorted(COMMANDS)

    def get_command(self, ctx, name):
        if name not in COMMANDS:
            return None
        module, attr, _ = COMMANDS[name]
        try:
            command = getattr(importlib.import_module(module), attr)
        except ModuleNotFoundError as err:
            if err.name == module:
                return None
            raise
        return add_common_options(command)  # --quiet, --verbose, --json: every command, declared once

    def format_commands(self, ctx, formatter):
        rows = [(name, COMMANDS[name][2]) for name in self.list_commands(ctx)]
        with formatter.section("Commands"):
            formatter.write_dl(rows)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="fishgen")
def cli() -> None:
    """fishgen: procedural fish and cloud assets for games and pipelines.

    Run `fishgen COMMAND --help` for the options of each command.
    """


add_common_options(cli, wrap=False)  # `fishgen --json build ...` as well as `fishgen build ... --json`


class Interrupted(BaseException):
    """Ctrl-C or SIGTERM. Not a KeyboardInterrupt: click turns that into Abort after printing a
    blank line of its own, and the message would be two lines. Atomic writers still unwind."""

    def __init__(self, status: int):
        super().__init__(status)
        self.status = status


def _interrupt(signum: int, _frame: object) -> None:
    raise Interrupted(128 + signum)


def main(argv: list[str] | None = None) -> None:
    """Console-script entry: bad input becomes a one-line error, never a traceback.

    Exit status: 0 done, 1 a file could not be read or written (or, in a batch, a job failed for
    another reason than its input), 2 bad input or usage, 130 Ctrl-C, 143 SIGTERM.
    """
    from fishgen.errors import FishgenError

    args = sys.argv[1:] if argv is None else list(argv)
    # Known before parsing, so that even an unknown option's error comes out as JSON.
    reset(json_errors="--json" in (args[: args.index("--")] if "--" in args else args))
    signal.signal(signal.SIGTERM, _interrupt)
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # not when a parent ignores it
        signal.signal(signal.SIGINT, _interrupt)
    try:
        cli.main(args=args, prog_name="fishgen", standalone_mode=False)
    except FishgenError as err:
        status = getattr(err, "status", 2)
        _fail(f"fishgen: {err}" if err.file is None else str(err), status, err.file, err.line,
              getattr(err, "kind", "input"))
    except click.exceptions.Abort:
        _fail("fishgen: interrupted", 130, kind="interrupted")  # the shell's ^C ends the line before ours
    except click.UsageError as err:  # one line, like every other error (`--help` shows the usage)
        command = err.ctx.command_path if err.ctx is not None else "fishgen"
        _fail(f"{command}: {err.format_message()}", err.exit_code, kind="usage")
    except click.ClickException as err:
        if not json_errors():
            err.show()
            sys.exit(err.exit_code)
        _fail(err.format_message(), err.exit_code, kind="usage")
    except (KeyboardInterrupt, Interrupted) as err:
        _fail("fishgen: interrupted", err.status if isinstance(err, Interrupted) else 130, kind="interrupted")
    except OSError as err:
        _fail(f"fishgen: {err.filename or ''}: {err.strerror or err}", 1, err.filename, kind="os")


def run() -> None:
    """The `fishgen` command (console script and ``python -m fishgen``): :func:`main`, then an exit
    that does not tear the interpreter down.

    Freeing every loaded module's objects one by one took 16-25 ms after a build (7-11 % of it) and
    50 ms after a batch's pool, with nothing left to gain: every file fishgen writes is closed and
    renamed into place before :func:`main` returns. The exit handlers still run and the standard
    streams are flushed; with another thread still running, Python exits as usual and waits for it.
    """
    try:
        main()
        status = 0
    except SystemExit as stop:
        if stop.code is None or isinstance(stop.code, int):
            status = stop.code or 0
        else:
            print(stop.code, file=sys.stderr)
            status = 1
    if threading.active_count() > 1:
        sys.exit(status)
    for signum in (signal.SIGINT, signal.SIGTERM):  # too late to interrupt: nothing is left to stop
        if signal.getsignal(signum) is _interrupt:
            signal.signal(signum, signal.SIG_DFL)
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):  # a reader that went away (`fishgen ... | head`): nothing to add
            pass
    os._exit(status)


def _fail(message: str, status: int, file: str | None = None, line: int | None = None,
          kind: str = "input") -> None:
    click.echo(error_line(message, status, file=file, line=line, kind=kind), err=True)
    sys.exit(status)
