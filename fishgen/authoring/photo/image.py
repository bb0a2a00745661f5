"""Decode a photo safely: the size is checked from the header before any pixel is decoded."""
from __future__ import annotations

import math
import os
import re
import warnings
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from fishgen.authoring.photo import FOCAL_LENGTHS
from fishgen.errors import FishgenError, not_a_file
from fishgen.reading import PILLOW_TAG_READER, in_srgb

#: Largest photo accepted, in pixels (about a 64-megapixel camera frame).
MAX_PHOTO_PIXELS = 64_000_000
#: Smallest side accepted: below this a fish has too few pixels to measure.
MIN_PHOTO_SIDE = 64
MEASURE_SIDE = 1024
"""Photos are measured on a copy at most this many pixels a side (:func:`measuring_side`): a
64-megapixel photo would otherwise need gigabytes, and at 2048 a full-HD photo's fit took twice as
long for fish no better in Blender (docs/decisions.md)."""
SMALL_FISH = 256
"""A fish shorter than this in that copy is measured again on one at most FINE_SIDE long, as every
photo was until the twentieth session: the fits were shown to hold on fish 181-434 px long
(Blender's 640 x 360 photos) and 320-662 px (its full-HD ones, at 1024), not below."""
FINE_SIDE = 2048
"""The longest side of that larger copy."""
MAX_ASPECT = 32
"""Longest side over the shortest: beyond it the measuring copy, however long, would be under
MIN_PHOTO_SIDE across (an 8000 x 64 photo measured 16 pixels tall, and its analysis ran out of fish
rows: NaN)."""
LOSSY_FORMATS = ("JPEG", "MPO")
"""Pillow's names of the formats whose codec rings round a sharp outline (JPEG's 8 x 8 blocks; MPO
is a camera's JPEG with a second frame). A lossy WebP rings too, but its header does not say so."""
REDRAW_SIDE = 2 * MEASURE_SIDE
"""The longest side up to which a 4:2:0 JPEG's colour is drawn again at full size
(:mod:`.chroma`): a larger photo is measured on a copy half its size or less, where a 2 x 2 block
of colour is a pixel at most, and on a 12-megapixel photo the redrawing would cost a second."""


@dataclass(frozen=True)
class Photo:
    rgb: np.ndarray              # (H, W, 3) uint8, upright as the file shows it
    alpha: np.ndarray | None     # (H, W) uint8 when the file has an alpha channel worth using
    path: Path
    lens_35mm: float | None = None   # EXIF's FocalLengthIn35mmFilm, where the camera wrote one
    lossy: bool = False          # saved as JPEG, whose blocks ring round every sharp outline
    colour_halved: bool = False  # a JPEG keeping colour for 2 x 2 or 2 x 1 blocks (4:2:0, 4:2:2)

    @property
    def size(self) -> tuple[int, int]:
        return self.rgb.shape[1], self.rgb.shape[0]


def measuring_side(size: tuple[int, int], longest: int = MEASURE_SIDE) -> int:
    """The longest side of the copy a photo of ``size`` is measured on: ``longest``, or longer for
    a photo so long and thin that its copy would be under MIN_PHOTO_SIDE across."""
    w, h = size
    return max(longest, MIN_PHOTO_SIDE * math.ceil(max(w, h) / min(w, h)))


def working_copy(photo: Photo, longest: int) -> Photo:
    """``photo`` scaled down to at most ``longest`` pixels a side (area-averaged), for measuring:
    texture points are fractions of the picture, so they do not depend on its resolution."""
    from PIL import Image

    w, h = photo.size
    if max(w, h) <= longest:
        return photo
    k = longest / max(w, h)
    size = (max(1, round(w * k)), max(1, round(h * k)))
    rgb = np.asarray(Image.fromarray(photo.rgb, "RGB").resize(size, Image.Resampling.BOX))
    alpha = None
    if photo.alpha is not None:
        alpha = np.asarray(Image.fromarray(photo.alpha, "L").resize(size, Image.Resampling.BOX))
    return replace(photo, rgb=np.ascontiguousarray(rgb), alpha=alpha)


def mirror_image(photo: Photo) -> Photo:
    """``photo`` mirrored left to right, pixel for pixel."""
    alpha = None if photo.alpha is None else np.ascontiguousarray(photo.alpha[:, ::-1])
    return replace(photo, rgb=np.ascontiguousarray(photo.rgb[:, ::-1]), alpha=alpha)


def load_photo(path: str | os.PathLike, colours: bool = True) -> Photo:
    """Read ``path`` as RGB (+ alpha), in sRGB unless ``colours`` is off (a mask's levels are no
    colours). Absurd sizes are refused from the header alone."""
    from PIL import Image, ImageOps, JpegImagePlugin, UnidentifiedImageError

    path = Path(path)
    if not path.is_file():
        raise not_a_file("a photo file", path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            # a damaged EXIF block, read as the file opens (Pillow's tag reader warns): the lens is
            # lost, the photo is not
            warnings.filterwarnings("ignore", category=UserWarning, module=PILLOW_TAG_READER)
            with Image.open(path) as img:
                w, h = img.size            # from the header; nothing is decoded yet
                if w * h > MAX_PHOTO_PIXELS:
                    raise FishgenError(f"expected a photo of at most {MAX_PHOTO_PIXELS // 1_000_000} "
                                       f"megapixels, found {w} x {h}", path)
                if min(w, h) < MIN_PHOTO_SIDE:
                    raise FishgenError(f"expected a photo at least {MIN_PHOTO_SIDE} pixels a side, "
                                       f"found {w} x {h}", path)
                if max(w, h) > MAX_ASPECT * min(w, h):
                    raise FishgenError(f"expected a photo at most {MAX_ASPECT} times as long as it is tall "
                                       f"(measured on a copy at least {MIN_PHOTO_SIDE} pixels across), "
                                       f"found {w} x {h}", path)
                if getattr(img, "n_frames", 1) > 1:   # a GIF's or WebP's first frame is no choice
                    raise FishgenError(f"expected a still photo, found an animation of {img.n_frames} "
                                       "frames", path)
                img.load()   # a damaged picture is refused here, before its EXIF is read apart
                lens = _lens_35mm(img)
                lossy = img.format in LOSSY_FORMATS
                sampling = JpegImagePlugin.get_sampling(img) if lossy else -1   # 2: 4:2:0, 1: 4:2:2
                if colours and sampling == 2:
                    img = _colour_at_full_size(img, path)
                icc = img.info.get("icc_profile") if colours else None
                img = ImageOps.exif_transpose(img)  # phones store portrait shots sideways
                has_alpha = img.mode in ("RGBA", "LA", "PA") or "transparency" in img.info
                rgba = np.asarray(in_srgb(_eight_bit(img), icc).convert("RGBA"))
    except FishgenError:
        raise
    except (Image.DecompressionBombError, Image.DecompressionBombWarning) as err:
        # PIL refuses very large headers itself, before our own check can see the size.
        found = re.search(r"\((\d+) pixels\)", str(err))
        size = f"{int(found[1]) / 1e6:.0f} megapixels" if found else "a larger one"
        raise FishgenError(f"expected a photo of at most {MAX_PHOTO_PIXELS // 1_000_000} megapixels, "
                           f"found {size}", path) from None
    except UnidentifiedImageError:
        raise FishgenError(f"expected a photo (PNG, JPEG, WebP, ...), found {_why(path)}", path) from None
    except (OSError, ValueError, SyntaxError) as err:
        raise FishgenError(f"expected a readable photo, found a damaged file ({err})", path) from None
    alpha = rgba[:, :, 3]
    # An alpha channel that is opaque everywhere says nothing about the background.
    usable = has_alpha and bool((alpha < 128).any())
    return Photo(np.ascontiguousarray(rgba[:, :, :3]), alpha.copy() if usable else None, path, lens, lossy,
                 sampling in (1, 2))


def _colour_at_full_size(img, path: Path):
    """``img``, a 4:2:0 JPEG or MPO, with its colour drawn again at full size along its brightness
    (:func:`.chroma.redraw`, from the file's own half-size colour planes); any other picture as it
    is. Decoded smoothly, such a JPEG's colour spreads a pixel or two past a fish's outline and
    thins a fin's. Blender's water photos in JPEG 90 on nine sets fitted 170 of 216 times at 0.85
    as decoded and 174 so redrawn (123 fits up, 68 down); saved with full-size colour (4:4:4), 149
    of the 168 on seven of them against 127 (docs/decisions.md)."""
    from PIL import Image

    w, h = img.size
    if img.mode != "RGB" or max(w, h) > REDRAW_SIDE or img.info.get("adobe_transform") == 0:
        return img   # an Adobe transform of 0 stores RGB, not brightness and colour
    half_size = ((w + 1) // 2, (h + 1) // 2)
    try:
        with Image.open(path) as again:
            # decoded at half size: the colour as stored. Asked for the size rounded down, as
            # Pillow picks the scale by whole divisions and libjpeg rounds an odd side up.
            again.draft("YCbCr", (max(1, w // 2), max(1, h // 2)))
            planes = np.asarray(again) if again.mode == "YCbCr" else None
    except (OSError, ValueError, SyntaxError):
        return img   # e.g. components named R, G, B: libjpeg gives no YCbCr, the decode stands
    if planes is None or planes.shape != (half_size[1], half_size[0], 3):
        return img
    from fishgen.authoring.photo.chroma import redraw

    drawn = Image.fromarray(redraw(np.asarray(img), planes), "RGB")
    drawn.info.update(img.info)   # the EXIF orientation and the colour profile go with the pixels
    return drawn


#: EXIF's Exif IFD, and its FocalLengthIn35mmFilm tag.
_EXIF_IFD, _FOCAL_35MM = 0x8769, 0xA405


def _lens_35mm(img) -> float | None:
    """The focal length the camera wrote as on 35 mm film (0 is EXIF's "unknown"), if --focal-length
    would take it."""
    try:   # the picture is decoded already: what fails here is the EXIF block alone
        value = float(img.getexif().get_ifd(_EXIF_IFD).get(_FOCAL_35MM, 0))
    except Exception:   # noqa: BLE001 - a damaged EXIF block costs a hint, never the photo
        return None
    # one --focal-length takes (a camera's 65535 is no lens)
    return value if math.isfinite(value) and FOCAL_LENGTHS[0] <= value <= FOCAL_LENGTHS[1] else None


def _eight_bit(img):
    """``img`` with 8-bit channels. Pillow converts a 16-bit or 32-bit grey image (``I;16``, ``I``,
    ``F``) to RGBA by clipping at 255, not scaling: a 16-bit photo turned all white."""
    if img.mode not in ("I;16", "I;16B", "I;16L", "I", "F"):
        return img
    from PIL import Image

    grey = np.asarray(img, dtype=np.float64)
    top = 65535.0 if img.mode.startswith("I;16") or grey.max(initial=0) > 255 else 255.0
    if img.mode == "F":
        top = 1.0 if grey.max(initial=0) <= 1.0 else top
    return Image.fromarray(np.clip(np.round(grey / top * 255), 0, 255).astype(np.uint8), "L")


#: The brands of an ISO media file (``ftyp``) that hold HEIF pictures: a phone camera's default.
_HEIF_BRANDS = {b"heic", b"heix", b"hevc", b"hevx", b"heim", b"heis", b"mif1", b"msf1"}


def _why(path: Path) -> str:
    """What a file Pillow cannot read is, said so the user knows what to do with it."""
    try:
        with open(path, "rb") as f:
            head = f.read(12)
    except OSError:
        head = b""
    if head[4:8] == b"ftyp" and head[8:12] in _HEIF_BRANDS:
        return "a HEIF/HEIC picture, which fishgen cannot read (a phone's default): save it as JPEG or PNG"
    return "a file that is not an image PIL can read"
