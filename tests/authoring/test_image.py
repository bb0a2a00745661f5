"""Reading a photo: the lens a camera wrote in its EXIF."""
from __future__ import annotations

import warnings

import pytest
from PIL import Image

from fishgen.authoring.photo.image import load_photo


@pytest.mark.parametrize("focal, read", [(50, 50.0), (0, None), (None, None)])
def test_the_35mm_focal_length_a_camera_wrote_is_read_and_zero_is_unknown(tmp_path, focal, read):
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
