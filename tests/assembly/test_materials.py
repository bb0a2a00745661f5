"""Textures as a build takes them: upright for glTF, and in sRGB."""
from __future__ import annotations

import io
import shutil

import numpy as np
from PIL import Image

from fishgen.assembly.materials import load_textures
from fishgen.species.parser import load_species
from tests.authoring.icc import D65, P3_PRIMARIES, p3_to_srgb, profile
from tests.conftest import PARAMS, ROOT


def test_a_texture_tagged_display_p3_is_built_in_srgb_and_its_mask_as_it_is(tmp_path):
    """A texture painted in Display P3 and tagged so: glTF reads a texture as sRGB, so its colours
    are taken there (read as they were, they came out duller); a fin mask's levels are no colours."""
    shutil.copy(PARAMS / "bonybream.txt", tmp_path)
    shutil.copy(ROOT / "textures" / "bonybream_mask.png", tmp_path)
    with Image.open(ROOT / "textures" / "bonybream.png") as img:
        raw = img.convert("RGB")
    icc = profile("Display P3, gamma 2.2", P3_PRIMARIES, D65, 2.2)
    raw.save(tmp_path / "bonybream.png", icc_profile=icc)
    with Image.open(ROOT / "textures" / "bonybream_mask.png") as img:
        img.save(tmp_path / "bonybream_mask.png", icc_profile=icc)
    species = load_species(tmp_path / "bonybream.txt")
    textures = load_textures(species, "mask")
    built = np.asarray(Image.open(io.BytesIO(textures["skin"])))[::-1]     # built upright: flip back
    off = np.abs(built[:, :, :3].astype(int) - p3_to_srgb(np.asarray(raw)))
    assert off.max() <= 1, off.max()
    with Image.open(ROOT / "textures" / "bonybream_mask.png") as img:
        mask = np.asarray(img.convert("L").resize(raw.size, Image.Resampling.NEAREST))
    assert np.array_equal(built[:, :, 3] >= 128, mask >= 128)


def test_a_damaged_texture_with_a_profile_is_refused_at_its_line(tmp_path):
    """The profile's conversion decoded the picture first and took its error for the profile's: a
    damaged texture was built from the part decoded (a review)."""
    import pytest

    from fishgen.errors import FishgenError
    from tests.authoring.test_image import _damaged_png

    shutil.copy(PARAMS / "bonybream.txt", tmp_path)
    shutil.copy(ROOT / "textures" / "bonybream_mask.png", tmp_path)
    rgb = np.random.default_rng(0).integers(0, 256, (200, 300, 3), dtype=np.uint8)
    icc = profile("P3", P3_PRIMARIES, D65, 2.2)
    (tmp_path / "bonybream.png").write_bytes(_damaged_png(rgb, icc))
    with pytest.raises(FishgenError, match="damaged"):
        load_textures(load_species(tmp_path / "bonybream.txt"), "mask")
