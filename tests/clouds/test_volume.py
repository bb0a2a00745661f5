"""A cloud as voxels (fishgen.clouds.volume): each particle is the Gaussian the lighting shadows with,
as extinction per unit, averaged over each voxel; the light grid is the light the particles carry."""
from __future__ import annotations

import math

import numpy as np
import pytest
from cloud_tables import TABLES

from fishgen.clouds import Lighting, fill_cloud, light_cloud, load_cubes
from fishgen.clouds.light import CUT, peak_optical_depth
from fishgen.clouds.model import MAX_VOXELS
from fishgen.clouds.sprite import SIGMA
from fishgen.clouds.volume import check_cube_files, particle_volume, voxel_box
from fishgen.errors import FishgenError

EXTINCTION = Lighting().extinction
KEPT = math.erf(CUT / math.sqrt(2)) ** 3
"""Share of a 3-D Gaussian's mass within CUT sigma along each axis (the footprint's box)."""


def one(center=(0.0, 0.0, 0.0), radius=1.0, density=1.0, light=0.5):
    return (np.array([center], np.float32), np.array([radius], np.float32), np.array([density], np.float32),
            np.array([light], np.float32))


@pytest.mark.parametrize("voxel_size", [0.2, 1.0, 5.0])
def test_the_grid_holds_every_particles_optical_depth_whatever_the_voxel(voxel_size):
    # a voxel holds the field's mean over it, so particles narrower than a voxel keep their mass
    cloud = fill_cloud(load_cubes(TABLES["4.4"]), seed=0)
    volume = particle_volume(cloud.centers, cloud.radii, cloud.density, None, EXTINCTION, voxel_size)
    sigma = cloud.radii.astype(np.float64) * SIGMA
    expected = (peak_optical_depth(cloud.density, EXTINCTION) * 2 * math.pi * sigma ** 2).sum() * KEPT
    density = dict(volume.grids)["density"]
    assert density.sum(dtype=np.float64) * voxel_size ** 3 == pytest.approx(expected, rel=1e-4)
    assert [name for name, _ in volume.grids] == ["density"]  # an unlit cloud has no light grid


def test_a_ray_through_a_particles_centre_meets_its_peak_optical_depth():
    voxel_size = 1 / 32        # sigma = 0.4: 12.8 voxels across it
    volume = particle_volume(*one(center=(1 / 64, 1 / 64, 0)), EXTINCTION, voxel_size)
    density = dict(volume.grids)["density"]
    at = np.argwhere(volume.active)
    cells = volume.origins[at[:, 0]] + at[:, 1:]
    column = density[tuple(at.T)][(cells[:, 0] == 0) & (cells[:, 1] == 0)].sum() * voxel_size
    # the voxel at the centre averages the Gaussian over its width: a loss of about w^2 / 12 sigma^2
    shrink = (1 - voxel_size ** 2 / (12 * 0.4 ** 2)) ** 2 * math.erf(CUT / math.sqrt(2))
    assert column == pytest.approx(peak_optical_depth(np.array([1.0]), EXTINCTION)[0] * shrink, rel=2e-3)


def test_the_light_grid_is_the_light_of_the_particles_there_weighted_by_their_density():
    centers = np.array([[0, 0, 0], [10, 0, 0], [0.3, 0, 0]], np.float32)
    radii, density = np.ones(3, np.float32), np.array([1, 1, 0.3], np.float32)
    light = np.array([0.2, 0.9, 0.8], np.float32)
    volume = particle_volume(centers, radii, density, light, EXTINCTION, 0.25)
    grids = dict(volume.grids)
    at = np.argwhere(volume.active)
    x = (volume.origins[at[:, 0]] + at[:, 1:])[:, 0] * 0.25
    lit = grids["light"][tuple(at.T)]
    assert np.allclose(lit[x > 5], 0.9, atol=1e-6)                 # alone: its own light
    pair = lit[x < 5]
    assert 0.2 - 1e-6 <= pair.min() and pair.max() <= 0.8 + 1e-6   # between the two that overlap
    assert (grids["light"][~volume.active] == 0).all() and (grids["density"][~volume.active] == 0).all()
    assert (grids["density"][volume.active] > 0).all()


def test_voxels_are_centred_on_multiples_of_the_voxel_size_and_leaves_on_multiples_of_8():
    volume = particle_volume(*one(center=(-3.0, 2.0, 7.5), radius=0.5), EXTINCTION, 0.5)
    assert (volume.origins % 8 == 0).all()
    density = dict(volume.grids)["density"]
    at = np.argwhere(density == density.max())[0]
    assert ((volume.origins[at[0]] + at[1:]) * 0.5).tolist() == [-3.0, 2.0, 7.5]


def test_a_box_of_too_many_voxels_is_refused_naming_a_size_that_fits():
    with pytest.raises(FishgenError) as refused:
        voxel_box((-100, -100, -100), (100, 100, 100), 0.1, "cloud.vdb")
    message = str(refused.value)
    assert message.startswith("cloud.vdb: expected at most 33,554,432 voxels in the volume's bounding box, "
                              "found 8,012,006,001 at voxel size 0.1; use --voxel-size ")
    least = float(message.split("--voxel-size ")[1].split()[0])
    first, last = voxel_box((-100, -100, -100), (100, 100, 100), least)
    assert np.prod(last - first) <= 1.1 * MAX_VOXELS
    with pytest.raises(FishgenError):
        voxel_box((-100, -100, -100), (100, 100, 100), least * 0.9)


def test_a_small_volume_far_from_the_origin_says_the_indices_are_what_it_is_past():
    """At 4e6 with voxels of 0.0035 the box held 27 million voxels, and the refusal said "at most
    33,554,432 ... found 27,270,901; use 0.00327", under the limit and smaller than given (QA pass 9)."""
    with pytest.raises(FishgenError) as refused:
        voxel_box((4e6 - 0.5, -0.5, -0.5), (4e6 + 0.5, 0.5, 0.5), 0.0035, "cloud.vdb")
    assert "expected a volume within 2^30 voxels of the origin" in str(refused.value)
    assert "use --voxel-size 0.00373 or more" in str(refused.value)
    voxel_box((4e6 - 0.5, -0.5, -0.5), (4e6 + 0.5, 0.5, 0.5), 0.00373)


@pytest.mark.parametrize("far", [0.0037212 * 2**30, 4e6, 1e9])
def test_the_voxel_size_a_refusal_suggests_is_taken(far):
    """Rounded to three figures it could fall under what it had to reach: 0.00372, refused again."""
    import re

    lo, hi = (far - 0.5, -0.5, -0.5), (far + 0.5, 0.5, 0.5)
    with pytest.raises(FishgenError) as refused:
        voxel_box(lo, hi, far / 2**30 * 0.9)
    suggested = float(re.search(r"--voxel-size ([0-9.e+-]+) or more", str(refused.value)).group(1))
    voxel_box(lo, hi, suggested)


@pytest.mark.parametrize("voxel_size,found", [(1e-300, "too many to count"), (1e-10, "about 8e+36")])
def test_a_voxel_too_small_to_count_is_refused_without_a_numpy_warning(voxel_size, found):
    """At 1e-300 the box's product overflowed, and numpy's RuntimeWarning reached stderr."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(FishgenError) as refused:
            voxel_box((-100, -100, -100), (100, 100, 100), voxel_size, "cloud.vdb")
    assert f"found {found} at voxel size {voxel_size:g}; use --voxel-size " in str(refused.value)


def test_cube_files_are_refused_before_filling_from_their_cubes_alone():
    cubes = load_cubes(TABLES["4.4"])
    check_cube_files([cubes], (), 0.2)
    with pytest.raises(FishgenError, match="voxels in the volume's bounding box"):
        check_cube_files([cubes], (), 0.02)
    # two clouds far apart make one big box
    with pytest.raises(FishgenError, match="voxels in the volume's bounding box"):
        check_cube_files([cubes, cubes], ((0, 0, 0), (10000, 0, 0)), 0.2)
    # the box from the cubes holds every particle the fill can place, with its reach
    cloud = light_cloud(fill_cloud(cubes, seed=0))
    volume = particle_volume(cloud.centers, cloud.radii, cloud.density, cloud.light, EXTINCTION, 0.2)
    first, last = voxel_box(*_cube_box(cubes), 0.2)
    assert (volume.origins >= first).all() and (volume.origins + 8 <= last).all()


def _cube_box(cubes):
    from fishgen.clouds.volume import reach

    lo = np.min([np.subtract(c.centre, np.divide(c.size, 2)) - reach(c.max_radius) for c in cubes.cubes], 0)
    hi = np.max([np.add(c.centre, np.divide(c.size, 2)) + reach(c.max_radius) for c in cubes.cubes], 0)
    return lo, hi


def test_no_voxel_above_zero_is_refused():
    with pytest.raises(FishgenError, match="expected a voxel of density above 0, found none at voxel size "
                                           "1e\\+30; use a smaller --voxel-size"):
        particle_volume(*one(), EXTINCTION, 1e30)


def test_erfc_is_scipys_to_a_relative_2e_7():
    from scipy.special import erfc as reference  # type: ignore[import-untyped]

    from fishgen.clouds.volume import erfc

    x = np.concatenate([np.linspace(-6, 6, 100_001), [-30.0, 0.0, 9.0]])
    assert np.allclose(erfc(x), reference(x), rtol=2e-7, atol=0)
