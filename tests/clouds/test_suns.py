"""Suns from anywhere on cube files fishgen did not ship (issue 32, item 2).

Each random cube file (sun_reference.random_cube_file: 1 to 30 cubes heaped or strung out,
100 to 10^4 particles here, to 10^5 in benchmarks/cloud_suns.py) is written, loaded and filled as
a user's would be, lit under the issue's three suns, one axis direction and two suns uniform on
the sphere, and the baked light ranked against an optical depth towards the sun that the lighting
code did not compute (sun_reference.optical_depth: each particle's 3D Gaussian integrated along
the ray, pairs from a KD-tree). Seeds 0-9 are what the lighting was tuned on (and 20-99, not run
here); 100-119 were held out of the first round, 200-219 out of both.
"""
from __future__ import annotations

import warnings

import pytest
from sun_reference import FRESH, HELD_OUT, TUNED, correlations

GOAL = 0.8
"""Rank correlation of the baked light with -(optical depth towards the sun), every file and sun."""
HIGHEST = 10_000
"""Most particles of a file here (the suite's time); the benchmark goes to 10^5."""


@pytest.mark.parametrize("seed", [*TUNED, *HELD_OUT, *FRESH])
def test_light_falls_with_the_optical_depth_towards_any_sun(seed, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")     # nothing but a file's declared total can warn here
        particles, cubes, got = correlations(seed, tmp_path, highest=HIGHEST)
    low = {sun: round(value, 3) for sun, value in got.items() if value < GOAL}
    assert not low, f"{particles} particles in {cubes} cubes: {low}"


def test_a_dense_cloud_keeps_its_order_where_e_to_the_minus_tau_is_zero(tmp_path):
    """Tuned seed 5 drawn up to 10^5 particles (the benchmark's file): one 6x4x1 cube of 26,002
    particles of radius 3.4, optical depths of 1,300 to 14,500 towards the sun. Its e^-tau is 0 in
    any float; the light scattered many times keeps its order (it ranked 0.32-0.37 without)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        particles, cubes, got = correlations(5, tmp_path, highest=100_000)
    assert (particles, cubes) == (26_002, 1)
    low = {sun: round(value, 3) for sun, value in got.items() if value < GOAL}
    assert not low, low


def test_a_file_strung_out_just_past_small_is_lit_as_a_small_one(tmp_path):
    """Seed 671 drawn up to 10^5 particles (``benchmarks/cloud_suns.py --seeds 600-699``): 2,059
    particles, eleven past SMALL, in 19 cubes strung out over 320 units across a sun from -y.
    Through 32 slabs, whose grid cells were twice its median particle's sigma, it ranked 0.812
    (0.828 through 128); its pairs within reach are as few as a small cloud's, so it is lit pair
    by pair (0.998)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        particles, cubes, got = correlations(671, tmp_path, highest=100_000)
    assert (particles, cubes) == (2_059, 19)
    low = {sun: round(value, 3) for sun, value in got.items() if value < 0.95}
    assert not low, low
