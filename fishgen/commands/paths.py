"""Where a command's outputs go, checked before any work starts.

The ``-o`` rule, for every command:

- ``-o`` names a folder only when it is an existing folder or ends in ``/``; each input then
  becomes ``FOLDER/<input stem>.<format>``;
- anything else names a file, whose extension picks the format; several inputs into one file
  is refused, and so is a name with no extension that is not a folder;
- an output that exists must be a regular file (never a FIFO or ``/dev/null``);
- no output may be one of the command's inputs.

Optional dependencies a chosen feature needs are checked before any work too (:func:`needs`, from
:mod:`fishgen.extras`, which the layers below the commands use as well).
"""
from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from fishgen.atomic import check_target, protecting
from fishgen.errors import FishgenError, UsageError
from fishgen.extras import needs as needs  # the commands' one place for their checks

if TYPE_CHECKING:
    from fishgen.exchange.registry import Format


def check_inputs(paths: Iterable[str | os.PathLike], command: str, kinds: Sequence[Format],
                 default: Format | None = None) -> list[Format]:
    """Every input is a file of a kind ``command`` reads (a file meant for another command names
    that command); returns each input's format. ``default``: the format of an input whose extension
    no format claims (species files need not end in .txt)."""
    from fishgen.exchange.registry import input_format

    found = []
    for path in map(Path, paths):
        if path.is_dir():
            raise FishgenError("expected a file, found a directory", path)
        found.append(input_format(path, kinds=kinds, command=command, default=default))
    return found


def names_folder(output: str | os.PathLike) -> bool:
    """Whether ``-o`` names a folder: an existing one, or a name ending in ``/``."""
    text = os.fspath(output)
    return text.endswith(("/", os.sep)) or Path(text).is_dir()


def targets(inputs: Sequence[Path], given: str | os.PathLike | None, *, fmt: str, holding: Iterable[str] = (),
            default_folder: Path = Path("out"), noun: str = "input") -> list[Path]:
    """One output per input by the ``-o`` rule; ``fmt`` is the format inside a folder."""
    from fishgen.exchange.registry import output_format

    need = list(holding)
    several = len(inputs) > 1
    output = Path(given) if given is not None else None
    if given is not None and output is not None and not names_folder(given):
        check_target(output)  # `-o /dev/null`: not a regular file, whatever its name
        if several:
            raise UsageError(f"expected a folder for {len(inputs)} {noun}s (an existing folder, or a "
                             f"name ending in /), found {os.fspath(output)!r}")
        if not output.suffix:
            raise UsageError(f"expected an output file with an extension, or a folder (an existing one, "
                             f"or a name ending in /), found {os.fspath(output)!r}")
        output_format(output, need)
        return [output]
    folder = output if output is not None else default_folder
    output_format(Path(f"x.{fmt}"), need)
    made: dict[str, Path] = {}
    for path in inputs:
        name = f"{path.stem}.{fmt}"
        if name in made:
            raise UsageError(f"expected {noun}s with distinct names for one folder, found {made[name]} "
                             f"and {path} (both make {name})")
        made[name] = path
    return [folder / name for name in made]


def check_targets(outputs: Iterable[str | os.PathLike | None], inputs: Iterable[str | os.PathLike]) -> None:
    """Every output may be written: a missing or regular file, and none of the command's inputs
    (checked before any work; the writers check again, see :func:`fishgen.atomic.protecting`)."""
    with protecting(inputs):
        for target in outputs:
            if target is not None:
                check_target(Path(target))


def suffix_of(path: Path, allowed: Sequence[str], what: str) -> None:
    """A side output (``--metrics``, ``--plot``) ends in one of ``allowed``."""
    if path.suffix.lower() not in allowed:
        raise UsageError(f"expected {what} ending in {' or '.join(allowed)}, found "
                         f"{path.suffix or 'no extension'!r}", path)

