"""Numeric helpers shared by assembly, writers, readers and the renderer (each in one place)."""
from __future__ import annotations

import functools

import numpy as np

FLOAT32_MAX = float(np.finfo(np.float32).max)
"""Largest finite float32: every coordinate fishgen writes is float32."""


def srgb_to_linear(c) -> np.ndarray:
    """sRGB-encoded values in [0, 1] to linear light (float32)."""
    c = np.asarray(c, np.float32)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)


def linear_to_srgb(c) -> np.ndarray:
    """Linear light in [0, 1] to sRGB-encoded values (float32)."""
    c = np.clip(np.asarray(c, np.float32), 0.0, 1.0)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * c ** (1 / 2.4) - 0.055).astype(np.float32)


@functools.cache
def srgb8_to_linear16() -> np.ndarray:
    """256-entry table: an sRGB byte to linear light as a normalized uint16.

    16 bits keep every one of the 256 sRGB levels distinct in linear light (8
    bits would merge the darkest dozen), so glTF's linear COLOR_0 round-trips
    to the exact sRGB bytes PLY and CSV carry.
    """
    lin = srgb_to_linear(np.arange(256) / 255.0).astype(np.float64)
    return np.round(lin * 65535.0).astype(np.uint16)


@functools.cache
def linear16_to_srgb8() -> np.ndarray:
    """65536-entry table, the inverse of :func:`srgb8_to_linear16` (nearest sRGB byte)."""
    forward = srgb8_to_linear16().astype(np.int64)
    levels = np.arange(65536)
    upper = np.clip(np.searchsorted(forward, levels), 0, 255)
    lower = np.clip(upper - 1, 0, 255)
    nearer_lower = np.abs(levels - forward[lower]) <= np.abs(forward[upper] - levels)
    return np.where(nearer_lower, lower, upper).astype(np.uint8)


def to_linear_float(colors: np.ndarray) -> np.ndarray:
    """A COLOR_0 array (float, or normalized uint8/uint16) as float32 RGBA in [0, 1]."""
    c = np.asarray(colors)
    out: np.ndarray = (c.astype(np.float32) / np.iinfo(c.dtype).max if c.dtype.kind in "iu"
                       else c.astype(np.float32))
    if out.shape[1] == 3:
        out = np.hstack([out, np.ones((len(out), 1), np.float32)])
    return out
