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
