"""Fixel's .FXL point files (thesis 6 and B.10).

Each part is a ``//name`` comment line, a count line, then one point per line:
``u v`` for fins and, for the body, ``section circle u v`` (the vertical line
and point numbers precede the coordinates, as chapter 6 says). Coordinates are
Fixel's: x / width and y / height of the upright picture, exactly what a
species file's texture record holds. Parts may be missing (Fixel's stages are
optional) and come in any order. The printed sample's first line runs the
header, count and first points together (an OCR join); the reader accepts a
part's tokens across lines for that reason.
"""
from __future__ import annotations

import os
import re
from dataclasses import fields

from fishgen.errors import FishgenError
from fishgen.reading import read_capped
from fishgen.species.model import TexturePoints, Vec2

PARTS = tuple(f.name for f in fields(TexturePoints))
MAX_FXL_BYTES = 4 << 20
_ALIASES = {"caudalfin": "caudal", "tail": "caudal", "dorsalfin": "dorsal", "adiposefin": "adipose",
            "analfin": "anal", "pectoralfin": "pectoral", "pelvicfin": "pelvic"}


def format_fxl(points: TexturePoints, circles: int) -> str:
    out = []
    for part in PARTS:
        pts: tuple[Vec2, ...] = getattr(points, part)
        out += [f"//{part}", str(len(pts))]
        if part == "body":
            out += [f"{k // circles} {k % circles} {u!r} {v!r}" for k, (u, v) in enumerate(pts)]
        else:
            out += [f"{u!r} {v!r}" for u, v in pts]
    return "\n".join(out) + "\n"


def parse_fxl(text: str, file: str | os.PathLike = "<fxl>") -> dict[str, list[Vec2]]:
    """Part name -> points, each checked to lie in the picture (0..1)."""
    file = os.fspath(file)
    parts: dict[str, list[Vec2]] = {}
    tokens: list[tuple[str, int]] = []
    current: str | None = None
    header_line = 0

    def finish() -> None:
        if current is None:
            if tokens:
                raise FishgenError(f"expected a //part line first, found {tokens[0][0]!r}", file,
                                   tokens[0][1])
            return
        if not tokens:
            raise FishgenError(f"expected a point count after //{current}, found nothing", file, header_line)
        count_text, count_line = tokens[0]
        # at most six digits before converting: a count of 400 digits overflowed float()
        if not re.fullmatch(r"\d{1,6}(\.0*)?", count_text) or int(float(count_text)) > 100_000:
            raise FishgenError(f"expected a point count of at most 100,000, found {count_text[:40]!r}", file,
                               count_line)
        count = int(float(count_text))
        width = 4 if current == "body" else 2
        values = tokens[1:]
        if len(values) != count * width:
            raise FishgenError(f"expected {count} points of {width} numbers for //{current}, found "
                               f"{len(values)} numbers", file, values[-1][1] if values else count_line)
        pts = []
        order = _BodyOrder(file) if current == "body" else None
        for k in range(count):
            chunk = values[k * width:(k + 1) * width]
            if order is not None:
                order.next(chunk[0], chunk[1])
            try:
                u, v = float(chunk[-2][0]), float(chunk[-1][0])
            except ValueError:
                bad = next(t for t in chunk if not _number(t[0]))
                raise FishgenError(f"expected a number, found {bad[0][:40]!r}", file, bad[1]) from None
            if not (0.0 <= u <= 1.0 and 0.0 <= v <= 1.0):
                raise FishgenError(f"expected texture coordinates from 0 to 1, found {u:g} {v:g}", file,
                                   chunk[-1][1])
            pts.append((u, v))
        if order is not None:
            order.finish(values[-1][1] if values else count_line)
        parts[current] = pts

    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("//"):
            words = stripped[2:].split()
            label = words[0].lower() if words else ""
            name = _ALIASES.get(label, label)
            if name in PARTS:
                finish()
                if name in parts:
                    raise FishgenError(f"expected each part once, found //{name} again", file, number)
                current, tokens, header_line = name, [(w, number) for w in words[1:]], number
                continue
            if current is None and not parts:
                continue    # a leading free comment
            raise FishgenError(f"expected a part name ({', '.join(PARTS)}), found {stripped[:40]!r}", file,
                               number)
        tokens += [(w, number) for w in stripped.split()]
    finish()
    if not parts:
        raise FishgenError("expected Fixel points (//body, //caudal, ...), found none", file, 1)
    return parts


class _BodyOrder:
    """Body lines are ``section circle u v``, section by section, circle by circle: each line's
    numbers must be the next ones, so a reversed or shuffled file is refused, not read silently."""

    def __init__(self, file: str):
        self.file = file
        self.expected: tuple[int, int] | None = (0, 0)
        self.last: tuple[int, int] | None = None
        self.circles: int | None = None

    def next(self, section: tuple[str, int], circle: tuple[str, int]) -> None:
        found = []
        for text, line in (section, circle):
            if not re.fullmatch(r"\d{1,6}", text):
                raise FishgenError(f"expected a body line `section circle u v` with whole numbers first, "
                                   f"found {text[:40]!r}", self.file, line)
            found.append(int(text))
        s, c = found
        if self.last is None:
            allowed = {(0, 0)}
        else:
            ls, lc = self.last
            allowed = set()
            if self.circles is None or lc + 1 < self.circles:
                allowed.add((ls, lc + 1))
            if self.circles is None or lc + 1 == self.circles:
                allowed.add((ls + 1, 0))
        if (s, c) not in allowed:
            want = " or ".join(f"{a} {b}" for a, b in sorted(allowed))
            raise FishgenError(f"expected the next body point, section and circle {want}, found {s} {c}",
                               self.file, circle[1])
        if self.last is not None and s == self.last[0] + 1 and self.circles is None:
            self.circles = self.last[1] + 1
        self.last = (s, c)

    def finish(self, line: int) -> None:
        if self.last is not None and self.circles is not None and self.last[1] + 1 != self.circles:
            raise FishgenError(f"expected {self.circles} points on the last body section, found "
                               f"{self.last[1] + 1}", self.file, line)


def read_fxl(path: str | os.PathLike) -> dict[str, list[Vec2]]:
    import stat

    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))  # a FIFO must not block the open
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                raise FishgenError("expected a regular .FXL file, found a device, pipe or other special file",
                                   path)
            with os.fdopen(os.dup(fd), "rb") as handle:
                data = read_capped(handle, MAX_FXL_BYTES)
        finally:
            os.close(fd)
    except OSError as err:
        raise FishgenError(f"expected a readable .FXL file, found {err.strerror or err}", path) from None
    if len(data) > MAX_FXL_BYTES:
        raise FishgenError(f"expected a .FXL file of at most {MAX_FXL_BYTES} bytes, found a larger one", path)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    return parse_fxl(text, path)


def _number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True
