"""A 4:2:0 JPEG's colour drawn again at full size, along its own brightness.

Such a JPEG keeps brightness (luma) for every pixel but colour (chroma) for each 2 x 2 block only,
and the decoder spreads each block's colour smoothly over its neighbours: a fish's colour leaks a
pixel or two into the water round it, and a fin one or two pixels wide takes half the water's
colour. Each pixel here takes the colour of the nearest blocks whose brightness is like its own
(joint bilateral upsampling, Kopf et al. 2007), from the file's own half-size colour planes.
"""
from __future__ import annotations

import numpy as np

LEVELS = 2.0      # luma levels (0-255) by which a block's brightness may differ from a pixel's
SPREAD = 1.4      # px: the distance over which a block's colour reaches
ROWS = 512        # rows of pixels drawn at once, so a big photo's temporaries stay small
#: a block's weight by its distance: the pixel's own block (0.5 px off each way), the next one
#: across, down, or both (1.5 px off); blocks further off would weigh under a sixth
NEAR = tuple(1.0 / (1.0 + 0.5 * d2 / SPREAD ** 2) ** 2 for d2 in (0.5, 2.5, 4.5))


def redraw(rgb: np.ndarray, half: np.ndarray) -> np.ndarray:
    """``rgb`` (H, W, 3 uint8, as decoded) with its colour drawn again from ``half``, the file's
    YCbCr planes at their own size ((H + 1) // 2, (W + 1) // 2, 3 uint8: luma scaled down, chroma
    as stored). Weights are rational, not exponential, so every CPU draws the same bytes."""
    h, w = rgb.shape[:2]
    planes = np.pad(half.astype(np.float32), ((1, 1), (1, 1), (0, 0)), mode="edge")
    planes[..., 1:] -= 128.0
    cols = np.arange(w)
    # each pixel's own block column, and the one on its side of it (blocks' centres: 2b + 0.5)
    columns = (cols // 2 + 1, cols // 2 + 2 * (cols % 2))
    out = np.empty_like(rgb)
    for top in range(0, h, ROWS):   # ROWS is even, so a strip starts on a block's first row
        stop = min(top + ROWS, h)
        base = top // 2             # the padded block row above the strip's first
        strip = planes[base:stop // 2 + 3]
        across = [strip[:, c] for c in columns]
        for parity in (0, 1):   # a row's own block row and the next one towards it are slices
            first = top + parity
            if first >= stop:
                continue
            f = rgb[first:stop:2].astype(np.float32)
            n = f.shape[0]
            luma = 0.299 * f[..., 0] + 0.587 * f[..., 1] + 0.114 * f[..., 2]
            cb = np.zeros_like(luma)
            cr = np.zeros_like(luma)
            total = np.zeros_like(luma)
            own = first // 2 + 1 - base
            for a, start in ((0, own), (1, own + 2 * parity - 1)):
                for b in (0, 1):
                    near = across[b][start:start + n]
                    step = (luma - near[..., 0]) * (1.0 / LEVELS)
                    weight = NEAR[a + b] / (1.0 + 0.5 * step * step) ** 2
                    cb += weight * near[..., 1]
                    cr += weight * near[..., 2]
                    total += weight
            cb /= total
            cr /= total
            drawn = np.stack([luma + 1.402 * cr, luma - 0.344136 * cb - 0.714136 * cr,
                              luma + 1.772 * cb], -1)
            out[first:stop:2] = np.clip(np.rint(drawn), 0, 255).astype(np.uint8)
    return out
