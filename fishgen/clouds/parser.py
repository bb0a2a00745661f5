"""Parser for RekAwan cloud cube files (.awn, report section 4.3.4) and texture cloud files (.awa).

Line 1 holds the total particle count, line 2 the cube count, then one line per
cube: ``particles, x size, y size, z size, centre x, centre y, centre z, max
radius``. Fields are separated by commas and/or white space, because the
editor's own Table 4.3 has a line with a missing comma. Blank lines are skipped
but still counted, so messages point at the real line.

A texture cloud file (.awa, the editor's texture mode; docs/clouds.md) is the same with
billboards for particles ("Billboards per Box") and a ninth field on each cube line: the
PNG its billboards carry, found in the file's folder or the ``textures/`` folder beside it.
"""
from __future__ import annotations

import math
import os
import re
import stat
import warnings
from collections.abc import Callable
from pathlib import Path

from fishgen.clouds.model import DEFAULT_MAX_PARTICLES, Cube, CubeFile
from fishgen.errors import FishgenError, describe, expected, plural

# ASCII-only patterns: "１２" (full-width digits) or "1_000" are not numbers in this format.
_SEPARATOR = re.compile(r"[ \t]*,[ \t]*|[ \t]+")
_INTEGER = re.compile(r"[+-]?[0-9]+")
_REAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_CONTROL = re.compile(rb"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")
_LINE_END = re.compile(r"\r\n|\r|\n")  # Unix, Windows and old Mac files alike
_LINE_END_BYTES = re.compile(rb"\r\n|\r|\n")

MAX_FILE_BYTES = 16 << 20
"""A cube file is a few KB; refuse anything bigger before reading it all. (64 MiB of minimal
cube lines took 63 s and 3 GB to parse, so the cap is 16 MiB, with MAX_CUBES below.)"""
MAX_CUBES = 100_000
"""The editor's files hold tens of cubes; more is refused at line 2, before any cube is parsed."""
MAX_DIGITS = 18
"""Longer whole numbers are far beyond any particle limit (and int() refuses > 4300 digits)."""

_FLOAT32_MAX = 3.4028234663852886e38
_FLOAT32_TINY = 1.1754943508222875e-38

CUBE_FIELDS = ("particle count", "x size", "y size", "z size",
               "centre x", "centre y", "centre z", "maximum radius")


class CubeFileWarning(UserWarning):
    """A suspicious but usable cube file (e.g. a declared total that does not add up)."""


def load_cubes(path: str | os.PathLike, *, max_particles: int = DEFAULT_MAX_PARTICLES,
               textures_dir: str | os.PathLike | None = None, raise_with: str | None = None) -> CubeFile:
    """Read and check a .awn cube file, or a .awa texture cloud file (by its extension);
    raise FishgenError naming FILE:LINE on bad input. ``raise_with``: the option that raises
    ``max_particles``, named when the limit is met (only a command that has one).

    A .awa file's textures are resolved in ``textures_dir`` if given, else in the file's
    folder and the ``textures/`` folder beside it (``texture_roots``), and must exist.
    """
    name = os.fspath(path)
    data = _read_capped(name)
    if name.lower().endswith(TEXTURE_SUFFIX):
        roots = texture_roots(Path(name), textures_dir)
        return parse_cubes(data, name, max_particles=max_particles, raise_with=raise_with,
                           textures=lambda texture, number: _texture(texture, roots, name, number))
    return parse_cubes(data, name, max_particles=max_particles, raise_with=raise_with)


TEXTURE_SUFFIX = ".awa"


def texture_roots(path: Path, textures_dir: str | os.PathLike | None = None) -> list[Path]:
    """Folders a .awa file may read textures from: ``textures_dir`` if given; else its own folder
    and the ``textures/`` folder beside it, as a species file's (fishgen.species.parser), or,
    for a file one folder deeper (params/clouds/sky.awa), the one beside that folder's parent."""
    if textures_dir is not None:
        return [Path(textures_dir).resolve()]
    here = path.resolve().parent
    for level in (here.parent, here.parent.parent):
        candidate = level / "textures"
        # as for species: only a textures/ folder that really lies there, not a link elsewhere
        if candidate.is_dir() and candidate.resolve().is_relative_to(level):
            return [here, candidate.resolve()]
    return [here]


def _texture(token: str, roots: list[Path], name: str, number: int) -> str:
    from fishgen.file_names import resolve_texture

    if not token.lower().endswith(".png"):
        raise expected("a texture file name ending in .png", describe(token), name, number)
    return str(resolve_texture(token, roots, name, number))


def _read_capped(name: str) -> bytes:
    """The file's bytes: only a regular file, and at most MAX_FILE_BYTES of it.

    Devices (/dev/zero), FIFOs and sockets never end or block, so they are refused
    by fstat before any read; O_NONBLOCK keeps opening a FIFO from waiting for a writer.
    At most MAX_FILE_BYTES + 1 bytes are read, so a growing file cannot eat memory.
    """
    try:
        fd = os.open(name, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except (FileNotFoundError, NotADirectoryError):
        raise FishgenError("expected an existing cube file, found no such file", name) from None
    except IsADirectoryError:
        raise FishgenError("expected a cube file, found a directory", name) from None
    except OSError as err:
        raise FishgenError(f"expected a readable cube file, found {_reason(err)}", name) from None
    try:
        mode = os.fstat(fd).st_mode
    except OSError:
        os.close(fd)
        raise
    if not stat.S_ISREG(mode):
        os.close(fd)
        raise FishgenError(f"expected a cube file, found {_file_kind(mode)}", name)
    with os.fdopen(fd, "rb", buffering=0) as handle:
        chunks, left = [], MAX_FILE_BYTES + 1
        try:
            while left > 0:
                chunk = handle.read(min(left, 1 << 20))
                if not chunk:
                    break
                chunks.append(chunk)
                left -= len(chunk)
        except OSError as err:
            raise FishgenError(f"expected a readable cube file, found {_reason(err)}", name) from None
    data = b"".join(chunks)
    if len(data) > MAX_FILE_BYTES:
        raise FishgenError(f"expected a cube file of at most {MAX_FILE_BYTES >> 20} MiB "
                           "(a cube file is a few KB), found a larger file", name)
    return data


def _file_kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISFIFO(mode):
        return "a pipe (FIFO)"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "a special file"


def _reason(err: OSError) -> str:
    return (err.strerror or type(err).__name__).lower()


def parse_cubes(data: bytes, name: str = "<cubes>", *,
                max_particles: int = DEFAULT_MAX_PARTICLES,
                textures: Callable[[str, int], str] | None = None, raise_with: str | None = None) -> CubeFile:
    """Parse the bytes of a cube file; ``name`` is used in messages. With ``textures`` (a .awa
    file) each cube line ends with a texture name, which ``textures(name, line)`` resolves.
    ``raise_with`` names the option that raises ``max_particles``, if the caller has one."""
    text = _decode(data, name)
    rows = [(number, row) for number, line in enumerate(_LINE_END.split(text), 1)
            if (row := line.strip(" \t"))]
    noun = "particle" if textures is None else "billboard"
    if not rows:
        raise expected(f"the total {noun} count on line 1", "an empty file", name, 1)

    declared_total = _header(rows[0], f"total {noun} count", name)
    if declared_total > max_particles:
        raise over_limit(declared_total, max_particles, name, rows[0][0], raise_with)
    if len(rows) < 2:
        raise expected("the number of cubes on the next line", "the end of the file",
                       name, rows[0][0] + 1)
    declared_cubes = _header(rows[1], "number of cubes", name)
    if declared_cubes == 0:
        raise expected("at least 1 cube", "0", name, rows[1][0])
    if declared_cubes > MAX_CUBES:
        raise expected(f"at most {MAX_CUBES:,} cubes", f"{declared_cubes:,}", name, rows[1][0])

    cube_rows = rows[2:]
    if len(cube_rows) > declared_cubes:
        extra = cube_rows[declared_cubes][0]
        raise expected(f"the end of the file after the {plural(declared_cubes, 'cube')} declared on line "
                       f"{rows[1][0]}", "another cube line", name, extra)
    if len(cube_rows) < declared_cubes:
        last = cube_rows[-1][0] if cube_rows else rows[1][0]
        raise expected(f"{plural(declared_cubes, 'cube line')} (declared on line {rows[1][0]})",
                       f"{len(cube_rows)}", name, last + 1)

    cubes: list[Cube] = []
    running = 0
    for number, line in cube_rows:
        cube = _cube(line, name, number, textures)
        running += cube.particles
        if running > max_particles:
            raise over_limit(running, max_particles, name, number, raise_with)
        cubes.append(cube)

    total = sum(cube.particles for cube in cubes)
    if total == 0:  # a total of 0 is where it starts; else the cubes' counts, which are used, are wrong
        raise expected(f"at least 1 {noun} in the cubes", "0", name,
                       rows[0][0] if declared_total == 0 else cube_rows[0][0])
    notes: list[str] = []
    if total != declared_total:
        notes.append(f"{name}:{rows[0][0]}: warning: declared total {plural(declared_total, noun)}, "
                     f"but the cubes hold {total:,}; using the cubes' counts")
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
    line = len(_LINE_END_BYTES.findall(data, 0, position)) + 1
    raise expected("a text cube file", "binary data", name, line)


def _fields(line: str) -> list[str]:
    return _SEPARATOR.split(line)


def _header(row: tuple[int, str], what: str, name: str) -> int:
    number, line = row
    fields = _fields(line)
    if len(fields) != 1:
        raise expected(f"1 field (the {what})", f"{len(fields)} fields", name, number)
    return _count(fields[0], what, name, number)


def _count(token: str, what: str, name: str, number: int) -> int:
    """A whole number of 0 or more; ``what`` has no article ("particle count")."""
    if token == "":
        raise expected(f"a whole number for the {what}", "an empty field", name, number)
    if not _INTEGER.fullmatch(token):
        raise expected(f"a whole number for the {what}", describe(token), name, number)
    negative = token.startswith("-") and token.strip("+-0") != ""
    if negative:
        raise expected(f"a whole number of 0 or more for the {what}", describe(token), name, number)
    digits = token.lstrip("+-").lstrip("0")
    if len(digits) > MAX_DIGITS:  # int() would refuse 4300+ digits; no limit is this large
        raise expected(f"a whole number of at most {MAX_DIGITS} digits for the {what}",
                       f"a number with {len(digits):,} digits", name, number)
    return int(digits or "0")


def _real(token: str, what: str, name: str, number: int, positive: bool) -> float:
    if not _REAL.fullmatch(token):
        _reject_non_number(token, what, name, number)
        raise expected(f"a number for the {what}", describe(token), name, number)
    value = float(token)
    article = "an" if what.startswith(("x ", "a", "e", "i", "o", "u")) else "a"  # an x size
    if not math.isfinite(value):  # e.g. 1e999 overflows to infinity
        raise expected(f"a finite number for the {what}", describe(token), name, number)
    if positive and value <= 0:
        raise expected(f"{article} {what} greater than 0", describe(token), name, number)
    # Particles are stored as float32: values it cannot hold would turn into 0 or infinity.
    if abs(value) > _FLOAT32_MAX or (positive and value < _FLOAT32_TINY):
        low = f"{_FLOAT32_TINY:.3g}" if positive else f"{-_FLOAT32_MAX:.3g}"
        raise expected(f"{article} {what} within float32 range ({low} to {_FLOAT32_MAX:.3g})",
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


def _cube(line: str, name: str, number: int, textures: Callable[[str, int], str] | None = None) -> Cube:
    fields = _fields(line)
    if textures is None and len(fields) != len(CUBE_FIELDS):
        raise expected(f"{len(CUBE_FIELDS)} fields (particles, x y z size, centre x y z, "
                       "maximum radius)", f"{len(fields)} fields", name, number)
    if textures is not None and len(fields) != len(CUBE_FIELDS) + 1:
        raise expected(f"{len(CUBE_FIELDS) + 1} fields (billboards, x y z size, centre x y z, "
                       "maximum radius, texture)", f"{len(fields)} fields", name, number)
    what = CUBE_FIELDS[0] if textures is None else "billboard count"
    particles = _count(fields[0], what, name, number)
    size = tuple(_real(fields[i], CUBE_FIELDS[i], name, number, True) for i in (1, 2, 3))
    centre = tuple(_real(fields[i], CUBE_FIELDS[i], name, number, False) for i in (4, 5, 6))
    radius = _real(fields[7], CUBE_FIELDS[7], name, number, True)
    texture = textures(fields[8], number) if textures is not None else None
    return Cube(particles, size, centre, radius, number, texture)  # type: ignore[arg-type]


def over_limit(count: int, limit: int, name: str, number: int, raise_with: str | None = None) -> FishgenError:
    """More particles than ``limit``, said at line ``number`` of ``name``."""
    hint = f" (raise the limit with {raise_with})" if raise_with else ""
    return expected(f"at most {limit:,} particles{hint}", f"{count:,}", name, number)
