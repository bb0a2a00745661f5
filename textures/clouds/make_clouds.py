"""Draw the shipped cloud textures: three seeded noise puffs for texture clouds (.awa).

    python textures/clouds/make_clouds.py       # rewrites textures/clouds/*.png

RekAwan's texture mode pasted a PNG per cube on its billboards (report, Appendix A and the
user manual); the project draws its own. Each is 128 x 128 RGBA: near-white, a little
greyer where the puff is thin, with an alpha that fades to 0 well inside the square (the
billboards are crossed quads, whose edges must not show) and is broken up by fractal
value noise. The same script gives the same bytes (the seeds are fixed, no timestamps).
"""
from __future__ import annotations

import io
import sys
from pathlib import Path

import numpy as np
from PIL import Image

HERE = Path(__file__).resolve().parent
SIZE = 128

PUFFS = {
    # name: (seed, [(centre x, centre y, radius) of blobs in the unit square], noise strength)
    "cumulus.png": (11, [(0.5, 0.56, 0.36), (0.36, 0.5, 0.3), (0.64, 0.5, 0.3), (0.5, 0.4, 0.3),
                         (0.42, 0.64, 0.24), (0.6, 0.64, 0.24)], 0.55),
    "wisp.png": (23, [(0.25, 0.52, 0.2), (0.4, 0.5, 0.24), (0.58, 0.5, 0.24), (0.74, 0.48, 0.2)], 0.7),
    "billow.png": (37, [(0.5, 0.5, 0.42), (0.4, 0.42, 0.26), (0.62, 0.58, 0.26)], 0.55),
}


def value_noise(rng: np.random.Generator, size: int, octaves: int = 5) -> np.ndarray:
    """Fractal value noise in [0, 1]: octaves of bilinearly upsampled random grids."""
    total = np.zeros((size, size))
    weight = 0.0
    for o in range(octaves):
        cells = 2 ** (o + 2)
        grid = rng.random((cells + 1, cells + 1))
        t = np.linspace(0, cells, size, endpoint=False)
        i = t.astype(int)
        f = t - i
        f = f * f * (3 - 2 * f)  # smoothstep between lattice values
        rows = grid[i] * (1 - f)[:, None] + grid[i + 1] * f[:, None]
        layer = rows[:, i] * (1 - f)[None, :] + rows[:, i + 1] * f[None, :]
        amplitude = 0.55 ** o
        total += amplitude * layer
        weight += amplitude
    return total / weight


def puff(seed: int, blobs, noise_strength: float, size: int = SIZE) -> np.ndarray:
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:size, 0:size] / (size - 1)
    clear = np.ones((size, size))
    for cx, cy, r in blobs:  # a soft union of Gaussian blobs
        clear *= 1 - np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * (r / 2.2) ** 2))
    body = 1 - clear
    noise = value_noise(rng, size)
    alpha = body * (1 - noise_strength + noise_strength * 2 * noise)
    edge = np.clip((0.5 - np.hypot(x - 0.5, y - 0.5)) / 0.12, 0, 1)  # 0 before the square's rim
    alpha = np.clip(alpha * edge * 1.2, 0, 1)
    shade = 0.86 + 0.14 * np.clip(body, 0, 1)  # thin parts a little greyer
    rgba = np.empty((size, size, 4), np.uint8)
    rgba[..., :3] = np.round(255 * shade)[..., None]
    rgba[..., 3] = np.round(255 * alpha)
    return rgba


def main() -> int:
    for name, (seed, blobs, strength) in PUFFS.items():
        out = io.BytesIO()
        Image.fromarray(puff(seed, blobs, strength), "RGBA").save(out, format="PNG", optimize=True)
        (HERE / name).write_bytes(out.getvalue())
        print(f"textures/clouds/{name}: {len(out.getvalue()):,} bytes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
