"""What the editor's server may touch: the file it was given, cube files in that file's folder, and
textures in the allowed texture folders. Nothing else, whatever the page asks.

- A cube file is named by a bare file name ending in ``.awn`` or ``.awa``: no folder part, so no
  ``..``, no absolute path, no drive; a name that is a symbolic link leading out of the folder is
  refused (one inside it is followed).
- A texture is named as a ``.awa`` file names it, relative to a texture folder, and is resolved by
  the rule of :func:`fishgen.file_names.resolve_texture` (never outside the folders).
- The folders are listed shallowly and with caps, so a huge folder cannot stall the page.

Leaf module: no numpy.
"""
from __future__ import annotations

import os
import re
import stat
from collections.abc import Iterator
from pathlib import Path

from fishgen.clouds.parser import texture_roots
from fishgen.editor.document import SUFFIX
from fishgen.errors import NAME_MAX, FishgenError, describe, expected
from fishgen.reading import read_capped

SUFFIXES = tuple(SUFFIX.values())
MAX_LISTED = 500
"""Most cube files, and most textures, a listing offers."""
TEXTURE_DEPTH = 3
"""Texture folders are listed this many folders deep (``clouds/billow.png`` is one)."""
MAX_TEXTURE_BYTES = 32 << 20
"""A texture served to the page is read whole; a cloud texture is a few KB."""
_NAME = re.compile(r"[^/\\\x00-\x1f\x7f]{1,255}")
_TEXTURE_NAME = re.compile(r"[^\s,\\\x00-\x1f\x7f]{1,1024}")


class Workspace:
    """The folder of the file ``fishgen edit`` was given, and the texture folders of its files."""

    def __init__(self, file: str | os.PathLike, textures_dir: str | os.PathLike | None = None):
        given = Path(file)
        self.folder = Path(os.path.realpath(given.absolute().parent))
        self.name = given.name
        self.given = self.folder / given.name
        self.textures_dir = Path(textures_dir) if textures_dir is not None else None

    # -- cube files -------------------------------------------------------------------------------
    def cube_file(self, name: object, *, must_exist: bool) -> Path:
        """The file a page's ``name`` means, in this folder; refused unless it is one the editor may
        read (``must_exist``) or write."""
        if not isinstance(name, str) or not _NAME.fullmatch(name) or name.startswith("."):
            raise expected(f"a file name in {self.folder} (no folder part, no ..)",
                           describe(name) if isinstance(name, str) else repr(name))
        if Path(name).suffix.lower() not in SUFFIXES:
            raise expected(f"a name ending in {' or '.join(SUFFIXES)}", describe(name))
        if len(os.fsencode(name)) > NAME_MAX:   # 255 characters of é are 510 bytes: ENAMETOOLONG
            raise expected(f"a name of at most {NAME_MAX} bytes (the file system's limit)",
                           f"{describe(name)}, of {len(os.fsencode(name))}")
        path = self.folder / name
        if name == self.name:
            path = Path(os.path.realpath(self.given))  # the file it was given, wherever it leads
        elif os.path.lexists(path):
            real = Path(os.path.realpath(path))
            if not real.is_relative_to(self.folder):
                raise expected(f"a file inside {self.folder}", f"{describe(name)}, a link leading out of it")
            path = real
        if path.is_dir():
            raise expected("a cube file", f"{describe(name)}, a folder")
        if must_exist and not path.is_file():
            raise expected(f"an existing file in {self.folder}", f"no {describe(name)}")
        return path

    def cube_files(self) -> list[str]:
        """Names of the .awn and .awa files in the folder (regular files, links only to inside it)."""
        found = []
        for entry in _entries(self.folder):
            if Path(entry.name).suffix.lower() in SUFFIXES and not entry.name.startswith("."):
                try:
                    self.cube_file(entry.name, must_exist=True)
                except FishgenError:
                    continue
                found.append(entry.name)
        return sorted(found)[:MAX_LISTED]

    # -- textures ---------------------------------------------------------------------------------
    def roots(self, file: Path | None = None) -> list[Path]:
        """The folders a .awa file here reads textures from (as `fishgen clouds` reads them)."""
        return texture_roots(file or self.given, self.textures_dir)

    def texture_names(self, file: Path | None = None) -> list[str]:
        """Names of the .png files in the texture folders, as a .awa file names them: relative to
        their folder, the first folder winning; names a cube line cannot hold are left out."""
        names: dict[str, None] = {}
        for root in self.roots(file):
            for name in _pngs(root, root, TEXTURE_DEPTH):
                names.setdefault(name)
                if len(names) >= MAX_LISTED:
                    return sorted(names)
        return sorted(names)

    def texture(self, name: object, file: Path | None = None) -> bytes:
        """The bytes of the texture a .awa file here names ``name``; only a PNG in the folders."""
        from fishgen.file_names import resolve_texture

        if (not isinstance(name, str) or not _TEXTURE_NAME.fullmatch(name)
                or not name.lower().endswith(".png")):
            raise expected("a texture name ending in .png, without blanks or commas",
                           describe(name) if isinstance(name, str) else repr(name))
        try:
            path = resolve_texture(name, self.roots(file), name, 0)
        except FishgenError as err:  # its message, without the made-up line
            raise FishgenError(err.message) from None
        with open(path, "rb") as handle:
            if not stat.S_ISREG(os.fstat(handle.fileno()).st_mode):
                raise expected("a texture file", f"{describe(name)}, a special file")
            data = read_capped(handle, MAX_TEXTURE_BYTES)
        if len(data) > MAX_TEXTURE_BYTES:
            raise expected(f"a texture of at most {MAX_TEXTURE_BYTES >> 20} MiB", f"{describe(name)}, larger")
        if not data.startswith(b"\x89PNG\r\n\x1a\n"):
            raise expected("a PNG texture", f"{describe(name)}, another kind of file")
        return data


def _entries(folder: Path) -> list[os.DirEntry]:
    try:
        with os.scandir(folder) as it:
            return [entry for _, entry in zip(range(20 * MAX_LISTED), it, strict=False)]
    except OSError:
        return []


def _pngs(folder: Path, root: Path, depth: int) -> Iterator[str]:
    for entry in sorted(_entries(folder), key=lambda e: e.name):
        if entry.name.startswith("."):
            continue
        path = Path(entry.path)
        if entry.is_symlink() and not Path(os.path.realpath(path)).is_relative_to(root):
            continue  # a link out of the texture folder: resolve_texture would refuse it
        name = path.relative_to(root).as_posix()
        if entry.is_dir():
            if depth > 0:
                yield from _pngs(path, root, depth - 1)
        elif entry.name.lower().endswith(".png") and _TEXTURE_NAME.fullmatch(name):
            yield name
