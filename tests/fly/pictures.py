"""Still frames of `fishgen fly` drawn directly and with impostors, and how far apart they are.

Used by tests/fly/test_impostors_browser.py and ``benchmarks/fly.py --pictures``. The page must
fly the "still" path (nothing else moves its camera); ``window.fishgenFly.look`` sets the view and
drops every impostor, ``capture`` draws a frame and returns it as a PNG.
"""
from __future__ import annotations

import base64
import io
import math

import numpy as np


def luminance(rgb: np.ndarray) -> np.ndarray:
    """Rec. 601 luma of an H x W x 3 array of 0-255 values, as float64."""
    return rgb[..., :3].astype(np.float64) @ np.array([0.299, 0.587, 0.114])


def ssim(a: np.ndarray, b: np.ndarray, sigma: float = 1.5) -> float:
    """Mean structural similarity (Wang et al. 2004) of two pictures' luma: a Gaussian window of
    ``sigma`` pixels, K1 = 0.01, K2 = 0.03, dynamic range 255."""
    from scipy.ndimage import gaussian_filter

    x, y = luminance(a), luminance(b)
    c1, c2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2
    mx, my = gaussian_filter(x, sigma), gaussian_filter(y, sigma)
    sxx = gaussian_filter(x * x, sigma) - mx * mx
    syy = gaussian_filter(y * y, sigma) - my * my
    sxy = gaussian_filter(x * y, sigma) - mx * my
    index = ((2 * mx * my + c1) * (2 * sxy + c2)) / ((mx * mx + my * my + c1) * (sxx + syy + c2))
    return float(index.mean())


def mean_abs(a: np.ndarray, b: np.ndarray) -> float:
    """Mean absolute difference of the RGB values, 0-255."""
    return float(np.abs(a[..., :3].astype(np.float64) - b[..., :3].astype(np.float64)).mean())


def views_around(centre, radius: float, count: int, seed: int, near: float = 2.5, far: float = 6.0):
    """``count`` seeded views of one cloud: eyes ``near``-``far`` radii from its centre, at any
    azimuth and -30 to 45 degrees of elevation, looking at a point within a radius of the centre."""
    rng = np.random.default_rng(seed)
    c = np.asarray(centre, float)
    out = []
    for _ in range(count):
        az, el = rng.uniform(0, 2 * math.pi), math.radians(rng.uniform(-30, 45))
        d = rng.uniform(near, far) * radius
        eye = c + d * np.array([math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az)])
        out.append((eye.tolist(), (c + rng.uniform(-0.5, 0.5, 3) * radius).tolist()))
    return out


def sky_views(area, altitude, count: int, seed: int):
    """``count`` seeded views from inside a sky (centred on the origin): eyes among the clouds,
    looking level within 10 degrees, any way round."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        eye = np.array([rng.uniform(-0.4, 0.4) * area[0], rng.uniform(*altitude),
                        rng.uniform(-0.4, 0.4) * area[1]])
        yaw, pitch = rng.uniform(0, 2 * math.pi), math.radians(rng.uniform(-10, 10))
        ahead = eye + 100 * np.array([math.cos(pitch) * math.sin(yaw), math.sin(pitch),
                                      math.cos(pitch) * math.cos(yaw)])
        out.append((eye.tolist(), ahead.tolist()))
    return out


def png(data_url: str) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(base64.b64decode(data_url.split(",", 1)[1]))).convert("RGB"))


def both(page, view) -> tuple[np.ndarray, np.ndarray, list[dict]]:
    """The view drawn directly, then with every cloud it can show as an impostor redrawn for it;
    and how each cloud was drawn the second time."""
    eye, target = view
    page.evaluate("([e, t]) => window.fishgenFly.look(e, t, 'direct')", [eye, target])
    direct = png(page.evaluate("window.fishgenFly.capture()"))
    page.evaluate("([e, t]) => window.fishgenFly.look(e, t, 'impostors')", [eye, target])
    impostors = png(page.evaluate("window.fishgenFly.capture()"))
    return direct, impostors, page.evaluate("window.fishgenFly.modes()")
