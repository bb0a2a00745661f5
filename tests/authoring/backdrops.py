"""Textured backdrops for photos more like photographs (issue 25): sand, a water gradient and
caustics, made from seeded noise with numpy alone (no pictures ship with the tests)."""
from __future__ import annotations

import numpy as np
from scipy import ndimage  # type: ignore[import-untyped]


def _noise(h: int, w: int, seed: int, scales=(64, 16, 4), weights=(0.5, 0.3, 0.2)) -> np.ndarray:
    """Smooth value noise in [0, 1]: white noise blurred at a few scales and summed."""
    rng = np.random.default_rng(seed)
    out = np.zeros((h, w))
    for scale, weight in zip(scales, weights, strict=True):
        n = ndimage.gaussian_filter(rng.random((h, w)), scale / 4, mode="wrap")
        out += weight * (n - n.min()) / max(np.ptp(n), 1e-9)
    return out


def sand(w: int, h: int, seed: int = 0) -> np.ndarray:
    """Pale sand: tan grains over soft ripples."""
    n = _noise(h, w, seed, (32, 8, 1), (0.35, 0.35, 0.3))
    ripple = 0.5 + 0.5 * np.sin(np.arange(h)[:, None] / h * 40 + 6 * _noise(h, w, seed + 1, (64,), (1.0,)))
    t = (0.6 * n + 0.4 * ripple)[:, :, None]
    colour = (1 - t) * np.array([120, 100, 70]) + t * np.array([190, 170, 130])
    return np.clip(colour, 0, 255).astype(np.uint8)


def water(w: int, h: int, seed: int = 0) -> np.ndarray:
    """Open water: light blue-green at the top to deep blue below, with soft murk."""
    t = np.linspace(0, 1, h)[:, None, None]
    base = (1 - t) * np.array([70, 150, 175]) + t * np.array([12, 50, 95])
    murk = (_noise(h, w, seed, (96, 32), (0.7, 0.3)) - 0.5)[:, :, None] * 30
    return np.clip(base + murk, 0, 255).astype(np.uint8)


def caustics(w: int, h: int, seed: int = 0) -> np.ndarray:
    """Water lit by caustics: bright wavy lines (the ridges of warped noise) over the gradient."""
    n = _noise(h, w, seed + 7, (48, 16), (0.7, 0.3))
    ridges = np.exp(-((n - 0.5) ** 2) / 0.0015) + np.exp(-((n - 0.3) ** 2) / 0.0015)
    glow = ndimage.gaussian_filter(ridges, 1.5)[:, :, None]
    return np.clip(water(w, h, seed) + glow * np.array([120, 150, 140]), 0, 255).astype(np.uint8)
