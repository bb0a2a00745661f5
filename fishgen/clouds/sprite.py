"""The billboard sprite: white, with a radial Gaussian alpha that reaches 0 at the quad's edge."""
from __future__ import annotations

import functools
import io

import numpy as np

SIZE = 64
SIGMA = 0.4  # in units of the quad's half width: alpha is e^-0.5 at 40 % of the radius


@functools.cache
def gaussian_sprite_png(size: int = SIZE, sigma: float = SIGMA) -> bytes:
    """PNG bytes of an RGBA sprite; the Gaussian is shifted and rescaled to hit 0 at r = 1."""
    from PIL import Image

    centres = (np.arange(size) + 0.5) / size * 2 - 1
    r2 = centres[None, :] ** 2 + centres[:, None] ** 2
    floor = np.exp(-0.5 / sigma**2)
    alpha = np.clip((np.exp(-0.5 * r2 / sigma**2) - floor) / (1 - floor), 0, 1)
    rgba = np.full((size, size, 4), 255, np.uint8)
    rgba[..., 3] = np.round(alpha * 255).astype(np.uint8)
    out = io.BytesIO()
    Image.fromarray(rgba, "RGBA").save(out, format="PNG")
    return out.getvalue()
