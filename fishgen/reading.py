"""Reading inputs: with a size cap, without reserving the cap; a picture's colours in sRGB; and the
warnings about the parts of an input fishgen does not read."""
from __future__ import annotations

import io
import os
from pathlib import Path
from typing import BinaryIO


def read_capped(handle: BinaryIO, limit: int) -> bytes:
    """Up to ``limit + 1`` bytes of an open binary file: one byte more than ``limit`` tells the caller
    the file is too big. ``read(n)`` allocates ``n`` bytes before it reads, so a 1 KB species file
    read as ``read(64 MiB + 1)`` reserved 64 MiB; this asks for what the file holds (a file that
    grows meanwhile is read on, up to the cap)."""
    try:
        size = os.fstat(handle.fileno()).st_size
    except (OSError, AttributeError, ValueError):  # no descriptor (a BytesIO): ask for the cap
        size = limit
    data = handle.read(min(size, limit) + 1)
    while size < len(data) <= limit:              # grew since fstat: read on, to the cap at most
        more = handle.read(limit + 1 - len(data))
        if not more:
            break
        data += more
        size = len(data) - 1
    return data


#: The module of Pillow's EXIF and TIFF tag reader, whose warnings :func:`unheeded` drops.
PILLOW_TAG_READER = r"PIL\.TiffImagePlugin"


def unheeded(category: type[Warning], filename: str) -> bool:
    """Whether a warning is about a part of an input fishgen does not need, so it is not said: one
    from Pillow's EXIF and TIFF tag reader (``filename``: where it was raised), which reads what it
    can of a damaged block as a picture opens (fishgen reads only a photo's orientation and lens
    there). Said, it was Pillow's own two lines naming its source file, before the command's one
    line; in a batch, a note naming no file."""
    where = Path(filename)
    return (issubclass(category, UserWarning) and where.name == "TiffImagePlugin.py"
            and where.parent.name == "PIL")


def in_srgb(img, icc: bytes | None):
    """A Pillow image ``img`` with the colours its ICC profile ``icc`` (as the file embedded it) gives
    taken to sRGB, the space fishgen's textures are written in and glTF reads (a phone's Display
    P3 photo read as sRGB came out duller); as it is without a profile, for a grey picture, or
    with a profile that cannot be read or does not fit it."""
    if not icc:
        return img
    img.load()   # a damaged picture's own error, not taken for the profile's below
    if img.mode in ("P", "PA"):    # a palette's colours are in the profile's space too
        img = img.convert("RGBA" if img.mode == "PA" or "transparency" in img.info else "RGB")
    if img.mode not in ("RGB", "RGBA", "CMYK"):
        return img
    from PIL import ImageCms

    try:
        source = ImageCms.ImageCmsProfile(io.BytesIO(icc))
        mode = "RGBA" if img.mode == "RGBA" else "RGB"
        return ImageCms.profileToProfile(img, source, ImageCms.createProfile("sRGB"), outputMode=mode)
    except (ImageCms.PyCMSError, OSError, ValueError, TypeError):
        return img
