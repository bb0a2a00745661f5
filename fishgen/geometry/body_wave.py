"""The carangiform body wave: lateral midline displacement h(x, t) = a(x) sin(2 pi (x / lambda - f t)).

x is the position along the fish from the nose (0) to the tail tip (1) in body lengths, h is in body
lengths. A travelling wave with a fixed envelope is the sum of two standing waves,

    h = S(x) cos(phi) - C(x) sin(phi),   S = a sin(2 pi x / lambda),  C = a cos(2 pi x / lambda),

with phi = 2 pi f t (or the integral of 2 pi f dt when the speed changes). Exported as four morph
targets +S, -S, +C, -C whose weights stay in [0, 1] (`wave_weights`), so clients that clip
negative weights (Blender's importer, glTF-Blender-IO issue 1364) still play the full amplitude.

Defaults (docs/decisions.md): the envelope is the quadratic fitted to saithe and mackerel by
Videler & Hess (1984), as used by Borazjani & Sotiropoulos (2008): a(x) = 0.02 - 0.0825 x +
0.1625 x^2, so a(1) = 0.1 body length; wavelength 0.95 body length; Strouhal number 0.3.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fishgen.fish_modes import MAX_TAIL_BEAT_HZ


@dataclass(frozen=True)
class BodyWave:
    """Parameters of the wave, in body lengths and seconds."""

    envelope: tuple[float, float, float] = (0.02, -0.0825, 0.1625)  # a(x) = c0 + c1 x + c2 x^2
    wavelength: float = 0.95          # body lengths
    strouhal: float = 0.3             # St = f A / U, A = peak-to-peak tail-tip amplitude
    max_frequency: float = MAX_TAIL_BEAT_HZ  # Hz: a cap for absurd speeds

    def amplitude(self, x: np.ndarray | float) -> np.ndarray:
        """a(x): the wave's amplitude (half the peak-to-peak excursion) in body lengths."""
        x = np.asarray(x, dtype=np.float64)
        c0, c1, c2 = self.envelope
        return c0 + c1 * x + c2 * x * x

    @property
    def tail_peak_to_peak(self) -> float:
        """A = 2 a(1), body lengths: the Strouhal number's amplitude."""
        return 2.0 * float(self.amplitude(1.0))

    def frequency(self, speed: np.ndarray | float) -> np.ndarray:
        """Tail-beat frequency (Hz) at swimming speed U (body lengths per second): f = St U / A,
        at most ``max_frequency``."""
        return np.minimum(self._strouhal_frequency(speed), self.max_frequency)

    def capped(self, speed: float) -> bool:
        """Whether ``speed`` asks for a faster tail beat than ``max_frequency``."""
        return bool(self._strouhal_frequency(speed) > self.max_frequency)

    def _strouhal_frequency(self, speed: np.ndarray | float) -> np.ndarray:
        return self.strouhal * np.abs(np.asarray(speed, dtype=np.float64)) / self.tail_peak_to_peak

    def shapes(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The two standing waves S(x), C(x) (body lengths) at positions x along the body."""
        a = self.amplitude(x)
        k = 2.0 * np.pi * np.asarray(x, dtype=np.float64) / self.wavelength
        return a * np.sin(k), a * np.cos(k)

    def displacement(self, x: np.ndarray, phase: np.ndarray | float) -> np.ndarray:
        """h(x, phi) for phi = 2 pi f t: broadcast over x and phase."""
        s, c = self.shapes(x)
        return s * np.cos(phase) - c * np.sin(phase)


def check_wave(wave: BodyWave) -> None:
    """ValueError unless the wave is usable: finite, a positive wavelength and Strouhal number."""
    numbers = (*wave.envelope, wave.wavelength, wave.strouhal, wave.max_frequency)
    if not all(np.isfinite(numbers)):
        raise ValueError(f"expected finite body-wave parameters, found {numbers}")
    if wave.wavelength <= 0 or wave.strouhal <= 0 or wave.tail_peak_to_peak <= 0:
        raise ValueError("expected a positive wavelength, Strouhal number and tail amplitude, found "
                         f"{wave.wavelength}, {wave.strouhal}, {wave.tail_peak_to_peak}")


def wave_targets(x: np.ndarray, wave: BodyWave) -> np.ndarray:
    """Lateral displacement (body lengths) of the four targets +S, -S, +C, -C: shape (4, len(x))."""
    s, c = wave.shapes(x)
    return np.stack([s, -s, c, -c])


def wave_weights(phase: np.ndarray) -> np.ndarray:
    """Weights (..., 4) in [0, 1] of targets +S, -S, +C, -C that make S cos(phi) - C sin(phi)."""
    cos, sin = np.cos(phase), np.sin(phase)
    return np.stack([np.maximum(cos, 0.0), np.maximum(-cos, 0.0),
                     np.maximum(-sin, 0.0), np.maximum(sin, 0.0)], axis=-1)


def integrate_phase(frequency: np.ndarray, dt: float, start: np.ndarray | float = 0.0) -> np.ndarray:
    """phi(t) = start + 2 pi * integral of f dt over frames (axis 0), by the trapezoid rule, so the
    phase stays continuous however the frequency changes."""
    f = np.asarray(frequency, dtype=np.float64)
    steps = 0.5 * (f[1:] + f[:-1]) * dt
    phase = np.concatenate([np.zeros((1, *f.shape[1:])), np.cumsum(steps, axis=0)])
    return np.asarray(start) + 2.0 * np.pi * phase
