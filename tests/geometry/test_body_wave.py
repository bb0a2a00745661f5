"""The body wave's numbers: envelope, Strouhal frequency, four non-negative weights, phase."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.geometry.body_wave import BodyWave, check_wave, integrate_phase, wave_targets, wave_weights


def test_envelope_is_small_at_the_head_and_a_tenth_at_the_tail():
    wave = BodyWave()
    x = np.linspace(0, 1, 101)
    a = wave.amplitude(x)
    assert a[-1] == pytest.approx(0.1, abs=1e-9) and a.max() == a[-1]
    assert a.min() > 0 and a[:30].max() < 0.25 * a[-1]      # the front third barely moves


def test_frequency_follows_speed_at_the_strouhal_number():
    wave = BodyWave(strouhal=0.3)
    speeds = np.array([0.5, 1.0, 2.0])
    f = wave.frequency(speeds)
    assert np.allclose(f * wave.tail_peak_to_peak / speeds, 0.3)
    assert wave.frequency(1e6) == wave.max_frequency


@pytest.mark.parametrize("phase", np.linspace(-7, 7, 29))
def test_four_weights_in_unit_range_make_the_travelling_wave(phase):
    wave = BodyWave()
    x = np.linspace(0, 1, 50)
    w = wave_weights(np.array(phase))
    assert w.shape == (4,) and np.all((w >= 0) & (w <= 1))
    assert np.allclose(w @ wave_targets(x, wave), wave.displacement(x, phase))


def test_the_wave_travels_from_head_to_tail():
    wave = BodyWave()
    x = np.linspace(0.1, 1.0, 500)
    # a crest moves to larger x as the phase advances: lambda / 2 pi further per radian
    phases = np.linspace(0, 2, 6)
    crest = [x[np.argmax(wave.displacement(x, p) / wave.amplitude(x))] for p in phases]
    assert np.allclose(np.diff(crest), wave.wavelength / (2 * np.pi) * 0.4, atol=0.004)


def test_phase_integrates_a_changing_frequency_without_jumps():
    f = np.concatenate([np.full(30, 1.0), np.linspace(1.0, 4.0, 30), np.full(30, 4.0)])
    phase = integrate_phase(f[:, None], 1 / 30, start=np.array([0.5]))
    steps = np.diff(phase[:, 0])
    assert phase[0, 0] == 0.5 and np.all(steps > 0)
    assert np.allclose(steps[:29], 2 * np.pi / 30) and np.allclose(steps[-29:], 2 * np.pi * 4 / 30)


@pytest.mark.parametrize("bad", [dict(wavelength=0), dict(strouhal=-1), dict(envelope=(0, 0, float("nan")))])
def test_unusable_waves_are_refused(bad):
    with pytest.raises(ValueError, match="expected"):
        check_wave(BodyWave(**bad))
