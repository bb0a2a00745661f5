"""File names fishgen reads and writes: how long a name may be, and where a texture an input names
may come from. Below every parser and writer, so that each of them can use it."""
from __future__ import annotations

import os
import re
import unicodedata
from collections.abc import Sequence
from pathlib import Path

from fishgen.errors import FishgenError, describe

NAME_MAX = 255
"""Bytes a file name's every part may have (Linux's NAME_MAX; ext4, APFS, NTFS alike)."""


def too_long(name: str) -> bool:
    """Whether a relative file name has a part longer than the file system allows."""
    parts = name.replace("\\", "/").split("/")
    return any(len(part.encode("utf-8", "surrogateescape")) > NAME_MAX for part in parts)


def name_text(name: str) -> str:
    """A file name as the text whose UTF-8 bytes (surrogates escaped) are its bytes on disk: what
    a file that names it (a species file, an OBJ, a PLY's header, a USD layer) writes, in any
    locale. Where the locale's file names are not UTF-8 (``LC_ALL=C``: the bytes are kept as
    surrogates; latin-1) the name as Python spells it wrote other bytes, or could not be written."""
    return os.fsencode(name).decode("utf-8", "surrogateescape")


def text_name(text: str) -> str:
    """The file a text names (its UTF-8 bytes), as the file system spells it: ``name_text``'s
    inverse. ``spëcies.png`` in a species file is the file ``sp\\udcc3\\udcabcies.png`` where the
    locale is ASCII; opened as spelled, it was a traceback."""
    return os.fsdecode(text.encode("utf-8", "surrogateescape"))


def ascii_name(text: str, fallback: str) -> str:
    """ASCII letters, digits and ``_`` of ``text`` (a name inside a file), its accents dropped
    rather than the letters that carry them: ``ünï🐟`` is ``uni``; ``fallback`` when none is left."""
    plain = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode("ascii")
    return re.sub(r"[^A-Za-z0-9_]+", "_", plain).strip("_") or fallback


def texture_token_problem(name: str) -> str | None:
    """Why ``name`` cannot stand in a species file's texture record and be read back as the same
    file beside it, or None when it can. The parser splits a record on any whitespace (str.split),
    reads the file as UTF-8, and resolves a name inside the texture roots."""
    if any(c.isspace() for c in name):
        return "holds whitespace, which separates a species file's values"
    if "/" in name or "\\" in name:
        return "holds a path separator (/ or \\)"
    try:
        size = len(name.encode("utf-8"))
    except UnicodeEncodeError:
        return "is not valid UTF-8, as species files are"
    if size > NAME_MAX:
        return f"would be longer than {NAME_MAX} bytes"
    return None


def resolve_texture(name: str, roots: Sequence[Path], file: str, line: int) -> Path:
    """Resolve a texture name inside one of ``roots``; never outside them."""
    shown = " or ".join(str(r) for r in roots)
    if too_long(name):
        raise FishgenError(f"expected a texture file name of at most {NAME_MAX} bytes a part, found "
                           f"{describe(name)}", file, line)
    escaped = False
    folder = other = None
    for root in roots:
        candidate = (root / text_name(name)).resolve()
        if not candidate.is_relative_to(root):
            escaped = True
            continue
        if candidate.is_file():
            _check_image(candidate, name, file, line)
            return candidate
        if candidate.is_dir() and folder is None:
            folder = candidate
        elif candidate.exists() and other is None:    # a FIFO, a socket, a device: there, not a file
            other = candidate
    if escaped or os.path.isabs(name):
        raise FishgenError(f"expected a texture path inside {shown}, found {name!r} "
                           "(texture paths may not leave the texture folder; use --textures DIR)",
                           file, line)
    if folder is not None:
        raise FishgenError(f"expected a texture file, found {name!r}, a folder", file, line)
    if other is not None:
        raise FishgenError(f"expected a texture file, found {name!r}, not a regular file (a pipe, a "
                           "socket or a device)", file, line)
    raise FishgenError(f"expected an existing texture file, found {name!r} missing from {shown}",
                       file, line)


#: Largest texture side accepted (pixels); larger files are refused before decoding.
MAX_TEXTURE_SIDE = 8192


def _check_image(path: Path, name: str, file: str, line: int) -> None:
    """A readable picture of a sane size, read to its end but not decoded, or a clear error."""
    import re
    import warnings

    from PIL import Image, UnidentifiedImageError

    too_big = f"expected a texture of at most {MAX_TEXTURE_SIDE} pixels a side, found {name!r}"
    try:
        with warnings.catch_warnings():  # a large header's warning: the size is refused below
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(path) as img:
                width, height = img.size
                if max(width, height) <= MAX_TEXTURE_SIDE:
                    _verify(img, name, file, line)
    except Image.DecompressionBombError as err:  # Pillow's own limit, before the size is ours to see
        pixels = re.search(r"\((\d+) pixels\)", str(err))
        raise FishgenError(f"{too_big} of {int(pixels[1]):,} pixels" if pixels else f"{too_big} larger",
                           file, line) from None
    except (UnidentifiedImageError, OSError, ValueError, SyntaxError):
        raise FishgenError(f"expected a texture image (PNG, GIF, JPEG, ...), found {name!r} unreadable",
                           file, line) from None
    if max(width, height) > MAX_TEXTURE_SIDE:
        raise FishgenError(f"{too_big} {width}x{height}", file, line)


def _verify(img, name: str, file: str, line: int) -> None:
    """Every chunk of the picture there and its checksum right, read but not decoded: a file cut
    off after its header is damaged, said at its line rather than by whatever decodes it later."""
    try:
        img.verify()
    except (OSError, ValueError, SyntaxError, EOFError):
        raise FishgenError(f"expected a readable texture image, found {name!r} damaged", file, line) from None

