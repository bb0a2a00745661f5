"""Fin motion (thesis 7.1): back and forth to +/- movement angle, step size degrees a frame.

One cycle 0 -> +A -> 0 -> -A -> 0 takes round(4 A / step) frames. Keys sit at
the turning points and LINEAR interpolation reproduces the constant step, so
the clip is exact at any frame rate. The clip lasts the least common multiple
of all fins' cycles so that every fin loops seamlessly.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MAX_CLIP_FRAMES = 100_000


@dataclass(frozen=True)
class FinMotion:
    amplitude: float      # degrees
    period_frames: int
    sign: float = 1.0     # -1 for a mirrored (right-hand) fin

    @classmethod
    def from_fin(cls, movement_angle: float, step_size: float, sign: float = 1.0) -> FinMotion | None:
        """The fin's motion, None for a still fin; a cycle over MAX_CLIP_FRAMES raises ValueError."""
        if movement_angle <= 0 or step_size <= 0:
            return None
        frames = 4 * movement_angle / step_size   # inf for a subnormal step: checked before round()
        if not frames <= MAX_CLIP_FRAMES:
            raise ValueError(f"a cycle of {frames:.4g} frames")
        return cls(movement_angle, max(4, round(frames)), sign)

    def keys(self, clip_frames: int) -> tuple[np.ndarray, np.ndarray]:
        """(frames, angles in degrees) at every turning point over the clip."""
        quarters = 4 * clip_frames // self.period_frames
        frames = np.arange(quarters + 1) * (self.period_frames / 4.0)
        pattern = np.array([0.0, 1.0, 0.0, -1.0])
        angles = pattern[np.arange(quarters + 1) % 4] * self.amplitude * self.sign
        return frames, angles

    def angle_at(self, frame: np.ndarray | float) -> np.ndarray:
        """Angle (degrees) at any frame: a triangle wave."""
        phase = (np.asarray(frame, dtype=np.float64) / self.period_frames) % 1.0
        tri = np.where(phase < 0.25, 4 * phase, np.where(phase < 0.75, 2 - 4 * phase, 4 * phase - 4))
        return tri * self.amplitude * self.sign


def clip_frames(motions: list[FinMotion]) -> int:
    """Frames of one seamless loop of all motions (their periods' least common multiple)."""
    if not motions:
        return 0
    frames = 1
    for m in motions:
        frames = math.lcm(frames, m.period_frames)
    return frames


def axis_rotation_quaternions(angles_deg: np.ndarray, axis: np.ndarray | None = None) -> np.ndarray:
    """Unit quaternions (x, y, z, w) for rotations about the unit ``axis`` (default +Y)."""
    unit = np.array([0.0, 1.0, 0.0]) if axis is None else np.asarray(axis, dtype=np.float64)
    half = np.radians(np.asarray(angles_deg, dtype=np.float64)) / 2.0
    q = np.empty((len(half), 4))
    q[:, :3] = np.sin(half)[:, None] * unit
    q[:, 3] = np.cos(half)
    return q
