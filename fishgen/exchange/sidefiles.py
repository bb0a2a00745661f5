"""Side files an asset refers to (glTF buffers and images, OBJ materials and textures).

An asset may name other files, but only files in its own folder (or below it):
a reference such as ``../secret.txt``, ``/etc/hostname``, ``file:///...`` or a
symlink that leads out of the folder is refused, so previewing or viewing a
file someone sent you cannot read (or embed in a page) anything else on disk.
``data:`` URIs are inline and need no file; callers handle them before this.
"""
from __future__ import annotations

import re
from pathlib import Path
from urllib.parse import unquote

from fishgen.errors import describe, expected
from fishgen.file_names import NAME_MAX, too_long

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
        name = unquote(name)  # glTF URIs are percent-encoded ("my%20skin.png")
        if "\0" in name or name.startswith("/"):
            raise expected("a relative file name inside the asset's folder", describe(ref), asset)
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
    return target
