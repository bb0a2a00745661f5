"""Nose and tail base on a head-left silhouette."""
from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from fishgen.authoring.photo.anatomy import nose_and_tail_base


def _forked_fish(gap: bool) -> np.ndarray:
    """A body, a peduncle at x 150-165 and a forked tail whose lobes end in 1-px threads; with
    ``gap`` the upper thread breaks for a column near the end, as a thin line drawn at a slant does."""
    img = Image.new("L", (230, 110), 0)
    pen = ImageDraw.Draw(img)
    pen.ellipse((10, 25, 155, 85), fill=255)
    pen.rectangle((150, 50, 166, 60), fill=255)
    pen.polygon([(164, 50), (200, 18), (172, 55)], fill=255)
    pen.polygon([(164, 60), (200, 92), (172, 55)], fill=255)
    pen.line([(200, 18), (214, 6)], fill=255, width=1)
    pen.line([(200, 92), (218, 104)], fill=255, width=1)
    mask = np.asarray(img) > 0
    if gap:
        mask = mask.copy()
        mask[:55, 212] = False
    return mask


def test_the_tail_base_is_the_peduncle_not_a_gap_in_a_lobes_thread():
    """A column near the end holding one lobe's pixel between columns spanning both lobes looks
    like the deepest neck of all; the peduncle is the tail base."""
    for gap in (False, True):
        _, tail = nose_and_tail_base(_forked_fish(gap))
        assert 148 <= tail[0] <= 170, f"tail base at x {tail[0]} (gap={gap}), not the peduncle"
        assert 50 <= tail[1] <= 60
