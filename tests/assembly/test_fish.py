"""Assembly: axes and metres, materials per fin technique, the looping swim clip."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from fishgen.assembly.animation import FinMotion, clip_frames
from fishgen.assembly.fish import build_fish
from fishgen.errors import FishgenError
from fishgen.species.parser import load_species
from tests.conftest import PARAMS


@pytest.fixture(scope="module")
def bony():
    return load_species(PARAMS / "bonybream.txt")


def test_axes_head_towards_plus_z_and_dorsal_up(bony):
    asset = build_fish(bony)
    parts = {p.name: p for p in asset.parts}
    body = parts["body"].mesh.positions
    nose = body[np.argmax(body[:, 2])]
    assert nose[2] > 0 and abs(nose[0]) < 1e-9 and abs(nose[1]) < 1e-9      # nose on +Z axis
    assert parts["caudal_fin"].translation[2] < body[:, 2].min() + 0.1 * np.ptp(body[:, 2])
    dorsal = parts["dorsal_fin"].mesh.positions
    assert dorsal[:, 1].max() > body[:, 1].max()                              # dorsal fin is up
    left = parts["pectoral_fin_left"].translation
    assert left[0] > 0                                                        # fish's left is +X


def test_length_option_sets_nose_to_tail_metres(bony):
    asset = build_fish(bony, length=1.25)
    lo, hi = asset.bounds()
    assert hi[2] - lo[2] == pytest.approx(1.25)


def test_default_size_comes_from_world_scale(bony):
    asset = build_fish(bony)
    body = asset.parts[0].mesh.positions
    assert np.ptp(body[:, 2]) == pytest.approx(25.5 * 0.26 * 0.05)


def test_moving_fins_pivot_and_static_fins_do_not(bony):
    asset = build_fish(bony)
    moving = {p.name for p in asset.parts if p.motion is not None}
    assert moving == {"caudal_fin", "pectoral_fin_left", "pectoral_fin_right", "pelvic_fin_left",
                      "pelvic_fin_right"}
    for p in asset.parts:
        if p.motion is None:
            assert not np.any(p.translation)


def test_swim_clip_loops_every_fin_seamlessly(bony):
    asset = build_fish(bony, fps=30)
    # caudal 4*10/1 = 40 frames, pelvic 24, pectoral 16 -> lcm 240
    assert asset.clip_frames == 240 and asset.clip_seconds == pytest.approx(8.0)
    for p in asset.parts:
        if p.motion:
            frames, angles = p.motion.keys(asset.clip_frames)
            assert frames[-1] == asset.clip_frames and angles[0] == angles[-1] == 0
            assert np.abs(angles).max() == p.motion.amplitude


def test_fin_steps_by_step_size_each_frame():
    m = FinMotion.from_fin(10.0, 1.0)
    assert m.period_frames == 40
    assert np.allclose(np.diff(m.angle_at(np.arange(0, 11))), 1.0)
    assert m.angle_at(10) == 10 and m.angle_at(30) == -10 and m.angle_at(40) == 0
    assert clip_frames([m, FinMotion.from_fin(6.0, 1.0)]) == 120


def test_mirrored_fins_swing_opposite(bony):
    asset = build_fish(bony)
    parts = {p.name: p for p in asset.parts}
    assert parts["pelvic_fin_right"].motion.sign == -parts["pelvic_fin_left"].motion.sign


@pytest.mark.parametrize("mode,alpha_mode", [("blend", "BLEND"), ("mask", "MASK"), ("opaque", "OPAQUE")])
def test_fin_techniques(bony, mode, alpha_mode):
    asset = build_fish(bony, fins=mode)
    fins, body = asset.materials["fins"], asset.materials["body"]
    assert fins.alpha_mode == alpha_mode and fins.double_sided and body.alpha_mode == "OPAQUE"
    if mode == "blend":
        assert fins.base_color[3] == 0.5            # transparency 1.0 -> 0.5 as the thesis did
    if mode == "mask":
        assert fins.alpha_cutoff == 0.5


def test_mask_texture_carries_the_black_and_white_picture_as_alpha(bony):
    from io import BytesIO

    from PIL import Image, ImageOps
    asset = build_fish(bony, fins="mask")
    skin = Image.open(BytesIO(asset.images["skin"]))
    assert skin.mode == "RGBA"
    mask = ImageOps.flip(Image.open(bony.mask_texture).convert("L"))
    assert np.array_equal(np.asarray(skin)[:, :, 3], np.asarray(mask))


def test_texture_is_turned_upright(bony):
    """VRFish stores textures upside down; the body's texture points are measured from the
    upright picture's top, so the top rows of the glTF image must hold the fish's back."""
    from io import BytesIO

    from PIL import Image
    asset = build_fish(bony, fins="opaque")
    skin = np.asarray(Image.open(BytesIO(asset.images["skin"])).convert("RGB")).astype(float)
    tp = np.asarray(bony.texture_points.body).reshape(16, 12, 2)
    h, w = skin.shape[:2]
    back = tp[8, 3] * [w, h]          # circle 3 is the top of the fish (+y)
    belly = tp[8, 9] * [w, h]
    sample = lambda p: skin[int(p[1]) + (4 if p is back else -4), int(p[0])]  # noqa: E731
    assert sample(back).sum() < sample(belly).sum()  # painted dark back, light belly


def test_untextured_species_uses_its_colour(bony):
    plain = replace(bony, textured=False, texture_points=None, colour_texture=None, mask_texture=None)
    asset = build_fish(plain)
    assert asset.images == {} and asset.materials["body"].base_color == (1.0, 1.0, 0.0, 1.0)
    with pytest.raises(FishgenError, match="textured species for --fins mask"):
        build_fish(plain, fins="mask")


@pytest.mark.parametrize("kwargs", [{"fps": 0}, {"length": -1}, {"fins": "glass"}])
def test_bad_options(bony, kwargs):
    with pytest.raises(FishgenError):
        build_fish(bony, **kwargs)


def test_loop_length_error_points_at_the_fin_record():
    text = (PARAMS / "bonybream.txt").read_text().replace("3.0 10.0 1.0\n", "3.0 10.0 0.0001\n")
    from fishgen.species.parser import parse_species
    sp = parse_species(text, "slow.txt")
    with pytest.raises(FishgenError) as info:
        build_fish(sp)
    caudal_line = next(i for i, l in enumerate(text.splitlines(), 1) if l.endswith("3.0 10.0 0.0001"))
    assert info.value.line == caudal_line and "loop within 100000 frames" in str(info.value)
