"""A 4:2:0 JPEG's colour, drawn again at full size along its brightness before anything is measured."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image
from scipy import ndimage

from fishgen.authoring.photo.chroma import NEAR, redraw
from fishgen.authoring.photo.image import REDRAW_SIDE, load_photo


def _fish_in_water(width: int = 320, height: int = 180) -> np.ndarray:
    """Blue-green water with a reddish body and fins one to three pixels wide, at odd angles."""
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float64)
    img = np.empty((height, width, 3))
    img[:] = (40, 110, 130)
    body = ((xx - 0.5 * width) / (0.25 * width)) ** 2 + ((yy - 0.5 * height) / (0.15 * height)) ** 2 < 1
    img[body] = (200, 120, 60)
    for slope, width_px in ((0.7, 1.0), (-1.9, 2.0), (0.15, 3.0)):   # fins: thin straight strokes
        distance = np.abs(yy - 0.5 * height - slope * (xx - 0.5 * width)) / np.hypot(1, slope)
        img[(distance < width_px / 2) & ~body & (np.abs(xx - 0.5 * width) < 0.4 * width)] = (190, 100, 90)
    return img.astype(np.uint8)


@pytest.mark.parametrize("size", [(320, 180), (321, 181)])
def test_a_420_jpeg_keeps_a_thin_fins_colour_and_the_water_beside_it_its_own(tmp_path, size):
    """Within two pixels of every outline, the colour read is nearer the picture that was saved than
    the decoder's own smooth upsampling (which spreads each 2 x 2 block's colour over its
    neighbours); odd sides too, whose last block holds one row or column."""
    original = _fish_in_water(*size)
    path = tmp_path / "fish.jpg"
    Image.fromarray(original).save(path, quality=90)          # Pillow's default: 4:2:0
    decoded = np.asarray(Image.open(path).convert("RGB")).astype(float)
    read = load_photo(path).rgb.astype(float)
    edges = ndimage.morphological_gradient(original.sum(axis=2), size=5) > 0
    error = lambda img: np.abs(img - original)[edges].mean()   # noqa: E731
    assert error(read) < 0.75 * error(decoded)
    # away from the outlines the colour is as the decoder gave it, give or take its smoothing
    assert np.abs(read - decoded)[~edges].mean() < 1.0


@pytest.mark.parametrize("case", ["png", "jpeg 4:4:4", "jpeg over REDRAW_SIDE"])
def test_other_pictures_are_read_as_decoded(tmp_path, case):
    original = _fish_in_water()
    if case == "jpeg over REDRAW_SIDE":
        original = np.tile(original, (1, REDRAW_SIDE // original.shape[1] + 1, 1))
    path = tmp_path / ("fish.png" if case == "png" else "fish.jpg")
    Image.fromarray(original).save(path, **({"quality": 90, "subsampling": 0} if case == "jpeg 4:4:4"
                                            else {"quality": 90} if path.suffix == ".jpg" else {}))
    assert np.array_equal(load_photo(path).rgb, np.asarray(Image.open(path).convert("RGB")))


def test_a_turned_420_jpeg_is_redrawn_then_turned(tmp_path):
    """The EXIF orientation a phone writes goes with the redrawn pixels."""
    plain, turned = tmp_path / "plain.jpg", tmp_path / "turned.jpg"
    picture = Image.fromarray(_fish_in_water())
    picture.save(plain, quality=90)
    exif = Image.Exif()
    exif[0x0112] = 6   # Orientation: rotate 90 degrees clockwise to show
    picture.save(turned, quality=90, exif=exif)
    upright = Image.fromarray(load_photo(plain).rgb).transpose(Image.Transpose.ROTATE_270)
    assert np.array_equal(load_photo(turned).rgb, np.asarray(upright))


@pytest.mark.parametrize("size", [(7, 9), (8, 10), (1030, 5), (5, 1), (1, 7), (513, 3)])
def test_each_pixel_takes_the_colour_of_the_four_nearest_blocks_weighed_by_brightness(size):
    """The vectorised strips against the definition, pixel by pixel: odd sizes, one column, and a
    photo taller than one strip."""
    h, w = size
    rng = np.random.default_rng(7)
    rgb = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    half = rng.integers(0, 256, ((h + 1) // 2, (w + 1) // 2, 3), dtype=np.uint8)
    planes = np.pad(half.astype(float), ((1, 1), (1, 1), (0, 0)), mode="edge")
    planes[..., 1:] -= 128
    expected = np.empty_like(rgb)
    for i in range(h):
        for j in range(w):
            r, g, b = rgb[i, j].astype(float)
            luma = 0.299 * r + 0.587 * g + 0.114 * b
            colour, total = np.zeros(2), 0.0
            for a in (0, 1):
                for c in (0, 1):
                    block = planes[i // 2 + 1 + a * (2 * (i % 2) - 1), j // 2 + 1 + c * (2 * (j % 2) - 1)]
                    weight = NEAR[a + c] / (1 + 0.5 * ((luma - block[0]) / 2.0) ** 2) ** 2
                    colour += weight * block[1:]
                    total += weight
            cb, cr = colour / total
            expected[i, j] = np.clip(np.rint([luma + 1.402 * cr, luma - 0.344136 * cb - 0.714136 * cr,
                                              luma + 1.772 * cb]), 0, 255)
    got = redraw(rgb, half)
    assert np.abs(got.astype(int) - expected).max() <= 1   # float32 against float64 rounding


def test_a_jpeg_whose_components_are_named_rgb_is_read_as_decoded(tmp_path):
    """Components named R, G, B (no JFIF marker) are RGB to libjpeg, which then gives no brightness
    and colour planes: the photo is read as decoded, not refused as damaged."""
    import io
    import struct

    buffer = io.BytesIO()
    Image.fromarray(_fish_in_water()).save(buffer, "JPEG", quality=90)
    data = bytearray(buffer.getvalue())
    assert data[2:4] == b"\xff\xe0"                          # drop the JFIF marker (APP0)
    data = data[:2] + data[4 + struct.unpack(">H", data[4:6])[0]:]
    frame, scan = data.find(b"\xff\xc0"), data.find(b"\xff\xda")
    for k in range(3):
        data[frame + 10 + 3 * k] = data[scan + 5 + 2 * k] = b"RGB"[k]
    path = tmp_path / "rgb.jpg"
    path.write_bytes(bytes(data))
    assert np.array_equal(load_photo(path).rgb, np.asarray(Image.open(path).convert("RGB")))
