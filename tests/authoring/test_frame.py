"""The fish's frame: levelled head-left, and turned further on request."""
from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from fishgen.authoring.photo.frame import faces_right, fish_frame, turned


def _fish(mirrored: bool) -> np.ndarray:
    img = Image.new("L", (300, 160), 0)
    pen = ImageDraw.Draw(img)
    pen.ellipse((40, 50, 220, 110), fill=255)
    pen.rectangle((215, 74, 235, 86), fill=255)
    pen.polygon([(232, 74), (270, 40), (270, 120), (232, 86)], fill=255)
    mask = np.asarray(img) > 0
    return mask[:, ::-1] if mirrored else mask


def _axis_degrees(mask: np.ndarray) -> float:
    ys, xs = np.nonzero(mask)
    vx, vy = np.linalg.eigh(np.cov(np.stack([xs, ys]).astype(float)))[1][:, -1]
    return float((np.degrees(np.arctan2(vy, vx)) + 90.0) % 180.0 - 90.0)


def test_a_turned_frame_turns_the_levelled_fish_and_says_so_on_the_photo():
    """Turned 5 degrees further, the levelled fish's long axis tilts 5 degrees (counter-clockwise,
    y down) in the frame, the photo's angle moves by 5 (the other way for a mirrored photo), and
    a point maps back to the same photo pixel."""
    for mirrored in (False, True):
        mask = _fish(mirrored)
        level = fish_frame(mask)
        five = turned(mask, level, 5.0)
        assert five.mirrored == level.mirrored == mirrored
        assert abs(_axis_degrees(five.mask) - _axis_degrees(level.mask) + 5.0) < 0.5
        assert abs(five.angle - level.angle - (-5.0 if mirrored else 5.0)) < 1e-9
        photo_point = np.array([[120.0, 80.0]])
        back = five.to_photo(photo_point @ five.linear.T + five.shift)
        assert np.allclose(back, photo_point)
    assert turned(mask, level, 0.0) is level


def _tall_fish(tilt: float, mirrored: bool) -> np.ndarray:
    """A fish nearly as tall as long: a blunt face, a tall dorsal fin leaning forward and a long
    pelvic fin swept far back, so its principal axis lies some 26 degrees off its midline."""
    img = Image.new("L", (400, 400), 0)
    pen = ImageDraw.Draw(img)
    pen.ellipse((60, 150, 260, 250), fill=255)
    pen.rectangle((50, 150, 75, 250), fill=0)
    pen.rectangle((75, 178, 90, 222), fill=255)
    pen.polygon([(120, 160), (170, 155), (110, 20)], fill=255)
    pen.polygon([(130, 240), (160, 240), (240, 340)], fill=255)
    pen.rectangle((255, 192, 275, 208), fill=255)
    pen.polygon([(272, 192), (310, 160), (310, 240), (272, 208)], fill=255)
    mask = np.asarray(img.rotate(tilt, resample=Image.Resampling.BILINEAR, center=(200, 200))) > 127
    return mask[:, ::-1] if mirrored else mask


def test_a_fish_turned_off_by_its_tall_fins_is_levelled_by_its_midline():
    """The principal axis of a fish nearly as tall as long is pulled off by its fins; turned by it,
    the leading pixel is the dorsal fin's tip, not the nose, and the frame was 44 degrees off (the
    Blender photos 704, 1203 and 1208: 15, 16 and 8). Levelled again on its own midline, and
    from level, it lies within the fit's own turns (2.5 degrees) of the drawn tilt."""
    for mirrored in (False, True):
        for tilt in (-2.0, 0.0, 2.0):
            frame = fish_frame(_tall_fish(tilt, mirrored))
            assert frame.mirrored == mirrored
            assert abs(frame.angle - (-tilt if mirrored else tilt)) < 2.5, (mirrored, tilt, frame.angle)


def test_a_sail_finned_fish_is_read_head_left_though_its_fins_pull_its_axis_round():
    """The silhouette the command read from Blender's photo 2407 (a fish 2 degrees off level with a
    sail of a dorsal fin and long pelvic fins; tests/fixtures/silhouettes): its principal axis lies
    22 degrees off, and turned by it the fish's two ends had necks 1.3 times apart, the head's the
    deeper. Read so, the fish was fitted backwards (nose at the tail base; IoU 0.68-0.82 in
    Blender on four bases). As it stands, the tail's neck is 10 times the head's."""
    from PIL import Image

    from tests.conftest import ROOT

    mask = np.asarray(Image.open(ROOT / "tests" / "fixtures" / "silhouettes" / "sampled_2407.png")
                      .convert("L")) > 127
    for mirrored in (False, True):
        frame = fish_frame(mask[:, ::-1] if mirrored else mask)
        assert frame.mirrored == mirrored
        assert abs(frame.angle) < 4.0, frame.angle      # the fit's own turns take up to 4 degrees


def test_a_fish_level_as_it_stands_is_a_second_reading_of_its_level():
    """The silhouette the command read from Blender's full-HD photo 3207 (a level fish turned 8
    degrees off side-on, with a tall dorsal fin and long pelvic fins; tests/fixtures/silhouettes):
    its principal axis lies 25 degrees off, and turned by it, its nose and tail base agree with that
    turn; as it stands they are 2 degrees off level. That is offered as a second reading (the fit
    tries both: tests/authoring/test_fit.py); a fish read near level has none."""
    from PIL import Image

    from fishgen.authoring.photo.frame import other_level
    from tests.conftest import ROOT

    mask = np.asarray(Image.open(ROOT / "tests" / "fixtures" / "silhouettes" / "sampled_3207.png")
                      .convert("L")) > 127
    for mirrored in (False, True):
        shown = mask[:, ::-1] if mirrored else mask
        first = fish_frame(shown)
        assert abs(first.angle) > 20.0
        second = other_level(shown, first)
        assert second is not None and second.mirrored == mirrored
        assert abs(second.angle) < 4.0, (mirrored, second.angle)
    level = _tall_fish(0.0, False)
    assert other_level(level, fish_frame(level)) is None


def test_a_weak_neck_as_the_photo_stands_does_not_overrule_the_turn():
    """A small-tailed fish drawn 7 degrees off level, head left (a review's random drawings,
    tests/fixtures/silhouettes): turned by its axis its necks are 1.9 and 1.53 (the tail the
    deeper), as it stands 1.2 and 1.52 (the head the deeper). The reading as it stands overruled
    the turn whenever it was the more decisive, and read this fish backwards; it now must be clearly
    decisive (frame.TAIL_DECISIVE). Its mirror image is read backwards by every version so far."""
    from PIL import Image

    from tests.conftest import ROOT

    mask = np.asarray(Image.open(ROOT / "tests" / "fixtures" / "silhouettes" / "drawn_small_tail.png")
                      .convert("L")) > 127
    assert not fish_frame(mask).mirrored


def test_a_frame_of_the_mirror_image_levels_and_maps_the_photo_itself():
    """A fish facing right is measured on its photo's mirror image: the frame the command gives
    back levels a mask of the photo as the mirror's frame levels the mirrored mask, maps frame
    points to the photo's own pixels, and says the photo's turn and facing."""
    photo = np.asarray(Image.fromarray(_fish(True)).rotate(6.0, resample=Image.Resampling.NEAREST)) > 0
    mirror = photo[:, ::-1].copy()
    assert faces_right(photo) and not faces_right(mirror)
    of_mirror = fish_frame(mirror)
    frame = of_mirror.of_mirror(photo.shape[1])
    assert np.array_equal(frame.level(photo), of_mirror.level(mirror))
    point = np.array([[100.0, 70.0]])
    assert np.allclose(frame.to_photo(point), [[photo.shape[1] - of_mirror.to_photo(point)[0, 0],
                                               of_mirror.to_photo(point)[0, 1]]])
    assert frame.mirrored and frame.angle == -of_mirror.angle
    assert abs(frame.angle - fish_frame(photo).angle) < 0.5
