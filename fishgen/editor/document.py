"""The editor's document: the cubes as the page holds them (JSON), and the cube file text they make.

The page sends its cubes as JSON. :func:`cube_text` writes them in RekAwan's format (``.awn``, or
``.awa`` with each cube's texture name last), the totals of the first two lines computed from the
cubes, each number as the shortest text that reads back as the same double: a file opened from the
report's tables and saved again keeps every cube's values exactly. That text is never trusted:
:func:`read_back` parses it with fishgen's own parser (:func:`fishgen.clouds.parser.parse_cubes`)
and checks it holds what the page sent, before anything is filled or written.

Leaf module: no numpy (the command's ``--help`` imports nothing heavy).
"""
from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fishgen.clouds.model import DEFAULT_MAX_PARTICLES, CubeFile
from fishgen.clouds.parser import MAX_CUBES, over_limit, parse_cubes
from fishgen.errors import FishgenError, describe, expected

PARTICLES = "particles"
TEXTURE = "texture"
MODES = (PARTICLES, TEXTURE)
"""The manual's two systems: "Particle System" (.awn) and "Texture" (.awa)."""
SUFFIX = {PARTICLES: ".awn", TEXTURE: ".awa"}

_KEYS = ("particles", "size", "centre", "radius", "texture")
_TEXTURE_NAME = re.compile(r"[^\s,\x00-\x1f\x7f]+")
"""A texture name is one field of a cube line: no blanks, commas or control characters."""


@dataclass(frozen=True)
class EditCube:
    """One cube as the page edits it: its count (particles, or billboards in texture mode), x/y/z
    size (y up), centre, maximum radius, and in texture mode its texture's name (as the file
    writes it, relative to a texture folder)."""

    particles: int | float
    size: tuple[float, float, float]
    centre: tuple[float, float, float]
    radius: float
    texture: str | None = None

    def json(self) -> dict[str, Any]:
        return {"particles": self.particles, "size": list(self.size), "centre": list(self.centre),
                "radius": self.radius, "texture": self.texture}


def mode_of(path: str | Path) -> str:
    """The system a file's extension means: .awa is Texture, anything else Particle System."""
    return TEXTURE if Path(path).suffix.lower() == SUFFIX[TEXTURE] else PARTICLES


def cubes_from_json(value: Any) -> tuple[EditCube, ...]:
    """The page's cubes, each ``{particles, size: [x, y, z], centre: [x, y, z], radius, texture}``.

    Only the shape is checked here (numbers are JSON numbers, a texture a string): the values are
    the parser's to judge, with their line, once :func:`cube_text` has written them.
    """
    if not isinstance(value, list):
        raise expected("the cubes as a list", _kind(value))
    if len(value) > MAX_CUBES:
        raise expected(f"at most {MAX_CUBES:,} cubes", f"{len(value):,}")
    return tuple(_cube(item, k + 1) for k, item in enumerate(value))


def _cube(item: Any, number: int) -> EditCube:
    if not isinstance(item, dict) or not set(item) <= set(_KEYS) or not set(_KEYS[:4]) <= set(item):
        raise expected(f"cube {number} as {{{', '.join(_KEYS)}}}", _kind(item))
    texture = item.get("texture")
    if texture is not None and not isinstance(texture, str):
        raise expected(f"cube {number}'s texture as a name or null", _kind(texture))
    return EditCube(_number(item["particles"], number, "count"), _triple(item["size"], number, "size"),
                    _triple(item["centre"], number, "centre"), _number(item["radius"], number, "radius"),
                    texture)


def _number(value: Any, number: int, what: str) -> int | float:
    # bool is an int to Python, and a string could smuggle commas or line breaks into the file
    if type(value) not in (int, float):
        raise expected(f"cube {number}'s {what} as a number", _kind(value))
    return value


def _triple(value: Any, number: int, what: str) -> tuple[float, float, float]:
    if not isinstance(value, list) or len(value) != 3:
        raise expected(f"cube {number}'s {what} as three numbers", _kind(value))
    x, y, z = (_number(v, number, what) for v in value)
    return (x, y, z)


def _kind(value: Any) -> str:
    if isinstance(value, (list, dict)):
        return f"a {type(value).__name__} of {len(value)}"
    return describe(repr(value)) if not isinstance(value, str) else f"the text {describe(value)}"


def number_text(value: int | float) -> str:
    """The shortest text that reads back as ``value`` (``1`` for 1.0, ``6.12438e-07``)."""
    if isinstance(value, int):
        return str(value)
    if math.isfinite(value) and value.is_integer() and abs(value) < 1e16:
        return str(int(value))
    return repr(value)  # nan and inf come out as such, for the parser to refuse with their line


def cube_text(cubes: Sequence[EditCube], mode: str, name: str = "<cubes>") -> str:
    """The cube file: total count, number of cubes, then a line per cube (``.awa``: its texture)."""
    if mode not in MODES:
        raise expected(f"the system as one of {', '.join(MODES)}", describe(str(mode)))
    noun = "billboard count" if mode == TEXTURE else "particle count"
    for k, cube in enumerate(cubes):  # the total is theirs: a bad one would be blamed on line 1
        if not (isinstance(cube.particles, int) or float(cube.particles).is_integer()) or cube.particles < 0:
            raise expected(f"a whole number of 0 or more for the {noun}",
                           describe(number_text(cube.particles)), name, k + 3)
    lines = [number_text(sum(c.particles for c in cubes)), str(len(cubes))]
    for k, cube in enumerate(cubes):
        fields = [number_text(cube.particles), *map(number_text, cube.size), *map(number_text, cube.centre),
                  number_text(cube.radius)]
        if mode == TEXTURE:
            if not cube.texture:
                raise expected("a texture for every cube of a texture cloud (Set Texture)", "none",
                               name, k + 3)
            if not _TEXTURE_NAME.fullmatch(cube.texture):
                raise expected("a texture name without blanks or commas", describe(cube.texture), name, k + 3)
            fields.append(cube.texture)
        lines.append(", ".join(fields))
    return "\n".join(lines) + "\n"


Resolver = Callable[[str, int], str]


def texture_resolver(roots: Sequence[Path], name: str) -> Resolver:
    """How a .awa file's texture names resolve, as :func:`fishgen.clouds.parser.load_cubes` does:
    a .png inside one of ``roots``, which must exist and be a readable picture."""
    from fishgen.file_names import resolve_texture

    def resolve(token: str, line: int) -> str:
        if not token.lower().endswith(".png"):
            raise expected("a texture file name ending in .png", describe(token), name, line)
        return str(resolve_texture(token, roots, name, line))

    return resolve


def read_back(text: str, mode: str, name: str, cubes: Sequence[EditCube], *,
              roots: Sequence[Path] = (), max_particles: int = DEFAULT_MAX_PARTICLES) -> CubeFile:
    """Parse ``text`` as fishgen reads a file called ``name`` (its errors are the parser's, with the
    line), and check it holds exactly ``cubes``."""
    # the cube whose count takes the file past the limit, at its line (the total on line 1, which the
    # parser reads first, names no cube the page could select: QA pass 22)
    running = 0
    for k, cube in enumerate(cubes):
        running += int(cube.particles)
        if running > max_particles:
            raise over_limit(running, max_particles, name, k + 3)
    resolver = texture_resolver(roots, name) if mode == TEXTURE else None
    parsed = parse_cubes(text.encode("utf-8"), name, max_particles=max_particles, textures=resolver)
    for cube, got in zip(cubes, parsed.cubes, strict=True):
        if (cube.particles, cube.size, cube.centre, cube.radius) != (got.particles, got.size, got.centre,
                                                                     got.max_radius):
            raise FishgenError(f"expected the text to read back as the cubes it was written from, "
                               f"found {got} for {cube}", name, got.line)
    return parsed


def document_json(cube_file: CubeFile, roots: Sequence[Path]) -> dict[str, Any]:
    """A parsed file as the page holds it: its system, its cubes, and the parser's warnings.

    A .awa file's textures were resolved to absolute paths; each becomes its name in the first
    texture folder holding it again (a name the same parser resolves to the same file).
    """
    mode = mode_of(cube_file.path)
    cubes = [EditCube(c.particles, c.size, c.centre, c.max_radius,
                      texture_name(Path(c.texture), roots) if c.texture else None).json()
             for c in cube_file.cubes]
    return {"mode": mode, "cubes": cubes, "warnings": list(cube_file.warnings)}


def texture_name(path: Path, roots: Sequence[Path]) -> str:
    """``path`` (resolved) as a name relative to the first of ``roots`` that holds it."""
    for root in roots:
        if path.is_relative_to(root):
            return path.relative_to(root).as_posix()
    return path.name
