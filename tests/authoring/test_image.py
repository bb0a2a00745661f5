"""Reading a photo: the lens a camera wrote in its EXIF, its colours, and the copy it is measured on."""
from __future__ import annotations

import io
import struct
import warnings
import zlib
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from fishgen.authoring.photo.image import MIN_PHOTO_SIDE, Photo, load_photo, measuring_side, working_copy
from fishgen.errors import FishgenError


@pytest.mark.parametrize("focal, read", [(50, 50.0), (0, None), (None, None), (65535, None)])
def test_the_35mm_focal_length_a_camera_wrote_is_read_if_the_option_would_take_it(tmp_path, focal, read):
    exif = Image.Exif()
    if focal is not None:
        exif.get_ifd(0x8769)[0xA405] = focal     # FocalLengthIn35mmFilm; EXIF's 0 is "unknown"
    path = tmp_path / "p.jpg"
    Image.new("RGB", (96, 64), (40, 90, 120)).save(path, exif=exif)
    assert load_photo(path).lens_35mm == read


def test_a_damaged_exif_block_costs_the_lens_not_the_photo_and_says_nothing(tmp_path):
    """Pillow warns of a damaged EXIF block, a line naming its own source file that the command
    printed before its one line (or its summary)."""
    path = tmp_path / "p.jpg"
    Image.new("RGB", (96, 64), (40, 90, 120)).save(path, exif=b"Exif\x00\x00II*\x00\xff\xff\xff\x7f")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        photo = load_photo(path)
    assert photo.size == (96, 64) and photo.lens_35mm is None


@pytest.mark.parametrize("suffix", [".png", ".jpg"])
def test_a_photo_tagged_display_p3_is_read_in_srgb(tmp_path, suffix):
    """A phone writes Display P3 and tags it: read as sRGB its colours came out duller (P3's
    (200, 100, 100) is sRGB's (216, 93, 97)); the texture is written, and glTF reads it, in sRGB."""
    from tests.authoring.icc import D65, P3_PRIMARIES, p3_to_srgb, profile

    colour = (200, 100, 100)
    path = tmp_path / f"p3{suffix}"
    icc = profile("Display P3, gamma 2.2", P3_PRIMARIES, D65, 2.2)
    extra = {"quality": 100} if suffix == ".jpg" else {}
    Image.new("RGB", (96, 64), colour).save(path, icc_profile=icc, **extra)
    read = load_photo(path).rgb[32, 48].astype(int)
    assert abs(read - p3_to_srgb(colour)).max() <= (1 if suffix == ".png" else 3), read
    assert abs(read - colour).max() >= 10


def test_a_tagged_photo_keeps_its_alpha_a_palette_is_converted_and_a_bad_profile_is_not(tmp_path):
    from tests.authoring.icc import D65, P3_PRIMARIES, profile

    img = Image.new("RGBA", (96, 64), (200, 100, 100, 255))
    img.paste((0, 0, 0, 0), (0, 0, 48, 64))
    img.save(tmp_path / "a.png", icc_profile=profile("P3", P3_PRIMARIES, D65, 2.2))
    photo = load_photo(tmp_path / "a.png")
    assert photo.alpha is not None and photo.alpha[:, :48].max() == 0 and photo.alpha[:, 48:].min() == 255
    palette = Image.new("P", (96, 64))
    palette.putpalette([200, 100, 100] * 256)
    palette.save(tmp_path / "p.png", icc_profile=profile("P3", P3_PRIMARIES, D65, 2.2))
    converted = load_photo(tmp_path / "a.png").rgb[0, 60].tolist()
    assert load_photo(tmp_path / "p.png").rgb[0, 0].tolist() == converted != [200, 100, 100]
    Image.new("RGB", (96, 64), (200, 100, 100)).save(tmp_path / "d.png", icc_profile=b"not a profile" * 20)
    assert load_photo(tmp_path / "d.png").rgb[0, 0].tolist() == [200, 100, 100]


def _damaged_png(rgb: np.ndarray, icc: bytes | None = None) -> bytes:
    """A PNG of ``rgb`` with 64 bytes of its pixel data zeroed and the chunk's checksum made right:
    only decoding it finds the damage."""
    buf = io.BytesIO()
    Image.fromarray(rgb).save(buf, "PNG", icc_profile=icc)
    data = bytearray(buf.getvalue())
    at = data.index(b"IDAT") - 4
    size = struct.unpack(">I", data[at:at + 4])[0]
    data[at + 8 + size // 3:at + 8 + size // 3 + 64] = bytes(64)
    data[at + 8 + size:at + 12 + size] = struct.pack(">I", zlib.crc32(bytes(data[at + 4:at + 8 + size])))
    return bytes(data)


def test_a_damaged_photo_is_refused_not_read_in_part(tmp_path):
    """Reading a PNG's EXIF decodes it, and the lens's guard had swallowed the decoding error: the
    photo was fitted from the part decoded (a review: 68 % of the rows black)."""
    from tests.authoring.icc import D65, P3_PRIMARIES, profile

    rgb = np.random.default_rng(0).integers(0, 256, (200, 300, 3), dtype=np.uint8)
    for icc in (None, profile("P3", P3_PRIMARIES, D65, 2.2)):
        (tmp_path / "d.png").write_bytes(_damaged_png(rgb, icc))
        with pytest.raises(FishgenError, match="found a damaged file"):
            load_photo(tmp_path / "d.png")


def test_a_mask_is_read_as_its_levels_whatever_its_profile(tmp_path):
    from tests.authoring.icc import D65, P3_PRIMARIES, profile

    Image.new("RGB", (96, 64), (200, 100, 100)).save(tmp_path / "m.png",
                                                      icc_profile=profile("P3", P3_PRIMARIES, D65, 2.2))
    assert load_photo(tmp_path / "m.png", colours=False).rgb[0, 0].tolist() == [200, 100, 100]


def test_an_exif_tag_larger_than_the_file_says_nothing(tmp_path):
    """Pillow's tag reader warns of more than a "corrupt" block: "Tag data larger than file" too."""
    exif = bytearray(b"Exif\x00\x00II*\x00\x08\x00\x00\x00\x01\x00")
    exif += struct.pack("<HHII", 271, 2, 100, 1000) + bytes(4)    # Make: 100 bytes at offset 1000
    path = tmp_path / "p.jpg"
    Image.new("RGB", (96, 64), (40, 90, 120)).save(path, exif=bytes(exif))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert load_photo(path).size == (96, 64)


@pytest.mark.parametrize("size, side", [((640, 360), 1024), ((1920, 1080), 1024), ((6000, 3375), 1024),
                                        ((3000, 3000), 1024), ((2000, 100), 1280), ((8000, 250), 2048)])
def test_a_photo_is_measured_on_a_copy_1024_px_long_unless_that_would_be_under_64_px_across(size, side):
    """A camera's photo is measured at 1024 px (a full-HD fit took twice as long at 2048 for no
    better fish); a long thin one keeps at least MIN_PHOTO_SIDE rows, as the refusal of longer ones
    promises."""
    assert measuring_side(size) == side
    w, h = size
    photo = Photo(np.zeros((h, w, 3), np.uint8), None, Path("photo.png"))
    copy = working_copy(photo, measuring_side(size))
    assert max(copy.size) == min(max(size), side) and min(copy.size) >= MIN_PHOTO_SIDE


@pytest.mark.parametrize(("suffix", "options", "lossy", "halved"), [
    (".jpg", {}, True, True), (".jpg", {"subsampling": 1}, True, True),
    (".jpg", {"subsampling": 0}, True, False),
    (".png", {}, False, False), (".webp", {"lossless": True}, False, False)])
def test_a_jpeg_is_known_as_lossy_and_by_its_colours_size_and_its_copies_and_mirror_stay_so(
        tmp_path, suffix, options, lossy, halved):
    """Pillow's JPEGs keep colour for 2 x 2 blocks (4:2:0) unless told 4:2:2 or full size (4:4:4)."""
    from fishgen.authoring.photo.image import mirror_image

    path = tmp_path / f"photo{suffix}"
    Image.new("RGB", (2048, 1024), (40, 90, 120)).save(path, **options)
    photo = load_photo(path)
    copy = working_copy(photo, 1024)
    assert (photo.lossy, photo.colour_halved) == (lossy, halved)
    assert (copy.lossy, copy.colour_halved) == (lossy, halved) and copy.size == (1024, 512)
    mirrored = mirror_image(photo)
    assert (mirrored.lossy, mirrored.colour_halved) == (lossy, halved)
