"""Option and argument types the commands share, so click checks values before any work starts."""
from __future__ import annotations

import math
from pathlib import Path

import click

FLOAT32_MAX = 3.4028234663852886e38  # mirrors fishgen.numeric without importing numpy at --help time


class Triple(click.ParamType):
    """``X,Y,Z``: three finite numbers within float32 range (where particles and nodes live)."""

    name = "X,Y,Z"

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        try:
            numbers = tuple(float(part) for part in str(value).replace(" ", "").split(","))
        except ValueError:
            numbers = ()
        if len(numbers) != 3 or not all(math.isfinite(v) and abs(v) <= FLOAT32_MAX for v in numbers):
            self.fail(f"expected X,Y,Z with three finite numbers within float32 range, found {value!r}",
                      param, ctx)
        return numbers


class FiniteRange(click.FloatRange):
    """click's FloatRange, refusing NaN too (it compares false with both bounds, so it passes them)."""

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number.", param, ctx)
        return number


def check_inputs(paths, command: str, kinds, default=None) -> None:
    """Every input exists as a file of a kind ``command`` reads; else the one-line ``FILE: expected ...``.

    A file meant for another command (a cube file given to `build`) names that command.
    """
    from fishgen.errors import FishgenError
    from fishgen.exchange.registry import input_format

    for path in map(Path, paths):
        if path.is_dir():
            raise FishgenError("expected a file, found a directory", path)
        input_format(path, kinds=kinds, command=command, default=default)
