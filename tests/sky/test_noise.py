"""Seeded 3D noise (report section 6.4 c): Perlin's improved noise, fBm, and a cloud roughened by it."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.clouds.fill import fill_cloud
from fishgen.clouds.noise import MAX_AMOUNT, fbm, perlin3, permutation, roughen
from fishgen.sky.build import load_models


def test_noise_is_zero_on_the_lattice_and_within_minus_one_to_one():
    perm = permutation(5)
    lattice = np.random.default_rng(0).integers(-300, 300, (1000, 3)).astype(float)
    assert np.all(perlin3(lattice, perm) == 0)
    values = perlin3(np.random.default_rng(1).uniform(-50, 50, (200_000, 3)), perm)
    assert values.min() >= -1 and values.max() <= 1
    assert 0.15 < values.std() < 0.35 and abs(values.mean()) < 0.01


def test_noise_is_smooth_neighbours_are_alike():
    perm = permutation(2)
    p = np.random.default_rng(3).uniform(-20, 20, (5_000, 3))
    step = 1e-3
    change = np.abs(perlin3(p + step, perm) - perlin3(p, perm))
    # improved noise has a gradient bounded by a few units per lattice cell
    assert change.max() < 10 * step


def test_the_seed_picks_the_field_the_same_seed_the_same_bits():
    p = np.random.default_rng(4).uniform(-10, 10, (10_000, 3))
    a, b, c = perlin3(p, permutation(1)), perlin3(p, permutation(1)), perlin3(p, permutation(2))
    assert a.tobytes() == b.tobytes()
    assert abs(np.corrcoef(a, c)[0, 1]) < 0.1


def test_fbm_fields_are_independent_and_bounded():
    p = np.random.default_rng(5).uniform(-30, 30, (100_000, 3))
    sizes, densities = fbm(p, permutation(9), fields=2)
    assert abs(np.corrcoef(sizes, densities)[0, 1]) < 0.1
    assert np.abs(sizes).max() <= 1 and np.abs(densities).max() <= 1
    one = fbm(p, permutation(9))
    assert one.tobytes() == sizes.tobytes()          # field 0 is the field of a one-field call


@pytest.fixture(scope="module")
def cloud():
    return fill_cloud(load_models()[0][1], seed=0)


def test_roughen_scales_radii_and_densities_coherently_and_keeps_them_valid(cloud):
    rough = roughen(cloud, 0.5, seed=11, scale=2.0)
    assert rough.centers is cloud.centers                         # particles stay where they are
    ratio = rough.radii / cloud.radii
    assert 0.5 - 1e-6 <= ratio.min() and ratio.max() <= 1.5 + 1e-6 and ratio.std() > 0.05
    assert np.all(rough.density > 0) and np.all(rough.density <= 1)
    # coherent: particles close together are scaled alike, far apart independently
    c = cloud.centers.astype(float)
    d = np.linalg.norm(c[:, None] - c[None], axis=2)
    near = np.abs(ratio[:, None] - ratio[None])[(d < 0.2) & (d > 0)]
    far = np.abs(ratio[:, None] - ratio[None])[d > 6]
    assert near.mean() < 0.5 * far.mean()


def test_two_clouds_from_one_file_differ_under_other_noise_seeds_and_not_without_noise(cloud):
    a, b = roughen(cloud, 0.5, seed=1, scale=2.0), roughen(cloud, 0.5, seed=2, scale=2.0)
    assert not np.array_equal(a.radii, b.radii) and not np.array_equal(a.density, b.density)
    assert roughen(cloud, 0.0, seed=1, scale=2.0) is cloud
    with pytest.raises(ValueError):
        roughen(cloud, MAX_AMOUNT + 0.01, seed=1, scale=2.0)
