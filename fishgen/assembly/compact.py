"""Smaller animation, the core glTF way: rotation keys and morph weights as normalized 16-bit integers.

glTF 2.0 allows an animation sampler's output to be normalized integers for rotations (signed)
and morph weights (signed or unsigned); no extension is needed. Rotations become signed shorts
(each component rounded to 1/32767), weights, which fishgen keeps in [0, 1], unsigned shorts
(1/65535). Key times and translations stay float, as glTF requires.
"""
from __future__ import annotations

import numpy as np

from fishgen.scene.model import Scene

ROTATION = np.int16
WEIGHTS = np.uint16


def quantize_rotations(quaternions: np.ndarray) -> np.ndarray:
    """Unit quaternions as normalized signed shorts (x, y, z, w each rounded to 1/32767)."""
    q = np.asarray(quaternions, np.float64)
    q = q / np.maximum(np.linalg.norm(q, axis=-1, keepdims=True), 1e-30)
    return np.round(np.clip(q, -1.0, 1.0) * np.iinfo(ROTATION).max).astype(ROTATION)


def quantize_weights(weights: np.ndarray) -> np.ndarray:
    """Morph weights in [0, 1] as normalized unsigned shorts; ValueError for any outside."""
    w = np.asarray(weights, np.float64)
    if w.size and (w.min() < -1e-6 or w.max() > 1 + 1e-6):
        raise ValueError(f"weights outside [0, 1]: {w.min():g} .. {w.max():g}")
    return np.round(np.clip(w, 0.0, 1.0) * np.iinfo(WEIGHTS).max).astype(WEIGHTS)


def rotation_error_degrees(quaternions: np.ndarray, stored: np.ndarray) -> float:
    """The largest angle between each rotation and what a client reads back from ``stored``
    (divided by 32767 and renormalized, as slerp and node matrices do)."""
    q = np.asarray(quaternions, np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    back = np.asarray(stored, np.float64) / np.iinfo(ROTATION).max
    back = back / np.linalg.norm(back, axis=-1, keepdims=True)
    dot = np.clip(np.abs(np.sum(q * back, axis=-1)), 0.0, 1.0)
    return float(np.degrees(2.0 * np.arccos(dot)).max()) if dot.size else 0.0


def compact_clips(scene: Scene) -> float:
    """Quantize every rotation and weights sampler of ``scene`` in place (each once, however many
    channels share it); returns the largest rotation error added, in degrees."""
    done: set[int] = set()
    worst = 0.0
    for clip in scene.clips:
        for channel in clip.channels:
            smp = channel.sampler
            if id(smp) in done or channel.sampler.interpolation == "CUBICSPLINE":
                continue
            done.add(id(smp))
            values = np.asarray(smp.values)
            if values.dtype.kind in "iu":
                continue
            if channel.path == "rotation":
                smp.values = quantize_rotations(values)
                worst = max(worst, rotation_error_degrees(values, smp.values))
            elif channel.path == "weights":
                smp.values = quantize_weights(values)
    return worst
