"""Parser for VRFish species parameter files (thesis Appendix A).

Lines starting with ``//`` are whole-line comments; records come in a fixed
order, one record per line. Every fault is a :class:`FishgenError` reading
``FILE:LINE: expected ..., found ...``.
"""
from __future__ import annotations

import math
import os
import re
import stat
import unicodedata
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import NamedTuple

from fishgen.errors import FishgenError, describe, plural
from fishgen.file_names import resolve_texture
from fishgen.reading import read_capped
from fishgen.shape_names import SHAPE_NAMES, check_shape_params, shape_params_found
from fishgen.species.model import (
    METRES_PER_WORLD_UNIT,
    Behaviour,
    CaudalFin,
    PectoralFin,
    PelvicFin,
    Species,
    TexturePoints,
    Vec2,
    Vec3,
    VerticalFin,
)

#: Largest level of detail accepted; refused before anything is allocated.
MAX_SECTIONS = 1024
MAX_SPECIES_FILE_BYTES = 64 * 1024 * 1024  # a 1024 x 1024 body with texture points is ~40 MiB
#: No value in a species file is meaningful beyond this; larger ones would overflow
#: float32 geometry long before anything is drawn.
MAX_MAGNITUDE = 1e6
MAX_WORLD_SCALE = 1e4
MAX_SCALE = 100.0
MIN_LENGTH = 0.001
"""Shortest body, metres (world_scale x METRES_PER_WORLD_UNIT x scaleX), as `--length`'s floor:
a world_scale of 1e-300 built a fish of zero size (float32 zeros) and exited 0."""
MIN_ASPECT = 1e-3
"""scaleY and scaleZ against scaleX: a body 1,000 times longer than it is tall or wide is a line."""
MAX_FIN_LENGTH = 100.0
MAX_LINE_CHARS = 65536
"""Longest record line: a spline of 2,048 control points fits; a 60 MB line is refused unsplit."""


class _Line(NamedTuple):
    number: int
    text: str

    @property
    def tokens(self) -> list[str]:
        return self.text.split()


class _Reader:
    """Walks the meaningful (non-comment, non-blank) lines of a species file."""

    def __init__(self, text: str, file: str):
        self.file = file
        # Only \n, \r\n and \r end a line: str.splitlines() would also split on form
        # feeds and U+2028 inside comments, and the line numbers would drift.
        text = text.removeprefix("\ufeff")  # a byte-order mark, as Windows editors write it
        raw_lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
        self.lines = [_Line(n, raw.strip()) for n, raw in enumerate(raw_lines, 1)
                      if raw.strip() and not raw.lstrip().startswith("//")]
        self.pos = 0
        self.record_lines: dict[str, int] = {}
        self.last_line = len(raw_lines)

    def peek(self) -> _Line | None:
        return self.lines[self.pos] if self.pos < len(self.lines) else None

    def error(self, line: _Line | None, what: str, found: str) -> FishgenError:
        number = line.number if line else self.last_line
        return FishgenError(f"expected {what}, found {found}", self.file, number)

    def record(self, what: str, count: int | None = None, at_least: int | None = None,
               key: str | None = None) -> _Line:
        line = self.peek()
        if line is None:
            raise self.error(None, what, "end of file (the file is truncated)")
        self.pos += 1
        if len(line.text) > MAX_LINE_CHARS:  # before splitting it into millions of tokens
            raise self.error(line, f"{what} on a line of at most {MAX_LINE_CHARS} characters",
                             f"{len(line.text):,} characters")
        n = len(line.tokens)
        if (count is not None and n != count) or (at_least is not None and n < at_least):
            wanted = f"{count}" if count is not None else f"at least {at_least}"
            raise self.error(line, f"{what} ({wanted} values)", _found_values(line))
        if key is not None:
            self.record_lines[key] = line.number
        return line


def _hint(token: str) -> str:
    odd = [c for c in token if ord(c) > 127 or not c.isprintable()]
    if odd:
        c = odd[0]
        name = unicodedata.name(c, "unnamed character")
        return f" (U+{ord(c):04X} {name}: a misprinted digit?)"
    if token[:1].isalpha() and len(token) > 1 and token.lower() not in _NOT_WORDS:
        return " (a wrapped comment line? every comment line must start with //)"
    return ""


_NOT_WORDS = {"nan", "inf", "infinity", "true", "false", "yes", "no"}


def _found_values(line: _Line) -> str:
    tokens = line.tokens
    shown = " ".join(tokens)
    if len(shown) > 48:
        shown = shown[:47] + "…"
    non_numeric = next((t for t in tokens if not _is_number(t)), None)
    hint = _hint(non_numeric) if non_numeric is not None else ""
    return f"{plural(len(tokens), 'value')} {shown!r}{hint}"


# The number forms the thesis' files use, ASCII only: Python's float() also takes "1_0.0",
# full-width digits ("８") and "nan", which a species file never holds (as the cube parser does).
_REAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_BLOCK = re.compile(r"[0-9eE+\-. ]*")


def _real(token: str) -> float | None:
    """The number a token writes in the file's number forms, else None."""
    return float(token) if _REAL.fullmatch(token) else None


def _is_number(token: str) -> bool:
    value = _real(token)
    return value is not None and math.isfinite(value)


class _Fields:
    """Typed access to the tokens of one record, with errors pointing at the line."""

    def __init__(self, reader: _Reader, line: _Line, names: Sequence[str]):
        self.reader, self.line, self.names = reader, line, names
        self.tokens = line.tokens

    def _fail(self, i: int, what: str) -> FishgenError:
        token = self.tokens[i]
        return self.reader.error(self.line, f"{self.names[i]} as {what}", f"{describe(token)}{_hint(token)}")

    def number(self, i: int, low: float = -MAX_MAGNITUDE, high: float = MAX_MAGNITUDE,
               open_low: bool = False) -> float:
        value = _real(self.tokens[i])
        if value is None:
            raise self._fail(i, "a finite number" if self.tokens[i].lower() in _NOT_WORDS else "a number")
        if not math.isfinite(value):
            raise self._fail(i, "a finite number")
        if value < low or (open_low and value == low) or value > high:
            lo = f"> {low:g}" if open_low else f">= {low:g}"
            raise self._fail(i, f"a number {lo} and <= {high:g}")
        return value

    def whole(self, i: int, low: int = 0, high: int | None = None, what: str = "a whole number") -> int:
        # the range is said either way: "16.5" for BodySections needs it as much as "2" does
        rng = f"from {low} to {high}" if high is not None else f"of {low} or more"
        expected = f"{what} {rng}" if what == "a whole number" else f"{what}, {rng}"
        value = _real(self.tokens[i])
        if value is None or not math.isfinite(value) or value != int(value):
            raise self._fail(i, expected)
        value = int(value)
        if value < low or (high is not None and value > high):
            raise self._fail(i, expected)
        return value

    def flag(self, i: int) -> bool:
        token = self.tokens[i].lower()
        if token not in ("true", "false"):
            raise self._fail(i, "true or false")
        return token == "true"

    def vec(self, i: int, n: int) -> tuple[float, ...]:
        return tuple(self.number(i + k) for k in range(n))

    def vec2(self, i: int) -> Vec2:
        return self.number(i), self.number(i + 1)

    def vec3(self, i: int, low: float = -MAX_MAGNITUDE, high: float = MAX_MAGNITUDE,
             open_low: bool = False) -> Vec3:
        return (self.number(i, low, high, open_low), self.number(i + 1, low, high, open_low),
                self.number(i + 2, low, high, open_low))


# Record names as the thesis' comments give them.
HEADER = ("name", "world_scale", "urgeFactor", "start x", "start y", "start z", "cube_size")
SHAPE = ("fishshape_subclass", "BodySections", "CircleSections", "textured", "masked",
         "turn_T", "catchfish_T")
CAUDAL = ("top_line", "middle_line", "top_angle", "no_of_top_triangles", "connection x",
          "connection y", "connection z", "rotation_angle", "bottom_line", "bottom_angle",
          "no_of_bottom_triangles", "movement_angle", "step_size")
VERTICAL = ("startBodySection", "endBodySection", "startLength", "endLength",
            "startangle_in_degrees", "proportion")
PELVIC = ("startCircleSection", "startBodySection", "endBodySection", "start_length",
          "end_length", "end_angle", "movement_angle", "step_size")
PECTORAL = ("startBodySection", "startCircleSection", "no_of_triangles", "startLength",
            "startAngle", "proportion", "version_t", "movement_angle", "step_size")
URGES = ("random", "center", "keepaway", "repelDistance", "speed", "changeRate", "direction")


def _vertical(reader: _Reader, label: str, bodies: int) -> VerticalFin:
    line = reader.record(f"the {label} record `{' '.join(VERTICAL)}`", 6)
    f = _Fields(reader, line, [f"{label} {n}" for n in VERTICAL])
    start = f.whole(0, 0, bodies - 2, "a BodySection number before the last")
    # a fin needs two base points along the body: one section alone is a line, not a fin
    end = f.whole(1, start + 1, bodies - 1, f"a BodySection number after startBodySection {start}")
    return VerticalFin(start, end, f.number(2, 0, MAX_FIN_LENGTH), f.number(3, 0, MAX_FIN_LENGTH),
                       f.number(4, -180, 180), f.number(5, 0, 1))


def _points(reader: _Reader, label: str, expected: int, why: str) -> tuple[tuple[float, float], ...]:
    line = reader.record(f"the number of {label} texture points", 1)
    f = _Fields(reader, line, [f"number of {label} texture points"])
    count = f.whole(0, 0, None, "a whole number")
    if count != expected:
        raise reader.error(line, f"{expected} {label} texture points ({why})", f"{count}")
    points = []
    for _ in range(count):
        pl = reader.record(f"a {label} texture point `u v`", 2)
        pf = _Fields(reader, pl, ("u", "v"))
        points.append((pf.number(0, 0, 1), pf.number(1, 0, 1)))
    return tuple(points)


def _body_points(reader: _Reader, bodies: int, circles: int) -> tuple[tuple[float, float], ...]:
    line = reader.record("the number of body texture points", 1)
    f = _Fields(reader, line, ["number_of_points_body_points"])
    count = f.whole(0, 0, None, "a whole number")
    if count != bodies * circles:
        raise reader.error(line, f"{bodies * circles} body texture points "
                           f"(BodySections {bodies} x CircleSections {circles})", f"{count}")
    fast = _body_points_fast(reader, bodies, circles)
    if fast is not None:
        return fast
    points = []
    for j in range(bodies):
        for i in range(circles):
            pl = reader.record(f"body texture point `{j} {i} u v`", 4)
            pf = _Fields(reader, pl, ("bodySection_no", "circleSection_no", "u", "v"))
            if pf.whole(0) != j or pf.whole(1) != i:
                raise reader.error(pl, f"body texture point for section {j}, circle {i}",
                                   f"section {pl.tokens[0]}, circle {pl.tokens[1]}")
            points.append((pf.number(2, 0, 1), pf.number(3, 0, 1)))
    return tuple(points)


def _body_points_fast(reader: _Reader, bodies: int, circles: int):
    """Parse a well-formed block of body points in one numpy pass (a 1024 x 1024 body
    has a million lines). Returns None if anything is off, so the line-by-line path
    can find the first bad line and report it."""
    import numpy as np

    n = bodies * circles
    block = reader.lines[reader.pos:reader.pos + n]
    if len(block) < n:
        return None
    joined = " ".join(line.text for line in block)
    if not _BLOCK.fullmatch(joined):  # numpy reads "1_0" and full-width digits too: the slow path says where
        return None
    try:
        values = np.array(joined.split(), dtype=np.float64)
    except ValueError:
        return None
    if values.size != 4 * n:
        return None
    values = values.reshape(n, 4)
    k = np.arange(n)
    if not (np.array_equal(values[:, 0], k // circles) and np.array_equal(values[:, 1], k % circles)):
        return None
    uv = values[:, 2:]
    if not (np.all(np.isfinite(uv)) and uv.min() >= 0 and uv.max() <= 1):
        return None
    if any(len(line.text.split()) != 4 for line in block):   # a record is one line
        return None
    reader.pos += n
    return tuple(map(tuple, uv.tolist()))


def parse_species(text: str, file: str | os.PathLike = "<species>",
                  textures: Callable[[str, _Line], Path] | None = None) -> Species:
    """Parse species-file text. ``textures`` resolves a texture name (see :func:`load_species`)."""
    file = os.fspath(file)
    reader = _Reader(text, file)
    if reader.peek() is None:
        raise FishgenError("expected a VRFish species file, found "
                           + ("an empty file" if not text.strip() else "only comments"), file, 1)

    first = reader.peek()
    header_like = (len(line.tokens) == 7 and all(_is_number(t) for t in line.tokens[1:])
                   for line in reader.lines[reader.pos:reader.pos + 50])
    if first is not None and sum(_is_number(t) for t in first.tokens[1:7]) < 4 and not any(header_like):
        # No species header anywhere near the top: not a species file at all (a scene file may name
        # any file, /etc/passwd say), so say so without echoing a line of it.
        numbers = sum(_is_number(t) for t in first.tokens)
        raise reader.error(first, f"the header record `{' '.join(HEADER)}` of a VRFish species file",
                           f"a first record that is not one ({numbers} numbers where 6 stand)")
    line = reader.record(f"the header record `{' '.join(HEADER)}`", 7)
    f = _Fields(reader, line, HEADER)
    name = line.tokens[0]
    world_scale = f.number(1, 0, MAX_WORLD_SCALE, open_low=True)
    urge = f.number(2)
    start = f.vec3(3)
    cube = f.number(6)

    line = reader.record("the fish colour record `R G B`", 3)
    f = _Fields(reader, line, ("red", "green", "blue"))
    colour = (f.number(0, 0, 1), f.number(1, 0, 1), f.number(2, 0, 1))

    line = reader.record(f"the shape record `{' '.join(SHAPE)}`", at_least=7, key="shape")
    f = _Fields(reader, line, SHAPE + tuple(f"shape parameter {k + 1}" for k in range(len(line.tokens))))
    shape_class = line.tokens[0]
    if shape_class not in SHAPE_NAMES:
        raise reader.error(line, "a shape class (one of " + ", ".join(sorted(SHAPE_NAMES)) + ")",
                           f"{shape_class!r}")
    bodies = f.whole(1, 3, MAX_SECTIONS)
    circles = f.whole(2, 3, MAX_SECTIONS)
    textured, masked, turn, catch = (f.flag(k) for k in range(3, 7))
    shape_params = tuple(f.number(k) for k in range(7, len(line.tokens)))
    problem = check_shape_params(shape_class, shape_params)
    if problem:
        raise reader.error(line, problem, shape_params_found(shape_class, shape_params))

    line = reader.record("the body scale record `scaleX scaleY scaleZ`", 3)
    f = _Fields(reader, line, ("scaleX", "scaleY", "scaleZ"))
    scale = f.vec3(0, 0, MAX_SCALE, open_low=True)
    long = world_scale * METRES_PER_WORLD_UNIT * scale[0]
    if long < MIN_LENGTH:
        raise reader.error(line, f"a body at least {MIN_LENGTH:g} m long (world_scale x "
                                 f"{METRES_PER_WORLD_UNIT:g} m x scaleX)",
                           f"{world_scale:g} x {METRES_PER_WORLD_UNIT:g} m x {scale[0]:g} = {long:.3g} m")
    for k in (1, 2):
        if scale[k] < MIN_ASPECT * scale[0]:
            raise f._fail(k, f"a number at least {MIN_ASPECT:g} x scaleX ({MIN_ASPECT * scale[0]:.3g})")

    line = reader.record("the caudal fin record", 13, key="caudal")
    f = _Fields(reader, line, [f"caudal {n}" for n in CAUDAL])
    caudal = CaudalFin(
        top_line=f.number(0, 0, MAX_FIN_LENGTH), middle_line=f.number(1, 0, MAX_FIN_LENGTH),
        top_angle=f.number(2, -180, 180),
        top_triangles=f.whole(3, 1, 256, "a number of triangles"),
        connection=(f.number(4, 0, 1), f.number(5, -1, 1), f.number(6, -1, 1)),
        rotation_angle=f.number(7, -180, 180),
        bottom_line=f.number(8, 0, MAX_FIN_LENGTH), bottom_angle=f.number(9, -180, 180),
        bottom_triangles=f.whole(10, 1, 256, "a number of triangles"),
        movement_angle=f.number(11, 0, 90), step_size=f.number(12, 0))
    _check_motion(reader, line, f, 11, 12)

    adipose = _vertical(reader, "adipose fin", bodies)
    dorsal = _vertical(reader, "dorsal fin", bodies)

    line = reader.record(f"the pelvic fin record `{' '.join(PELVIC)}`", 8, key="pelvic")
    f = _Fields(reader, line, [f"pelvic {n}" for n in PELVIC])
    p_circle = f.whole(0, 0, circles - 1, "a CircleSection number")
    p_start = f.whole(1, 0, bodies - 2, "a BodySection number before the last")
    p_end = f.whole(2, p_start + 1, bodies - 1, f"a BodySection number after startBodySection {p_start}")
    pelvic = PelvicFin(p_circle, p_start, p_end, f.number(3, 0, MAX_FIN_LENGTH),
                       f.number(4, 0, MAX_FIN_LENGTH), f.number(5, -180, 180),
                       f.number(6, 0, 90), f.number(7, 0))
    _check_motion(reader, line, f, 6, 7)

    anal = _vertical(reader, "anal fin", bodies)

    line = reader.record(f"the pectoral fin record `{' '.join(PECTORAL)}`", 9, key="pectoral")
    f = _Fields(reader, line, [f"pectoral {n}" for n in PECTORAL])
    pectoral = PectoralFin(
        start_section=f.whole(0, 0, bodies - 1, "a BodySection number"),
        start_circle=f.whole(1, 0, circles - 1, "a CircleSection number"),
        triangles=f.whole(2, 1, circles - 1, "a number of triangles (each spans one CircleSection)"),
        start_length=f.number(3, 0, MAX_FIN_LENGTH), start_angle=f.number(4, -180, 180),
        proportion=f.number(5, 0, 1),
        version=f.number(6), movement_angle=f.number(7, 0, 90), step_size=f.number(8, 0))
    _check_motion(reader, line, f, 7, 8)

    colour_tex = mask_tex = None
    points = None
    transparency = 1.0
    nxt = reader.peek()
    has_texture_block = textured or (nxt is not None and len(nxt.tokens) == 2
                                     and not _is_number(nxt.tokens[0]))
    if has_texture_block:
        line = reader.record("the texture record `texture_file black_and_white_file`", 2, key="texture")
        if textured and textures is not None:
            colour_tex = textures(line.tokens[0], line)
            mask_tex = textures(line.tokens[1], line)
        body = _body_points(reader, bodies, circles)
        caudal_pts = _points(reader, "caudal fin", caudal.texture_point_count,
                             f"1 + (top triangles {caudal.top_triangles} + 1) + "
                             f"(bottom triangles {caudal.bottom_triangles} + 1)")
        line = reader.record("the fin transparency", 1)
        transparency = _Fields(reader, line, ("transparency_t",)).number(0, 0, 1)
        span = "2 x (endBodySection {e} - startBodySection {s} + 1)"
        dorsal_pts = _points(reader, "dorsal fin", dorsal.texture_point_count,
                             span.format(e=dorsal.end_section, s=dorsal.start_section))
        adipose_pts = _points(reader, "adipose fin", adipose.texture_point_count,
                              span.format(e=adipose.end_section, s=adipose.start_section))
        anal_pts = _points(reader, "anal fin", anal.texture_point_count,
                           span.format(e=anal.end_section, s=anal.start_section))
        pectoral_pts = _points(reader, "pectoral fin", pectoral.texture_point_count,
                               f"2 x triangles {pectoral.triangles} + 1")
        pelvic_pts = _points(reader, "pelvic fin", pelvic.texture_point_count,
                             span.format(e=pelvic.end_section, s=pelvic.start_section))
        points = TexturePoints(body, caudal_pts, dorsal_pts, adipose_pts, anal_pts, pectoral_pts,
                               pelvic_pts)
        if not textured:
            points = None

    line = reader.record("the initial velocity record `vx vy vz`", 3)
    velocity = _Fields(reader, line, ("vx", "vy", "vz")).vec3(0)
    line = reader.record(f"the urge weightings record `{' '.join(URGES)}`", 7)
    random, center, keepaway, repel_distance, speed, change_rate, direction = \
        _Fields(reader, line, URGES).vec(0, 7)
    line = reader.record("the flee record", 2)
    flee = _Fields(reader, line, ("flee 1", "flee 2")).vec2(0)
    extra = reader.peek()
    if extra is not None:
        raise reader.error(extra, "end of file after the flee record", _found_values(extra))

    return Species(
        name=name, world_scale=world_scale, urge_factor=urge, start_position=start, cube_size=cube,
        colour=colour, shape_class=shape_class, shape_params=shape_params, body_sections=bodies,
        circle_sections=circles, textured=textured, masked=masked, turn_test=turn,
        catchfish_test=catch, scale=scale, caudal=caudal, adipose=adipose, dorsal=dorsal,
        pelvic=pelvic, anal=anal, pectoral=pectoral, transparency=transparency,
        colour_texture=colour_tex, mask_texture=mask_tex, texture_points=points,
        behaviour=Behaviour(velocity, random, center, keepaway, repel_distance, speed, change_rate,
                            direction, flee), source=Path(file),
        record_lines=dict(reader.record_lines))


def _check_motion(reader: _Reader, line: _Line, f: _Fields, angle: int, step: int) -> None:
    if float(f.tokens[angle]) > 0 and float(f.tokens[step]) <= 0:  # both checked numbers above
        raise f._fail(step, "a step size > 0 (the fin has a movement angle)")


def texture_roots(species_path: Path, textures_dir: str | os.PathLike | None) -> list[Path]:
    """Folders a species file may read textures from: ``--textures DIR``, or else the
    species file's folder and the ``textures/`` folder beside it."""
    if textures_dir is not None:  # named by the user: followed wherever it points
        return [Path(textures_dir).resolve()]
    here = species_path.resolve().parent
    textures = here.parent / "textures"
    # The same rule as an asset's side files: a link may not lead out of the folders fishgen was
    # given. The implicit textures/ folder is used only if it really lies beside the species folder.
    if textures.resolve().is_relative_to(here.parent):
        return [here, textures.resolve()]
    return [here]


def load_species(path: str | os.PathLike, textures_dir: str | os.PathLike | None = None, *,
                 textures_needed: bool = True) -> Species:
    """Read and check a species file; texture files are resolved and must exist, unless
    ``textures_needed`` is false (only the geometry is wanted: a missing texture is then named
    where the species file's folder would hold it)."""
    path = Path(path)
    file = os.fspath(path)
    try:
        mode = path.stat().st_mode
        if not stat.S_ISREG(mode):
            kind = "a directory" if stat.S_ISDIR(mode) else "a device, pipe or other special file"
            raise FishgenError(f"expected a regular species file, found {kind}", file)
        with path.open("rb") as handle:
            data = read_capped(handle, MAX_SPECIES_FILE_BYTES)
        if len(data) > MAX_SPECIES_FILE_BYTES:
            raise FishgenError(f"expected a species file of at most {MAX_SPECIES_FILE_BYTES} bytes, "
                               "found a larger file", file, 1)
    except FileNotFoundError:
        raise FishgenError("expected a species file, found no such file", file) from None
    except IsADirectoryError:
        raise FishgenError("expected a species file, found a directory", file) from None
    if b"\0" in data:
        raise FishgenError("expected a text species file, found binary data", file,
                           data[: data.index(b"\0")].count(b"\n") + 1)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise FishgenError("expected a UTF-8 text species file, found binary data", file,
                           data[: err.start].count(b"\n") + 1) from None
    roots = texture_roots(path, textures_dir)

    def resolve(name: str, line: _Line) -> Path:
        try:
            return resolve_texture(name, roots, file, line.number)
        except FishgenError:
            if textures_needed:
                raise
            return path.parent / name

    return parse_species(text, file, resolve)
