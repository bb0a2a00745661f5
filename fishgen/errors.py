"""The errors fishgen raises, each with the exit status of the README's table.

Every message reads ``FILE:LINE: expected ..., found ...`` (or ``fishgen: PATH: reason`` when the
system refused), so that a user, or an editor jumping to the location, can act without reading a
traceback. The class says what went wrong; the CLI and ``--json`` take ``status`` and ``kind``
from it, never from attributes set on the side.

| class               | status | kind        | what went wrong                                        |
|---------------------|-------:|-------------|--------------------------------------------------------|
| FishgenError        | 2      | input       | bad input, or an impossible request                     |
| UsageError          | 2      | usage       | a bad command line (an option's value, a missing -o)   |
| SystemFailure       | 1      | os          | a file could not be read or written for a reason       |
|                     |        |             | outside the input (a full disk, a write refused, a     |
|                     |        |             | port taken, a scheduler out of reach)                  |
| MissingDependency   | 1      | dependency  | an optional package is not installed                   |
| JobsFailed          | 2 or 1 | jobs        | batch jobs failed: 2 if any on bad input, else 1       |
"""
from __future__ import annotations

import copy
import os
from typing import Any


class FishgenError(Exception):
    """Bad input or an impossible request, reported without a traceback (exit status 2)."""

    status = 2
    kind = "input"
    job: str | None = None   # the batch job it failed, when it is a job's error

    def __init__(self, message: str, file: str | os.PathLike | None = None,
                 line: int | None = None):
        self.message = message
        self.file = os.fspath(file) if file is not None else None
        self.line = line
        super().__init__(str(self))

    def of_job(self, name: str) -> FishgenError:
        """This error as batch job ``name``'s: the job is named in the message unless a
        ``FILE:LINE`` already says where."""
        if self.file is None:
            return self._with(job=name, message=f"{name}: {self.message}")
        shown = os.path.relpath(self.file) if os.path.isabs(self.file) else self.file
        # a job's inputs are resolved: shown from here, as a user names them, when they lie below
        return self._with(job=name, file=self.file if shown.startswith("..") else shown)

    def naming(self, file: str | os.PathLike) -> FishgenError:
        """This error with its place named as ``file`` (the path as a user gave it, where a layer
        below read another spelling of it)."""
        return self._with(file=os.fspath(file))

    def at(self, file: str | os.PathLike | None, line: int | None = None) -> FishgenError:
        """This error said at ``file:line`` (a manifest job's line), its class, status and kind
        kept: a missing package stays exit 1, ``dependency``."""
        return self._with(file=os.fspath(file) if file is not None else None, line=line)

    def _with(self, **changes: Any) -> FishgenError:
        """A copy of this error (its class kept) with ``changes`` to its attributes."""
        clone = copy.copy(self)
        for name, value in changes.items():
            setattr(clone, name, value)
        clone.args = (str(clone),)
        return clone

    def __str__(self) -> str:
        where = ""
        if self.file is not None:
            where = f"{self.file}:{self.line}: " if self.line is not None else f"{self.file}: "
        return where + self.message

    def __reduce__(self):  # pickled across batch workers with its message, place and class intact
        return (type(self), (self.message, self.file, self.line))


class UsageError(FishgenError):
    """A bad command line: an option's value, or options that cannot go together (status 2)."""

    kind = "usage"


class SystemFailure(FishgenError):
    """The system refused, not the input: a full disk, a write refused, a port already in use, an
    unreachable scheduler (status 1). The message names the path or the resource."""

    status = 1
    kind = "os"

    def __str__(self) -> str:  # the path is in the message ("cannot write PATH: reason")
        return self.message


class MissingDependency(FishgenError):
    """An optional package a feature needs is not installed (status 1); says what to install."""

    status = 1
    kind = "dependency"


class JobsFailed(FishgenError):
    """Some of a batch's jobs failed: status 2 when any failed on bad input, else 1 (a pipeline
    can then retry only the others)."""

    kind = "jobs"

    def __init__(self, message: str, any_input: bool):
        super().__init__(message)
        self.status = 2 if any_input else 1

    def __reduce__(self):
        return (type(self), (self.message, self.status == 2))


def expected(what: str, found: str, file=None, line=None) -> FishgenError:
    """Build the canonical ``expected X, found Y`` error."""
    return FishgenError(f"expected {what}, found {found}", file, line)


def not_a_file(what: str, path: str | os.PathLike) -> FishgenError:
    """``expected WHAT, found …`` for a path that is no regular file: not there, a directory, or a
    special file (a FIFO, /dev/null), each said as what it is."""
    found = ("no such file" if not os.path.exists(path) else "a directory" if os.path.isdir(path)
             else "a special file")
    return expected(what, found, os.fspath(path))


def cannot(action: str, path: str | os.PathLike, err: OSError) -> SystemFailure:
    """An OS error while reading or writing ``path``, with the path always named (a full disk's
    ``OSError`` carries none)."""
    return SystemFailure(f"cannot {action} {os.fspath(path)}: {err.strerror or err}", path)


NAME_MAX = 255
"""The longest name a part of a path may have on the file systems fishgen runs on, in bytes."""


def too_long(err: OSError) -> str | None:
    """For a path the system refused as too long, what was expected and what was found, with the
    overlong part cut short (the whole path may be thousands of characters); else None."""
    import errno

    if err.errno != errno.ENAMETOOLONG or not err.filename:
        return None
    path = os.fspath(err.filename)
    parts = path.split(os.sep)
    size = max(len(os.fsencode(part)) for part in parts)
    if size <= NAME_MAX:
        return (f"{path[:40]}…: expected a path of at most {os.pathconf('/', 'PC_PATH_MAX')} bytes, "
                f"found {len(os.fsencode(path))}")
    shown = os.sep.join(p if len(os.fsencode(p)) <= NAME_MAX else p[:24] + "…" for p in parts)
    return (f"{shown}: expected names of at most {NAME_MAX} bytes (the file system's limit), "
            f"found one of {size}")


def plural(count: int, noun: str) -> str:
    """``1 cube``, ``2 cubes``, ``1,000 files``: a count and its noun, as messages and summaries say it."""
    return f"{count:,} {noun}{'s' * (count != 1)}"


def either(words: list[str] | tuple[str, ...], conjunction: str = "or") -> str:
    """``a``, ``a or b``, ``a, b or c``: words as a sentence lists them."""
    return ", ".join(words[:-1]) + f" {conjunction} " + words[-1] if len(words) > 1 else "".join(words)


def describe(token: str, limit: int = 40) -> str:
    """Quote a piece of input for an error message, shortened and made printable."""
    text = token if len(token) <= limit else token[: limit - 1] + "…"
    return repr(text)
