"""Parser for RekAwan cloud cube files (.awn), report section 4.3.4.

Line 1 holds the total particle count, line 2 the cube count, then one line per
cube: ``particles, x size, y size, z size, centre x, centre y, centre z, max
radius``. Fields are separated by commas and/or white space, because the
editor's own Table 4.3 has a line with a missing comma. Blank lines are skipped
but still counted, so messages point at the real line.
"""
from __future__ import annotations

import math
import os
import re
import warnings
from pathlib import Path

from fishgen.errors import FishgenError, describe, expected
from fishgen.clouds.model import DEFAULT_MAX_PARTICLES, Cube, CubeFile

# ASCII-only patterns: "１２" (full-width digits) or "1_000" are not numbers in this format.
_SEPARATOR = re.compile(r"[ \t]*,[ \t]*|[ \t]+")
_INTEGER = re.compile(r"[+-]?[0-9]+")
_REAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_CONTROL = re.compile(rb"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")

_FLOAT32_MAX = 3.4028234663852886e38
_FLOAT32_TINY = 1.1754943508222875e-38

CUBE_FIELDS = ("particle count", "x size", "y size", "z size",
               "centre x", "centre y", "centre z", "maximum radius")


class CubeFileWarning(UserWarning):
    """A suspicious but usable cube file (e.g. a declared total that does not add up)."""


def load_cubes(path: str | os.PathLike, *, max_particles: int = DEFAULT_MAX_PARTICLES) -> CubeFile:
    """Read and check a .awn cube file; raise FishgenError naming FILE:LINE on bad input."""
    name = os.fspath(path)
    try:
        data = Path(path).read_bytes()
    except IsADirectoryError:
        raise FishgenError("expected a cube file, found a directory", name) from None
    except FileNotFoundError:
        raise FishgenError("expected an existing cube file, found no such file", name) from None
    return parse_cubes(data, name, max_particles=max_particles)


def parse_cubes(data: bytes, name: str = "<cubes>", *,
                max_particles: int = DEFAULT_MAX_PARTICLES) -> CubeFile:
    """Parse the bytes of a cube file; ``name`` is used in messages."""
    text = _decode(data, name)
    rows = [(number, line.strip(" \t\r")) for number, line in enumerate(text.split("\n"), 1)]
    rows = [(number, line) for number, line in rows if line]
    if not rows:
        raise expected("the total particle count on line 1", "an empty file", name, 1)

    declared_total = _header(rows[0], "the total particle count", name)
    if declared_total > max_particles:
        raise _over_limit(declared_total, max_particles, name, rows[0][0])
    if len(rows) < 2:
        raise expected("the number of cubes on the next line", "the end of the file",
                       name, rows[0][0] + 1)
    declared_cubes = _header(rows[1], "the number of cubes", name)
    if declared_cubes == 0:
        raise expected("at least 1 cube", "0", name, rows[1][0])

    cube_rows = rows[2:]
    if len(cube_rows) > declared_cubes:
        extra = cube_rows[declared_cubes][0]
        raise expected(f"the end of the file after the {declared_cubes} cubes declared on line "
                       f"{rows[1][0]}", "another cube line", name, extra)
    if len(cube_rows) < declared_cubes:
        last = cube_rows[-1][0] if cube_rows else rows[1][0]
        raise expected(f"{declared_cubes} cube lines (declared on line {rows[1][0]})",
                       f"{len(cube_rows)}", name, last + 1)

    cubes: list[Cube] = []
    running = 0
    for number, line in cube_rows:
        cube = _cube(line, name, number)
        running += cube.particles
        if running > max_particles:
            raise _over_limit(running, max_particles, name, number)
        cubes.append(cube)

    total = sum(cube.particles for cube in cubes)
    if total == 0:
        raise expected("at least 1 particle in the cubes", "0", name, cube_rows[0][0])
    notes: list[str] = []
    if total != declared_total:
        notes.append(f"{name}:{rows[0][0]}: warning: declared total {declared_total} particles, "
                     f"but the cubes hold {total}; using the cubes' counts")
        warnings.warn(notes[-1], CubeFileWarning, stacklevel=3)
    return CubeFile(path=name, declared_total=declared_total, cubes=tuple(cubes),
                    warnings=tuple(notes))


def _decode(data: bytes, name: str) -> str:
    """Text as UTF-8 (ASCII in practice); any control byte or invalid sequence means binary."""
    bad = _CONTROL.search(data)
    try:
        text = data.decode("utf-8-sig")
        position = bad.start() if bad else None
    except UnicodeDecodeError as err:
        position = min(err.start, bad.start()) if bad else err.start
    if position is None:
        return text
    line = data[:position].count(b"\n") + 1
    raise expected("a text cube file", "binary data", name, line)


def _fields(line: str) -> list[str]:
    return _SEPARATOR.split(line)


def _header(row: tuple[int, str], what: str, name: str) -> int:
    number, line = row
    fields = _fields(line)
    if len(fields) != 1:
        raise expected(f"1 field ({what})", f"{len(fields)} fields", name, number)
    return _count(fields[0], what, name, number)


def _count(token: str, what: str, name: str, number: int) -> int:
    if not _INTEGER.fullmatch(token):
        _reject_non_number(token, what, name, number)
        raise expected(f"a whole number for the {what}", describe(token), name, number)
    value = int(token)
    if value < 0:
        raise expected(f"a {what} of 0 or more", describe(token), name, number)
    return value


def _real(token: str, what: str, name: str, number: int, positive: bool) -> float:
    if not _REAL.fullmatch(token):
        _reject_non_number(token, what, name, number)
        raise expected(f"a number for the {what}", describe(token), name, number)
    value = float(token)
    if not math.isfinite(value):  # e.g. 1e999 overflows to infinity
        raise expected(f"a finite number for the {what}", describe(token), name, number)
    if positive and value <= 0:
        raise expected(f"a {what} greater than 0", describe(token), name, number)
    # Particles are stored as float32: values it cannot hold would turn into 0 or infinity.
    if abs(value) > _FLOAT32_MAX or (positive and value < _FLOAT32_TINY):
        raise expected(f"a {what} within float32 range ({_FLOAT32_TINY:.3g} to {_FLOAT32_MAX:.3g})",
                       describe(token), name, number)
    return value


def _reject_non_number(token: str, what: str, name: str, number: int) -> None:
    if token == "":
        raise expected(f"a number for the {what}", "an empty field", name, number)
    try:
        value = float(token)
    except ValueError:
        return
    if not math.isfinite(value):
        raise expected(f"a finite number for the {what}", describe(token), name, number)


def _cube(line: str, name: str, number: int) -> Cube:
    fields = _fields(line)
    if len(fields) != len(CUBE_FIELDS):
        raise expected(f"{len(CUBE_FIELDS)} fields (particles, x y z size, centre x y z, "
                       "maximum radius)", f"{len(fields)}", name, number)
    particles = _count(fields[0], CUBE_FIELDS[0], name, number)
    size = tuple(_real(fields[i], CUBE_FIELDS[i], name, number, True) for i in (1, 2, 3))
    centre = tuple(_real(fields[i], CUBE_FIELDS[i], name, number, False) for i in (4, 5, 6))
    radius = _real(fields[7], CUBE_FIELDS[7], name, number, True)
    return Cube(particles, size, centre, radius, number)  # type: ignore[arg-type]


def _over_limit(count: int, limit: int, name: str, number: int) -> FishgenError:
    return expected(f"at most {limit:,} particles (raise the limit with --max-particles)",
                    f"{count:,}", name, number)
