"""The one error type fishgen raises for bad input.

Every message reads ``FILE:LINE: expected ..., found ...`` so that a user (or an
editor jumping to the location) can fix the input without reading a traceback.
"""
from __future__ import annotations

import os


class FishgenError(Exception):
    """Bad input or an impossible request, reported without a traceback."""

    def __init__(self, message: str, file: str | os.PathLike | None = None,
                 line: int | None = None):
        self.message = message
        self.file = os.fspath(file) if file is not None else None
        self.line = line
        super().__init__(str(self))

    def __str__(self) -> str:
        where = ""
        if self.file is not None:
            where = f"{self.file}:{self.line}: " if self.line is not None else f"{self.file}: "
        return where + self.message


def expected(what: str, found: str, file=None, line=None) -> FishgenError:
    """Build the canonical ``expected X, found Y`` error."""
    return FishgenError(f"expected {what}, found {found}", file, line)


def describe(token: str, limit: int = 40) -> str:
    """Quote a piece of input for an error message, shortened and made printable."""
    text = token if len(token) <= limit else token[: limit - 1] + "…"
    return repr(text)
