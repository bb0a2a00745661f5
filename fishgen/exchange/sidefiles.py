"""Side files an asset refers to (glTF buffers and images, OBJ materials and textures).

An asset may name other files, but only files in its own folder (or below it):
a reference such as ``../secret.txt``, ``/etc/hostname``, ``file:///...`` or a
symlink that leads out of the folder is refused, so previewing or viewing a
file someone sent you cannot read (or embed in a page) anything else on disk.
``data:`` URIs are inline and need no file; callers handle them before this.
"""
from __future__ import annotations

import os
import re
import stat
from collections.abc import Mapping
from pathlib import Path
from urllib.parse import quote, unquote_to_bytes

from fishgen.errors import describe, expected
from fishgen.file_names import NAME_MAX, name_text, text_name, too_long


def name_uri(name: str) -> str:
    """A side file's name as a glTF URI: its bytes on disk, percent-encoded. ``quote(name)``
    encoded the name as UTF-8 text, so where the locale's file names are not UTF-8 the URI named
    another file (latin-1) or raised (ASCII, the name's bytes kept as surrogates)."""
    return quote(os.fsencode(name))


def uri_name(uri: str) -> str:
    """The file name a percent-encoded URI gives, as the file system spells it."""
    return os.fsdecode(unquote_to_bytes(uri))


_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")
"""``http:``, ``file:``, ``C:`` ... - anything but a plain relative path."""


def side_file(asset: str | Path, ref: str, *, uri: bool = False, must_exist: bool = False) -> Path:
    """The file ``ref`` (as written inside ``asset``) names, checked to lie in the asset's folder.

    ``uri``: ``ref`` is a percent-encoded URI (glTF), decoded before use.
    Raises FishgenError naming ``asset`` and ``ref`` when it points elsewhere
    (or, with ``must_exist``, when no such file is there).
    """
    asset = Path(asset)
    name = ref.strip().replace("\\", "/")
    if not name or "\0" in name:
        raise expected("a file name in a reference", describe(ref) if name else "an empty one", asset)
    if _SCHEME.match(name) or name.startswith(("/", "~")):
        raise expected("a relative file name inside the asset's folder", describe(ref), asset)
    if uri:
        name = uri_name(name)  # glTF URIs are percent-encoded ("my%20skin.png")
        if "\0" in name or name.startswith("/"):
            raise expected("a relative file name inside the asset's folder", describe(ref), asset)
    else:
        name = text_name(name)  # an OBJ's or PLY's text names a file by its bytes
    if too_long(name):
        raise expected(f"a file name of at most {NAME_MAX} bytes a part", f"{describe(ref)} "
                       f"({len(name.encode('utf-8', 'surrogateescape')):,} bytes)", asset)
    folder = asset.parent.resolve()
    try:
        target = (folder / name).resolve()  # follows symlinks: a link out of the folder is refused
    except (OSError, RuntimeError, ValueError):
        raise expected("a readable file name", describe(ref), asset) from None
    if not target.is_relative_to(folder):
        raise expected("a file inside the asset's folder", f"{describe(ref)}, which leads outside it", asset)
    if must_exist and not target.is_file():
        raise expected(f"the file {ref.strip()!r} it refers to beside the asset", "none", asset)
    from fishgen.atomic import protect

    protect(target)  # an input too: no output of the command under way may replace it
    return target


def _there(asset: Path, ref: str) -> bool:
    """Whether ``ref`` names something beside ``asset``; if it does, it must stay in the folder
    (``side_file`` refuses it in one line otherwise: a link out is refused, not skipped)."""
    name = ref.strip().replace("\\", "/")
    if not name or not os.path.lexists(os.path.join(Path(asset).parent, name)):  # lexists: False on NUL
        return False
    return side_file(asset, ref).is_file()


def mtl_libraries(asset: str | Path, rest: str) -> list[str]:
    """The MTL names one ``mtllib`` statement gives (``rest``: the text after the keyword): the
    whole of it when such a file is beside ``asset`` (``my fish.mtl``), else each word."""
    rest = rest.strip()
    return [rest] if _there(Path(asset), rest) else rest.split()


def map_file_name(asset: str | Path, rest: str) -> str:
    """The picture a texture map statement names (``rest``: the text after ``map_Kd`` and the
    like): the whole of it when such a file is beside ``asset``, as trimesh and three.js read it
    (``my fish_skin.png``), else its last word (options such as ``-imfchan m`` come first)."""
    rest = rest.strip()
    return rest if _there(Path(asset), rest) else rest.split()[-1]


_IMAGE_SUFFIX = re.compile(r"\.(png|jpe?g|gif|webp)$", re.IGNORECASE)
_NOT_PORTABLE = re.compile(r"[^A-Za-z0-9._-]+")


def image_stem(name: str) -> str:
    """An image's name without the picture extension a texture cloud's names carry (``billow.png``)."""
    return _IMAGE_SUFFIX.sub("", name) or name


def image_side_stems(asset_stem: str, image_names: list[str]) -> list[str]:
    """The stems of the files a writer puts images in beside ``asset_stem``'s asset, one per
    image and all different: ``x_billow`` for an image named ``billow.png`` (a texture cloud
    names its images by their files), never ``x_billow.png``, to which the writer adds its own
    extension; ``x_billow_2`` for a second image of that name (two clouds' different
    ``billow.png``), which would otherwise overwrite the first. Outside letters, digits, ``.``,
    ``_`` and ``-``, an image's name becomes ``_``: the billboards' sprite, named ``gaussian
    sprite``, went to ``x_gaussian sprite.png`` (the asset's own stem is the user's and is kept)."""
    stems: list[str] = []
    for name in image_names:
        stem = f"{asset_stem}_{_NOT_PORTABLE.sub('_', image_stem(name))}"
        unique, n = stem, 1
        while unique in stems:
            n += 1
            unique = f"{stem}_{n}"
        stems.append(unique)
    return stems


NAMING = (".gltf", ".mtl", ".usda", ".usdc", ".usd", ".ply")
"""Formats whose files name side files beside them (a glTF's images and buffer, an OBJ's material
file's textures, USD's textures, a textured PLY's TextureFile); each holds the names as bytes."""
_READ_MOST = 1 << 26


def check_shared(asset: str | os.PathLike, files: Mapping[Path, bytes]) -> None:
    """Refuse to change a side file that another asset beside ``asset`` names.

    ``files`` is everything one write puts down (``asset`` and its side files). ``fish.gltf`` and
    ``fish.obj`` both name ``fish_skin.png``: built with other ``--fins``, the second rewrote the
    first's texture without its mask. The same bytes again (the same fish) are no change.
    """
    from fishgen.errors import UsageError

    asset = Path(asset)
    writing = [Path(p) for p in files]
    siblings = [p for p in _same_stem(asset) if not any(_same(p, w) for w in writing)]
    if not siblings:
        return
    texts: dict[Path, bytes] = {}      # each sibling read once, however many side files
    for side, data in files.items():
        if _same(side, asset) or not side.is_file():
            continue
        try:
            if side.stat().st_size == len(data) and side.read_bytes() == data:
                continue
        except OSError:
            continue
        for other in siblings:
            if other not in texts:
                texts[other] = _head(other)
            if any(form.encode("utf-8", "surrogateescape") in texts[other]
                   for form in (name_text(side.name), name_uri(side.name))):
                obj = other.with_suffix(".obj")      # an OBJ names its textures in its .mtl
                other = obj if other.suffix.lower() == ".mtl" and obj.is_file() else other
                raise UsageError(f"expected side files no other asset names, found {side.name!r}, named by "
                                 f"{other.name!r} beside it, with other content; choose another -o")


def _same_stem(asset: Path) -> list[Path]:
    """The files beside ``asset`` of its stem in a format that names side files, its extension in
    lower or upper case. Looked up by name, not by listing the folder: a batch writes thousands of
    files into one, and a listing for each write was quadratic."""
    found: dict[tuple[int, int], Path] = {}    # one file once (a case-insensitive file system)
    for ext in NAMING:
        for spelt in (ext, ext.upper()):
            path = asset.with_name(asset.stem + spelt)
            try:
                st = path.stat()
            except OSError:
                continue
            if stat.S_ISREG(st.st_mode):
                found.setdefault((st.st_dev, st.st_ino), path)
    return list(found.values())


def _same(a: Path, b: Path) -> bool:
    """One file, however spelt (a case-insensitive file system, a link)."""
    if os.path.abspath(a) == os.path.abspath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def _head(asset: Path) -> bytes:
    """The first _READ_MOST bytes of ``asset`` (b"" when it cannot be read): where it names its files."""
    try:
        with asset.open("rb") as handle:
            return handle.read(_READ_MOST)
    except OSError:
        return b""
