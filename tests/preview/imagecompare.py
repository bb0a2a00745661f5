"""How far two renders are apart, in the two measures the reference tests use."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from PIL import Image

MEAN_TOLERANCE = 1.5
"""Mean absolute difference per channel (0-255) allowed between a render and its reference."""
CHANGED_TOLERANCE = 0.2
"""Per cent of pixels allowed to differ by more than CHANGED_LEVEL in some channel: catches
small parts (a lost fin) that the whole-image mean dilutes."""
CHANGED_LEVEL = 32


@dataclass
class Difference:
    mean: float
    changed_percent: float

    @property
    def within_tolerance(self) -> bool:
        return self.mean < MEAN_TOLERANCE and self.changed_percent < CHANGED_TOLERANCE

    def __str__(self) -> str:
        return (f"mean |diff| {self.mean:.2f} (tolerance {MEAN_TOLERANCE}), "
                f"{self.changed_percent:.3f}% pixels changed (tolerance {CHANGED_TOLERANCE}%)")


def difference(a, b) -> Difference:
    """Compare two images (paths or PIL images) of the same size, as RGB."""
    x = np.asarray((Image.open(a) if not isinstance(a, Image.Image) else a).convert("RGB"), np.float32)
    y = np.asarray((Image.open(b) if not isinstance(b, Image.Image) else b).convert("RGB"), np.float32)
    assert x.shape == y.shape, f"sizes differ: {x.shape} vs {y.shape}"
    d = np.abs(x - y)
    return Difference(float(d.mean()), float((d.max(-1) > CHANGED_LEVEL).mean() * 100))
