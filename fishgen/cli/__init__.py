"""Command-line entry point: a thin adapter over the use-case layer (:mod:`fishgen.commands`).

Each command's click command is made from its declaration (:mod:`fishgen.cli.adapter`) when it is
invoked, and the declarations import nothing heavy, so ``fishgen --help`` stays instant (no
numpy/trimesh import).
"""
from __future__ import annotations

import atexit
import os
import signal
import sys
import threading

import click

from fishgen import __version__, interrupts
from fishgen.cli.common import add_common_options, error_line, error_text, json_errors, reset, say
from fishgen.commands import MODULES, command

# numpy asks the kernel for transparent huge pages on every array of 4 MiB or more. Where the
# kernel then compacts memory to find one at each fault (THP defrag "madvise", a common default),
# first touching a fresh 500 MB array took 1.9 s instead of 0.22 s, and a 10^7-particle cloud's
# command spent more time in those faults than in its own work (docs/decisions.md). fishgen runs
# through its big arrays in order, where huge pages gain little, so the command turns them off
# before numpy is first imported; NUMPY_MADVISE_HUGEPAGE=1 in the environment turns them back on.
try:    # unset, or a value numpy's int() cannot read (empty, "yes": a traceback at its import)
    int(os.environ.get("NUMPY_MADVISE_HUGEPAGE", ""))
except ValueError:
    os.environ["NUMPY_MADVISE_HUGEPAGE"] = "0"


class LazyGroup(click.Group):
    def list_commands(self, ctx):
        return sorted(MODULES)

    def get_command(self, ctx, name):
        if name not in MODULES:
            return None
        from fishgen.cli.adapter import click_command

        cmd = command(name)
        return add_common_options(click_command(cmd))  # --quiet, --verbose, --json: every command, once

    def resolve_command(self, ctx, args):
        name = args[0] if args else ""
        if name not in MODULES and not name.startswith("-") and not ctx.resilient_parsing:
            import difflib

            near = difflib.get_close_matches(name, MODULES, n=1)    # as click suggests options
            if near:
                ctx.fail(f"No such command {name!r}. Did you mean {near[0]!r}?")
        return super().resolve_command(ctx, args)

    def format_commands(self, ctx, formatter):
        rows = [(name, command(name).summary) for name in self.list_commands(ctx)]
        with formatter.section("Commands"):
            formatter.write_dl(rows)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, package_name="fishgen")  # the version the files record, not pip's metadata
def cli() -> None:
    """fishgen: procedural fish and cloud assets for games and pipelines.

    Run `fishgen COMMAND --help` for the options of each command.

    \b
    Examples:
      fishgen build params/bonybream.txt -o out/bonybream.glb
      fishgen clouds params/clouds/table_4_4.awn -o out/cloud.glb --billboards
      fishgen school params/bonybream.txt --count 200 -o out/school.glb
      fishgen batch params/assets.toml -j 2
    """


add_common_options(cli, wrap=False)  # `fishgen --json build ...` as well as `fishgen build ... --json`


class Interrupted(BaseException):
    """Ctrl-C or SIGTERM. Not a KeyboardInterrupt: click turns that into Abort after printing a
    blank line of its own, and the message would be two lines. Atomic writers still unwind."""

    def __init__(self, status: int):
        super().__init__(status)
        self.status = status


def _interrupt(signum: int, _frame: object) -> None:
    interrupts.deliver(Interrupted(128 + signum))  # after the renames under way, if any


def _typed_among(option: str | None, args: list[str]) -> bool:
    """Whether ``option`` is among ``args`` as typed: alone, with ``=value``, or a short one in a
    bundle of them (``-qx``)."""
    if not option:
        return False
    return any(a == option or a.startswith(option + "=")
               or (len(option) == 2 and a.startswith("-") and not a.startswith("--") and option[1] in a[1:])
               for a in args)


def main(argv: list[str] | None = None) -> None:
    """Console-script entry: bad input becomes a one-line error, never a traceback.

    Exit status: 0 done, 1 a file could not be read or written, or memory ran out (or, in a batch,
    a job failed for another reason than its input), 2 bad input or usage, 130 Ctrl-C, 143 SIGTERM.
    """
    from fishgen.errors import FishgenError

    args = sys.argv[1:] if argv is None else list(argv)
    _printable_streams()
    # Known before parsing, so that even an unknown option's error comes out as JSON.
    reset(json_errors="--json" in (args[: args.index("--")] if "--" in args else args))
    signal.signal(signal.SIGTERM, _interrupt)
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # not when a parent ignores it
        signal.signal(signal.SIGINT, _interrupt)
    try:
        cli.main(args=args, prog_name="fishgen", standalone_mode=False)
    except FishgenError as err:
        _fail(error_text(err), err.status, err.file, err.line, err.kind)
    except click.exceptions.Abort:
        interrupts.stopped()
        _fail("fishgen: interrupted", 130, kind="interrupted")  # the shell's ^C ends the line before ours
    except click.exceptions.NoArgsIsHelpError as err:  # `fishgen` alone: its help, as click prints it
        err.show()
        sys.exit(err.exit_code)
    except click.UsageError as err:  # one line, like every other error (`--help` shows the usage)
        command = err.ctx.command_path if err.ctx is not None else "fishgen"
        if command == "fishgen":
            # click says an option given no value in the group's context, not its command's: the
            # command is found in the arguments, so the line names it as every other usage error does;
            # not an option typed before the command's name (`fishgen --foo build`): the group's
            at = next((i for i, a in enumerate(args) if a in MODULES), None)
            if at is not None and not _typed_among(getattr(err, "option_name", None), args[:at]):
                command = f"fishgen {args[at]}"
        _fail(f"{command}: {err.format_message()}", err.exit_code, kind="usage")
    except click.ClickException as err:
        if not json_errors():
            err.show()
            sys.exit(err.exit_code)
        _fail(err.format_message(), err.exit_code, kind="usage")
    except (KeyboardInterrupt, Interrupted) as err:
        interrupts.stopped()
        _fail("fishgen: interrupted", err.status if isinstance(err, Interrupted) else 130, kind="interrupted")
    except MemoryError as err:  # the estimates err high, but a system can refuse less than they foresee
        detail = str(err).strip()  # numpy names the array it could not allocate; Python names nothing
        _fail(f"fishgen: out of memory{': ' + detail if detail else ''}", 1, kind="os")
    except OSError as err:  # one no layer below turned into a SystemFailure with its path
        from fishgen.errors import too_long

        long = too_long(err)
        where = f"{err.filename}: " if err.filename and long is None else ""
        _fail(f"fishgen: {where}{long or err.strerror or err}", 1, err.filename, kind="os")


def _printable_streams() -> None:
    """Print what the terminal's encoding cannot show as escapes (``f\\xefsh.glb``), as Python's
    stderr already does: a file name in a summary line once ended a build whose file had landed in
    a traceback and exit 1 (``PYTHONIOENCODING=latin-1``, a name with a ``✓``)."""
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)      # a test's buffer may have none
        if reconfigure is not None and getattr(stream, "errors", None) == "strict":
            reconfigure(errors="backslashreplace")


def status_of(argv: list[str] | None = None) -> int:
    """:func:`main`'s exit status as the shell sees it (a non-numeric exit's message on stderr)."""
    try:
        main(argv)
        return 0
    except SystemExit as stop:
        if stop.code is None or isinstance(stop.code, int):
            return stop.code or 0
        print(stop.code, file=sys.stderr)
        return 1


def run() -> None:
    """The `fishgen` command (console script and ``python -m fishgen``): :func:`main`, then an exit
    that does not tear the interpreter down.

    Freeing every loaded module's objects one by one took 16-25 ms after a build (7-11 % of it) and
    50 ms after a batch's pool, with nothing left to gain: every file fishgen writes is closed and
    renamed into place before :func:`main` returns. The exit handlers still run and the standard
    streams are flushed; with another thread still running, Python exits as usual and waits for it.
    """
    status = status_of()
    if threading.active_count() > 1:
        sys.exit(status)
    for signum in (signal.SIGINT, signal.SIGTERM):  # too late to interrupt: nothing is left to stop
        if signal.getsignal(signum) is _interrupt:
            signal.signal(signum, signal.SIG_DFL)
    # Private, and on purpose: no public API runs the exit handlers (a library's log flush, a Dask
    # client's close) without also tearing the interpreter down, which is what this exit skips.
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
    from fishgen.errors import SystemFailure

    try:
        say([error_line(message, status, file=file, line=line, kind=kind)], err=True)
    except SystemFailure:
        pass      # stderr itself refused (a full disk): the status is all there is left to say
    sys.exit(status)
