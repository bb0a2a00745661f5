"""What the glTF reader and the OBJ/PLY reader share: a library's error text on one line, byte
counts in words, and the caps and checks of a texture image, read from its header before
anything decodes it.
"""
from __future__ import annotations

import io
import warnings

from fishgen.errors import expected

MAX_IMAGE_SIDE = 8192
"""Widest or tallest texture image, read from its header before any decoding."""
MAX_IMAGE_PIXELS = 2**26
"""Most pixels of one texture image (256 MiB as RGBA)."""


def one_line(err: BaseException, limit: int = 200) -> str:
    """A library's error message squeezed onto one short line for ours."""
    text = " ".join(str(err).split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


#: A library's own bugs on input it did not expect: their messages name its variables, not the file.
_INTERNAL = (TypeError, AttributeError, NameError, KeyError, IndexError, AssertionError, RecursionError)


def what_was_found(err: BaseException, kind: str, limit: int = 200) -> str:
    """What a reader's library choked on, said about the file: its message when it speaks of the
    data (a ValueError's "could not convert string to float: 'x'"), else that the file holds
    something the {kind} reader cannot parse. Never an exception's class name."""
    if isinstance(err, _INTERNAL) or not str(err).strip():
        return f"content the {kind} reader cannot parse"
    return one_line(err, limit)


def size_text(n: int) -> str:
    """A byte count for a message: ``564 bytes``, ``2.0 GiB``."""
    if n < 2**20:
        return f"{n:,} bytes"
    return f"{n / 2**30:.1f} GiB" if n >= 2**30 else f"{n / 2**20:.1f} MiB"


def check_picture(data: bytes, name: str) -> None:
    """Refuse a texture too big to decode, or damaged, from its header and a cheap verify.

    ``name`` says where the picture is (``images[0] ('skin')``); the error carries no file,
    which the caller adds.
    """
    from PIL import Image as PILImage  # Pillow only when a picture is there to check

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PILImage.DecompressionBombWarning)
            with PILImage.open(io.BytesIO(data)) as img:
                width, height = img.size
    except PILImage.DecompressionBombError:
        raise expected(f"an image of at most {MAX_IMAGE_PIXELS:,} pixels at {name}",
                       f"more than {2 * (PILImage.MAX_IMAGE_PIXELS or 0):,}") from None
    except Exception as err:  # Pillow raises anything from OSError to SyntaxError
        raise expected(f"a PNG or JPEG image at {name}", f"unreadable data ({type(err).__name__})") from None
    if width > MAX_IMAGE_SIDE or height > MAX_IMAGE_SIDE or width * height > MAX_IMAGE_PIXELS:
        raise expected(f"an image of at most {MAX_IMAGE_SIDE} px a side and {MAX_IMAGE_PIXELS:,} pixels "
                       f"at {name}", f"{width}x{height}")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with PILImage.open(io.BytesIO(data)) as img:
                img.verify()
    except Exception as err:
        raise expected(f"an undamaged image at {name}", what_was_found(err, "image", 80)) from None
