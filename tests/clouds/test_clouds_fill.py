"""The randomized fill (report 4.5): placement, counts, radii, octants, fit, determinism."""
from __future__ import annotations

import math

import numpy as np
import pytest
from cloud_tables import TABLES
from scipy import stats

from fishgen.clouds import Cube, CubeFile, Lighting, fill_cloud, light_cloud, load_cubes, merge_clouds
from fishgen.errors import FishgenError

METHODS = ("paper", "uniform")


def one_cube(particles, size=(8.0, 3.0, 7.0), centre=(1.0, 2.0, -3.0), radius=2.0):
    return CubeFile("test", particles, (Cube(particles, size, centre, radius),))


def cube_arrays(cube_file, offset=(0, 0, 0)):
    """Per-cube centre, half size and max radius straight from the parsed file."""
    centre = np.array([c.centre for c in cube_file.cubes]) + np.asarray(offset)
    half = np.array([c.size for c in cube_file.cubes]) / 2
    rmax = np.array([c.max_radius for c in cube_file.cubes])
    return centre, half, rmax


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("table", sorted(TABLES))
def test_counts_placement_radii_density(table, method):
    cubes = load_cubes(TABLES[table])
    offset = (100.0, -20.0, 5.5)
    cloud = fill_cloud(cubes, seed=11, method=method, offset=offset)
    counts = [c.particles for c in cubes.cubes]
    assert len(cloud) == sum(counts)
    assert np.bincount(cloud.cube_index, minlength=len(counts)).tolist() == counts
    assert np.all(np.diff(cloud.cube_index) >= 0)

    centre, half, rmax = cube_arrays(cubes, offset)
    k = cloud.cube_index
    p = cloud.centers.astype(np.float64)
    assert np.all(np.abs(p - centre[k]) <= half[k]), "a centre left its own cube"
    assert np.all(cloud.radii > 0) and np.all(cloud.radii <= rmax[k].astype(np.float32))
    assert np.all(cloud.density > 0) and np.all(cloud.density <= 1)
    assert (cloud.centers.dtype, cloud.radii.dtype, cloud.density.dtype, cloud.colors.dtype) == (
        np.float32, np.float32, np.float32, np.uint8)


@pytest.mark.parametrize("method", METHODS)
def test_every_octant_of_every_big_cube_is_populated(method):
    # Table 4.2's 1000-particle cube, plus big and very flat cubes.
    cubes = list(load_cubes(TABLES["4.2"]).cubes) + [
        Cube(1000, (20.0, 0.3, 5.0), (0.0, -40.0, 0.0), 1.0),
        Cube(5000, (1.0, 1.0, 1.0), (50.0, 0.0, 0.0), 0.5),
        Cube(20000, (7.39642, 1.07048, 2.89284), (-3.4, -3.3, -0.6), 2.1)]
    cube_file = CubeFile("octants", sum(c.particles for c in cubes), tuple(cubes))
    for seed in range(3):
        cloud = fill_cloud(cube_file, seed=seed, method=method)
        centre, _, _ = cube_arrays(cube_file)
        for k, cube in enumerate(cube_file.cubes):
            if cube.particles < 1000:
                continue
            side = cloud.centers[cloud.cube_index == k] > centre[k]
            octant = side[:, 0] * 4 + side[:, 1] * 2 + side[:, 2]
            assert np.bincount(octant, minlength=8).min() > 0, (seed, k)


def normalised(cloud, cube_file):
    centre, half, _ = cube_arrays(cube_file)
    return (cloud.centers - centre[cloud.cube_index]) / half[cloud.cube_index]


def test_uniform_method_fits_uniform_positions_and_radii():
    cube_file = one_cube(40_000)
    cloud = fill_cloud(cube_file, seed=5, method="uniform")
    s = normalised(cloud, cube_file)
    for axis in range(3):
        assert stats.kstest(s[:, axis], stats.uniform(-1, 2).cdf).pvalue > 1e-3
    counts, _ = np.histogramdd(s, bins=4, range=[(-1, 1)] * 3)
    assert stats.chisquare(counts.ravel()).pvalue > 1e-3
    assert stats.kstest(cloud.radii / 2.0, stats.uniform(0, 1).cdf).pvalue > 1e-3


def test_paper_method_is_clumped_not_uniform():
    cube_file = one_cube(40_000)
    s = normalised(fill_cloud(cube_file, seed=5, method="paper"), cube_file)
    counts, _ = np.histogramdd(s, bins=4, range=[(-1, 1)] * 3)
    assert stats.chisquare(counts.ravel()).pvalue < 1e-12
    # ... yet spread over the whole cube, not piled into one corner (the eq. 4.8 misprint).
    assert np.abs(s.mean(axis=0)).max() < 0.1
    assert (s.min(axis=0) < -0.9).all() and (s.max(axis=0) > 0.9).all()


def test_paper_radii_follow_eq_4_12_renormalised():
    cloud = fill_cloud(one_cube(40_000, radius=3.0), seed=2, method="paper")
    # r/R = f(u)/f(1) with f(u) = u + pi/2 sin u and u uniform in (0, 1]: invert f numerically.
    u = np.linspace(0, 1, 10_001)
    f = (u + math.pi / 2 * np.sin(u)) / (1 + math.pi / 2 * math.sin(1))
    cdf = lambda r: np.interp(r, f, u)  # noqa: E731
    assert stats.kstest(cloud.radii / 3.0, cdf).pvalue > 1e-3
    assert stats.kstest(cloud.radii / 3.0, stats.uniform(0, 1).cdf).pvalue < 1e-6


def test_density_is_the_gaussian_fall_off_from_the_cube_centre():
    cube_file = one_cube(5000)
    cloud = fill_cloud(cube_file, seed=1)
    s = normalised(cloud, cube_file)
    np.testing.assert_allclose(cloud.density, np.exp(-(s ** 2).sum(axis=1)), rtol=1e-4)


def test_a_filled_cloud_is_unlit_and_white():
    """The fill places particles; their colour comes from the sun (tests/clouds/test_light.py)."""
    cloud = fill_cloud(load_cubes(TABLES["4.4"]), seed=3)
    assert (cloud.colors == 255).all() and cloud.light is None and cloud.lighting is None


@pytest.mark.parametrize("method", METHODS)
def test_same_seed_same_bytes_whatever_the_thread_count(method):
    cube_file = one_cube(300_000)  # several chunks
    a = fill_cloud(cube_file, seed=9, method=method, workers=1)
    b = fill_cloud(cube_file, seed=9, method=method, workers=2)
    c = fill_cloud(cube_file, seed=10, method=method)
    for name in ("centers", "radii", "density", "colors", "cube_index"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes()
    assert a.centers.tobytes() != c.centers.tobytes()


def test_offset_moves_the_cloud():
    cubes = load_cubes(TABLES["4.3"])
    here = fill_cloud(cubes, seed=4)
    there = fill_cloud(cubes, seed=4, offset=(10, 20, 30))
    np.testing.assert_allclose(there.centers - here.centers,
                               np.broadcast_to([10, 20, 30], here.centers.shape), atol=1e-5)
    np.testing.assert_array_equal(there.radii, here.radii)
    np.testing.assert_allclose(there.cube_bounds - here.cube_bounds,
                               np.broadcast_to([10, 20, 30], here.cube_bounds.shape))


def test_merge_renumbers_cubes_and_keeps_everything():
    a = fill_cloud(load_cubes(TABLES["4.3"]), seed=1)
    b = fill_cloud(load_cubes(TABLES["4.4"]), seed=2, offset=(40, 0, 0))
    scene = merge_clouds([a, b])
    assert len(scene) == 554 + 615 and len(scene.cube_bounds) == 17 + 23
    assert scene.cube_index[554:].min() == 17
    lo, hi = scene.cube_bounds[scene.cube_index, 0], scene.cube_bounds[scene.cube_index, 1]
    assert np.all((scene.centers >= lo) & (scene.centers <= hi))
    assert merge_clouds([a]) is a
    with pytest.raises(FishgenError, match="expected at least one cloud to merge, found none"):
        merge_clouds([])


def test_bad_method_seed_and_offset_are_said_as_the_command_line_says_them():
    """A library caller's offset of two numbers was numpy's "cannot reshape array of size 2"."""
    with pytest.raises(FishgenError, match="expected a fill method of paper or uniform, found 'gaussian'"):
        fill_cloud(one_cube(10), method="gaussian")
    with pytest.raises(FishgenError, match="expected a seed as a whole number of 0 or more, found -1"):
        fill_cloud(one_cube(10), seed=-1)
    with pytest.raises(FishgenError, match=r"an offset of three numbers \(x, y, z\), found \(1, 2\)"):
        fill_cloud(one_cube(10), offset=(1, 2))
    with pytest.raises(FishgenError, match=r"expected a seed as a whole number of 0 or more, found 1\.5"):
        fill_cloud(one_cube(10), seed=1.5)   # type: ignore[arg-type]


def test_a_cube_file_made_in_python_is_checked_before_its_arrays_are_made():
    """The parser refuses these; a CubeFile made in Python reached numpy (its raw errors, or a
    MemoryError after gigabytes were taken)."""
    from fishgen.errors import UsageError

    with pytest.raises(FishgenError, match=r"^test: expected a cube of 0 or more particles, found -5$"):
        fill_cloud(one_cube(-5))
    with pytest.raises(UsageError, match=r"expected a cloud that fits in .*, found 1,000,000,000,000 "):
        fill_cloud(one_cube(10**12))


def test_phase_shift_is_eq_4_5_to_4_7_as_decided():
    """The hot loop folds constants; check it against the equations written out in float64."""
    from fishgen.clouds.fill import CLUMP, _phase_shift

    s = np.random.default_rng(0).uniform(-1, 1, (3, 10_000)).astype(np.float32)
    got = s.copy()
    _phase_shift(got)
    theta = math.pi * s.astype(np.float64)                        # a cube spans one period
    px = math.pi / 2 * np.sin(0.5 * theta[1])                     # eq. 4.5
    py = math.pi / 2 * np.sin(0.5 * theta[0])
    pz = math.pi / 2 * np.sin(0.5 * theta[2])
    px = px + math.pi * np.sin(px * theta[2] / 2)                 # eq. 4.6
    py = py + math.pi * np.sin(py * theta[2] / 2)                 # P_y where the print has P_x
    want = s + CLUMP / math.pi * np.stack([px, py, pz])           # eq. 4.7, in half extents
    np.testing.assert_allclose(got, want, atol=1e-6)


@pytest.mark.parametrize("offset,message", [
    ((1e300, 0, 0), r"^test: expected an offset within float32 range .*found \(1e\+300, 0, 0\)"),
    ((0, float("nan"), 0), r"^test: expected an offset within float32 range"),
    # the cube is fine where its file puts it, so the offset is blamed, not the file's line
    ((0, 0, 3.4e38), r"^expected an offset that keeps each cube at least one float32 step wide on "
                     r"each axis, found \(0, 0, 3.4e\+38\), which moves the cube of test:7 to corners"),
    ((0, 0, -3.4e38), r"^expected an offset that keeps each cube at least one float32 step wide"),
])
def test_offsets_and_cubes_outside_float32_are_refused(offset, message):
    from fishgen.errors import FishgenError
    cube_file = CubeFile("test", 5, (Cube(5, (8.0, 3.0, 7.0), (1.0, 2.0, -3.0), 2.0, 7),))
    with pytest.raises(FishgenError, match=message):
        fill_cloud(cube_file, offset=offset)


def test_cube_past_float32_after_the_offset_is_refused_as_the_offsets_fault():
    from fishgen.errors import UsageError
    cube_file = CubeFile("test", 5, (Cube(5, (2e37, 1.0, 1.0), (2e38, 0.0, 0.0), 2.0, 3),))
    with pytest.raises(UsageError, match=r"^expected an offset that keeps each cube within float32 "
                                         r"range .*, found \(1.5e\+38, 0, 0\), which moves the cube of "
                                         r"test:3 to corners \(3.4e\+38"):
        fill_cloud(cube_file, offset=(1.5e38, 0, 0))


def test_cube_past_float32_on_its_own_is_the_files_fault_whatever_the_offset():
    from fishgen.errors import FishgenError, UsageError
    cube_file = CubeFile("test", 5, (Cube(5, (2e38, 1.0, 1.0), (2.5e38, 0.0, 0.0), 2.0, 3),))
    with pytest.raises(FishgenError, match=r"^test:3: expected a cube within float32 range") as caught:
        fill_cloud(cube_file, offset=(1.0, 0, 0))
    assert not isinstance(caught.value, UsageError)


def test_cube_too_thin_for_float32_at_its_position_is_refused():
    from fishgen.errors import FishgenError
    # 1 unit tall at y = 3e38, where float32 steps are 2e31: no float32 y lies inside it.
    with pytest.raises(FishgenError, match=r"^test: expected a cube at least one float32 step wide"):
        fill_cloud(one_cube(3, size=(1.0, 1.0, 1.0), centre=(0.0, 3e38, 0.0)))


def test_cubes_at_the_ends_of_float32_fill_without_overflow_warnings():
    import warnings
    cubes = CubeFile("test", 400, (Cube(200, (1.0, 1e37, 1.0), (0.0, 3e38, 0.0), 1.0),
                                   Cube(200, (1.0, 1e37, 1.0), (0.0, -3e38, 0.0), 1.0)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        cloud = fill_cloud(cubes, seed=1)
    assert np.isfinite(cloud.centers).all()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lit = light_cloud(cloud, Lighting(sun=(0, 1, 0)))
    assert np.isfinite(lit.light).all() and (lit.light >= 0).all() and (lit.light <= 1).all()
    for k in range(2):
        lo, hi = cloud.cube_bounds[k]
        part = cloud.centers[cloud.cube_index == k].astype(np.float64)
        assert ((part >= lo) & (part <= hi)).all()
