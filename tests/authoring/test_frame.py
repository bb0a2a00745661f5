"""The fish's frame: levelled head-left, and turned further on request."""
from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from fishgen.authoring.photo.frame import fish_frame, turned


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
