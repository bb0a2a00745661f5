"""The silhouette cut from a photo's backdrop keeps thin fins: their tips set the fish's size."""
from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from fishgen.authoring.photo.image import Photo
from fishgen.authoring.photo.silhouette import silhouette

SIZE = (400, 240)


def _photo(with_speck: bool = False, noise: float = 0.0, thread=(130, 150, 150)) -> Photo:
    """A pale fish on a vertical water-like gradient: an ellipse body and a fin that tapers from
    6 px to a 1-px thread 40 px long above its back (as a fin seen almost edge-on looks)."""
    w, h = SIZE
    ys = np.linspace(0.0, 1.0, h)[:, None, None]
    back = (np.array([60, 140, 170]) * (1 - ys) + np.array([20, 60, 110]) * ys) * np.ones((1, w, 1))
    img = Image.fromarray(back.astype(np.uint8), "RGB")
    pen = ImageDraw.Draw(img)
    colour = (220, 200, 150)
    pen.ellipse((100, 100, 300, 160), fill=colour)
    pen.polygon([(180, 105), (192, 105), (187, 80)], fill=colour)   # the fin's root, then its thread
    pen.line([(187, 82), (196, 40)], fill=thread, width=1)
    if with_speck:
        pen.rectangle((40, 40, 41, 41), fill=colour)
    rgb = np.asarray(img).astype(float)
    if noise:
        rgb += np.random.default_rng(3).normal(0.0, noise, rgb.shape)
    return Photo(np.clip(rgb, 0, 255).astype(np.uint8), None, Path("photo.png"))


def test_a_thread_thin_fin_tip_stays_on_the_fish():
    """The noise-clearing opening takes off anything under 3 px wide; the fin's 1-px thread
    touching the fish comes back, so the silhouette reaches the tip's row."""
    mask = silhouette(_photo()).mask
    top = int(np.flatnonzero(mask.any(axis=1))[0])
    assert top <= 44, f"the fin's tip (row 40) was cut at row {top}"
    assert mask[41:80].sum() >= 30     # the thread itself, not one stray pixel


def test_specks_apart_from_the_fish_stay_out():
    mask = silhouette(_photo(with_speck=True, noise=4.0)).mask
    assert not mask[30:50, 30:50].any()
    ys, xs = np.nonzero(mask)
    assert xs.min() >= 98 and xs.max() <= 302 and ys.max() <= 162
