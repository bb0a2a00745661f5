"""The use-case layer: one module per command, each holding one library function.

    from fishgen.commands.build import BuildOptions, build
    made = build([Path("params/bonybream.txt")], Path("out/bonybream.glb"), BuildOptions(fps=60))
    made.written, made.read, made.facts      # what it wrote, what it read, what it built

Each module declares its :class:`Command`: the options record (whose fields are the option
declarations, :mod:`fishgen.commands.options`), its inputs and output, its help, and the function.
The command line (:mod:`fishgen.cli`) and batch jobs (:func:`fishgen.commands.batch.run_job`) are
thin adapters over these; neither knows what a command does.

The modules import nothing heavy at the top (numpy loads inside the functions), so ``fishgen
--help`` and a batch run where nothing changed stay fast.
"""
from __future__ import annotations

import importlib
import os
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager as ContextManager
from contextlib import contextmanager, nullcontext
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fishgen.errors import FishgenError

#: Every command, by name -> the module that declares it (``COMMAND``), in `fishgen --help` order.
MODULES = {
    "batch": "fishgen.commands.batch",
    "build": "fishgen.commands.build",
    "clouds": "fishgen.commands.clouds",
    "edit": "fishgen.commands.edit",
    "fly": "fishgen.commands.fly",
    "preview": "fishgen.commands.preview",
    "school": "fishgen.commands.school",
    "sky": "fishgen.commands.sky",
    "species": "fishgen.commands.species",
    "texture": "fishgen.commands.texture",
    "view": "fishgen.commands.view",
}


@dataclass(frozen=True)
class Inputs:
    """A command's positional arguments."""

    metavar: str
    many: bool = True                   # one or more (else exactly one)
    path: bool = True                   # file paths (else plain strings)
    required: bool = True               # False: none at all is allowed (fly --mode)


@dataclass(frozen=True)
class Output:
    """A command's ``-o``."""

    help: str
    required: bool = True
    metavar: str = "PATH"
    shown_default: str | None = None
    holds: tuple[str, ...] = ()         # what its format must hold, in the registry's words
    folder: bool = False                # -o may name a folder (build's several inputs, species --count)


@dataclass(frozen=True)
class Command:
    """What a command is: the adapters build the CLI command and the batch job from this."""

    name: str
    summary: str                        # one line, in `fishgen --help`
    help: str                           # the command's --help text (click docstring conventions)
    options: type                       # the frozen options record
    run: str                            # "module:function" of the use-case function
    inputs: Inputs | None = None
    output: Output | None = None
    batch: bool = False                 # a batch manifest may list jobs of this command
    cli: str | None = None              # "module:function" of a command-specific CLI adapter
    together: bool = False              # the CLI lands every output only once the summary is printed
    check: Callable[[Any, str | os.PathLike | None], None] | None = None
    # options that cannot go together, or with the output (-o): a UsageError, for the use case and
    # for a manifest's job before any job runs

    def given(self, inputs: Any, options: Any) -> tuple[Any, ...]:
        """A Python caller's inputs and options, checked as the command line checks its own: the
        options record of this command, each value as declared; the inputs a list (one path stands
        for a list of one), as many as the command takes."""
        from fishgen.errors import UsageError
        from fishgen.options import check_record

        if not isinstance(options, self.options):
            raise UsageError(f"expected options to be a {self.options.__name__}, found "
                             f"{type(options).__name__}")
        check_record(options)
        spec = self.inputs or Inputs("INPUT", required=False)
        if isinstance(inputs, (str, os.PathLike)):
            inputs = [inputs]
        try:
            given = list(inputs)
            items = tuple(Path(p) if spec.path else str(p) for p in given)
        except TypeError:
            raise UsageError(f"expected the inputs as a list of {spec.metavar}, found {inputs!r}") from None
        if spec.path and any(not os.fspath(p) for p in given):     # Path("") is the working folder
            raise UsageError(f"expected each {spec.metavar} to be a path, found an empty one")
        if not items and spec.required:
            raise UsageError(f"expected {'one or more' if spec.many else 'one'} {spec.metavar}, found none")
        if len(items) > 1 and not spec.many:
            raise UsageError(f"expected one {spec.metavar}, found {len(items)}")
        return items

    @property
    def holds(self) -> tuple[str, ...]:
        """What the command's output format must hold (nothing when it writes no -o)."""
        return self.output.holds if self.output is not None else ()

    def function(self) -> Callable[..., Made]:
        module, name = self.run.split(":")
        return getattr(importlib.import_module(module), name)


def command(name: str) -> Command:
    """The declaration of command ``name``."""
    return importlib.import_module(MODULES[name]).COMMAND


@dataclass(frozen=True)
class Made:
    """What a command did: files written and read (absolute or as given), the summary lines it
    prints on stdout, its typed facts, and how many of several inputs failed (each reported
    through :attr:`Events.failed` as it happened)."""

    written: tuple[Path, ...] = ()
    read: tuple[Path, ...] = ()
    lines: tuple[str, ...] = ()
    facts: Any = None
    failed: tuple[FishgenError, ...] = ()
    verdict: FishgenError | None = None  # how the command ends once its summary is out (jobs failed)
    server: Any = None                  # a bound local server the caller serves until Ctrl-C


class Progress:
    """A progress bar's counter: ``update(n)`` adds ``n`` done; ``stage(label)`` names what the
    command does now, on the same bar (no longer a label than the bar's first)."""

    def update(self, n: int) -> None:
        pass

    def stage(self, label: str) -> None:
        pass


def stage(bar: Any, label: str) -> None:
    """``bar.stage(label)`` where the caller's bar has stages: a library caller may hand any counter
    with ``update`` (tqdm's, say), and a school ended in an AttributeError at its bake."""
    named = getattr(bar, "stage", None)
    if callable(named):
        named(label)


def _no_bar(label: str, total: int) -> ContextManager[Progress]:
    return nullcontext(Progress())


def _ignore(text: str) -> None:
    pass


def _ignore_line(text: str, detail: str | None) -> None:
    pass


@dataclass(frozen=True)
class Events:
    """How a running command talks to whoever runs it. The CLI prints notes on stderr and draws
    bars on a terminal; a batch job keeps the notes and draws nothing."""

    note: Callable[[str], None] = _ignore                              # a warning, one line
    failed: Callable[[FishgenError], None] | None = None                # one of several inputs failed
    progress: Callable[[str, int], ContextManager[Progress]] = field(default=_no_bar)
    line: Callable[[str, str | None], None] = _ignore_line             # a step done (a batch's job), and
                                                                       # why it ran (said with --verbose)
    summary: bool = True    # the caller shows Made.lines; without, a command skips what only they need


QUIET = Events()


def run(cmd: Command, inputs: tuple[Path, ...], output: str | os.PathLike | None, options: Any,
        events: Events = QUIET) -> Made:
    """Run a command as the CLI and batch jobs do: no file it writes may be one of its inputs, and
    a command that writes one file is given a file, not a folder."""
    from fishgen.atomic import protecting

    if output is not None and cmd.output is not None:
        from fishgen.atomic import check_target
        from fishgen.commands.paths import names_folder
        from fishgen.errors import UsageError

        if not os.fspath(output):   # Path("") is ".": build and species wrote into the working folder
            what = "file or folder" if cmd.output.folder else "file"
            raise UsageError(f"expected -o to name an output {what}, found an empty name")
        folder = names_folder(output)
        if folder and not cmd.output.folder:
            raise UsageError(f"expected -o to name an output file, found the folder {os.fspath(output)!r}")
        if not folder:  # before the format's check: `-o /dev/null` is a device, not a name with no extension
            check_target(Path(output))
    _folders_there(options)
    with protecting(inputs):
        made = cmd.function()(inputs, output, options, events)
    if cmd.output is not None:  # a batch writes through its jobs' runs, and each said its own
        from fishgen.exchange.client_limits import notes

        for note in notes(made.written):    # what a client will not read or play of it
            events.note(note)
    return made


def _folders_there(options: Any) -> None:
    """A folder an option reads from must be there: `sky --textures typo/` with no texture cloud
    was taken without a word (a manifest's folders are resolved by now)."""
    from dataclasses import fields, is_dataclass

    from fishgen.errors import UsageError
    from fishgen.options import OPTION, long_name

    if not is_dataclass(options):
        return
    for f in fields(options):       # a group's options (a cloud's lighting) name no folders
        spec = f.metadata.get(OPTION)
        value = getattr(options, f.name)
        if spec is not None and spec.exists and value is not None and not Path(value).is_dir():
            kind = "a file" if Path(value).exists() else "nothing"
            raise UsageError(f"expected --{long_name(f)} to name an existing folder, found {kind} at "
                             f"{os.fspath(value)!r}")


@contextmanager
def each_input(events: Events, errors: list[FishgenError], several: bool) -> Iterator[None]:
    """Run one input's work; with several inputs, its bad input is reported and the rest go on."""
    try:
        yield
    except FishgenError as err:
        if not several or events.failed is None or err.status != 2:
            raise
        events.failed(err)
        errors.append(err)
