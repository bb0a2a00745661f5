"""Assembly: axes and metres, materials per fin technique, the looping swim clip."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from fishgen.assembly.animation import FinMotion, clip_frames
from fishgen.assembly.fish import build_fish, make_fish
from fishgen.errors import FishgenError
from fishgen.species.parser import load_species
from tests.conftest import PARAMS


@pytest.fixture(scope="module")
def bony():
    return load_species(PARAMS / "bonybream.txt")


def parts(scene):
    """Node name -> (node, its one primitive), for the fish's part nodes."""
    return {n.name: (n, scene.meshes[n.mesh].primitives[0]) for n in scene.nodes if n.mesh is not None}


def swim_channels(scene):
    """Node name -> its rotation channel in the swim clip (the fins' swings)."""
    return {scene.nodes[c.node].name: c for c in scene.clip("swim").channels if c.path == "rotation"}


def material(scene, part):
    """The body's or the fins' material: named after the species, so two species in one folder
    (or one school) keep their own in an engine's import."""
    return next(m for m in scene.materials if m.name == f"{scene.name}_{part}")


def images(scene):
    return {i.name: i.data for i in scene.images}


def test_axes_head_towards_plus_z_and_dorsal_up(bony):
    fish = parts(build_fish(bony, swim="fins"))   # the tail fin swings (carries a pivot) on a rigid body
    body = fish["body"][1].positions
    nose = body[np.argmax(body[:, 2])]
    assert nose[2] > 0 and abs(nose[0]) < 1e-7 and abs(nose[1]) < 1e-7      # nose on +Z axis
    assert fish["caudal_fin"][0].translation[2] < body[:, 2].min() + 0.1 * np.ptp(body[:, 2])
    dorsal = fish["dorsal_fin"][1].positions
    assert dorsal[:, 1].max() > body[:, 1].max()                              # dorsal fin is up
    left = fish["pectoral_fin_left"][0].translation
    assert left[0] > 0                                                        # fish's left is +X


def test_length_option_sets_nose_to_tail_metres(bony):
    from fishgen.scene.pose import bounds
    lo, hi = bounds(build_fish(bony, length=1.25))
    assert hi[2] - lo[2] == pytest.approx(1.25)


def test_default_size_comes_from_world_scale(bony):
    body = parts(build_fish(bony))["body"][1].positions
    assert np.ptp(body[:, 2]) == pytest.approx(25.5 * 0.26 * 0.05)


def test_moving_fins_pivot_and_static_fins_do_not(bony):
    scene = build_fish(bony, swim="fins")
    moving = set(swim_channels(scene))
    assert moving == {"caudal_fin", "pectoral_fin_left", "pectoral_fin_right", "pelvic_fin_left",
                      "pelvic_fin_right"}
    for name, (node, _) in parts(scene).items():
        if name not in moving:
            assert not np.any(node.translation)


def test_swim_clip_loops_every_fin_seamlessly(bony):
    scene = build_fish(bony, fps=30, swim="fins")
    # caudal 4*10/1 = 40 frames, pelvic 24, pectoral 16 -> lcm 240
    assert scene.clip("swim").duration == pytest.approx(8.0)
    amplitudes = {"caudal_fin": 10.0, "pectoral_fin_left": 4.0, "pelvic_fin_left": 6.0}
    for name, channel in swim_channels(scene).items():
        times, quats = channel.sampler.times, channel.sampler.values
        assert times[-1] == pytest.approx(8.0) and np.allclose(quats[0], quats[-1])
        assert np.allclose(quats[0], [0, 0, 0, 1])            # every fin starts and ends at rest
        if name in amplitudes:
            angles = np.degrees(2 * np.arcsin(np.linalg.norm(quats[:, :3], axis=1)))
            assert np.abs(angles).max() == pytest.approx(amplitudes[name], abs=1e-4)


def test_fin_steps_by_step_size_each_frame():
    m = FinMotion.from_fin(10.0, 1.0)
    assert m.period_frames == 40
    assert np.allclose(np.diff(m.angle_at(np.arange(0, 11))), 1.0)
    assert m.angle_at(10) == 10 and m.angle_at(30) == -10 and m.angle_at(40) == 0
    assert clip_frames([m, FinMotion.from_fin(6.0, 1.0)]) == 120


def test_mirrored_fins_swing_opposite(bony):
    channels = swim_channels(build_fish(bony))
    left, right = (channels[f"pelvic_fin_{side}"].sampler.values for side in ("left", "right"))
    assert np.abs(left[:, 1]).max() > 0 and np.allclose(right[:, 1], -left[:, 1])


@pytest.mark.parametrize("mode,alpha_mode", [("blend", "BLEND"), ("mask", "MASK"), ("opaque", "OPAQUE")])
def test_fin_techniques(bony, mode, alpha_mode):
    scene = build_fish(bony, fins=mode)
    fins, body = material(scene, "fins"), material(scene, "body")
    assert fins.alpha_mode == alpha_mode and fins.double_sided and body.alpha_mode == "OPAQUE"
    if mode == "blend":
        assert fins.base_color[3] == 0.5            # transparency 1.0 -> 0.5 as the thesis did
    if mode == "mask":
        assert fins.alpha_cutoff == 0.5


def test_mask_texture_carries_the_black_and_white_picture_as_alpha(bony):
    from io import BytesIO

    from PIL import Image, ImageOps
    skin = Image.open(BytesIO(images(build_fish(bony, fins="mask"))["skin"]))
    assert skin.mode == "RGBA"
    mask = ImageOps.flip(Image.open(bony.mask_texture).convert("L"))
    assert np.array_equal(np.asarray(skin)[:, :, 3], np.asarray(mask))


def test_texture_is_turned_upright(bony):
    """VRFish stores textures upside down; the body's texture points are measured from the
    upright picture's top, so the top rows of the glTF image must hold the fish's back."""
    from io import BytesIO

    from PIL import Image
    skin = np.asarray(Image.open(BytesIO(images(build_fish(bony, fins="opaque"))["skin"])).convert("RGB"))
    skin = skin.astype(float)
    tp = np.asarray(bony.texture_points.body).reshape(16, 12, 2)
    h, w = skin.shape[:2]
    back = tp[8, 3] * [w, h]          # circle 3 is the top of the fish (+y)
    belly = tp[8, 9] * [w, h]
    sample = lambda p: skin[int(p[1]) + (4 if p is back else -4), int(p[0])]  # noqa: E731
    assert sample(back).sum() < sample(belly).sum()  # painted dark back, light belly


def test_untextured_species_uses_its_colour(bony):
    plain = replace(bony, textured=False, texture_points=None, colour_texture=None, mask_texture=None)
    scene = build_fish(plain)
    assert scene.images == [] and material(scene, "body").base_color == (1.0, 1.0, 0.0, 1.0)
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
    caudal_line = next(i for i, row in enumerate(text.splitlines(), 1) if row.endswith("3.0 10.0 0.0001"))
    assert (info.value.line == caudal_line
            and "fin cycle (4 x movement angle / step size) of at most 100000" in str(info.value))


def test_with_the_body_wave_the_tail_fin_rides_the_wave_and_the_loop_closes(bony):
    fish = make_fish(bony, fps=30)
    scene = fish.scene
    assert "caudal_fin" not in swim_channels(scene)          # its swing is the wave's (decisions.md)
    clip = scene.clip("swim")
    assert fish.facts.clip_seconds == clip.duration
    beats = clip.duration * fish.facts.tail_beat_hz
    laps = clip.duration / 1.6                                # fin loop: pelvic 24, pectoral 16 frames
    assert beats == pytest.approx(round(beats), abs=1e-5) and laps == pytest.approx(round(laps), abs=1e-5)
    assert fish.facts.tail_beat_hz == pytest.approx(1.5, rel=0.05)   # St 0.3 at 1 body length/s
    for channel in clip.channels:
        assert np.allclose(channel.sampler.values[0], channel.sampler.values[-1], atol=1e-6)
        assert channel.sampler.times[-1] == pytest.approx(clip.duration)


@pytest.mark.parametrize("name", ["bonybream", "centroberyx", "threadfingoldie"])
def test_a_still_fish_is_the_fish_at_rest_without_clips_or_morph_targets(name):
    """What a picture of the fish at rest needs (a photo fit draws hundreds): the same nodes and
    triangles at the same rest positions, and nothing that moves them."""
    from fishgen.exchange.rest import rest_meshes

    sp = load_species(PARAMS / f"{name}.txt")
    full, still = build_fish(sp, clips="swim,idle,turn_left"), build_fish(sp, still=True)
    assert full.clips and full.meshes[0].primitives[0].targets
    assert not still.clips and not any(p.targets for m in still.meshes for p in m.primitives)
    assert [n.name for n in still.nodes] == [n.name for n in full.nodes]
    for a, b in zip(rest_meshes(full), rest_meshes(still), strict=True):
        assert a.name == b.name and np.array_equal(a.faces, b.faces)
        assert np.array_equal(a.positions, b.positions) and np.array_equal(a.normals, b.normals)
