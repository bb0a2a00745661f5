"""Sunlight baked into a cloud (Harris's first pass): checked against brute force and by invariants.

The particle model the light is computed for: particle j's optical depth across the sun's
rays is a Gaussian of width sigma_j = 0.4 radius_j with peak Li2(1 - exp(-extinction x
density_j)) (the shadow of SkyWorks' splat), and it shades particle i as far as it lies nearer
the sun than i's sunward face, FRONT sigma_i before its centre: Phi((t - FRONT sigma_i) / sigma_j)
of it, t how much nearer j's centre is. With
scattering off a particle's effective depth is tau, summed over those shares; with scattering
on, depth d passes on e^-d + F (1 - e^-d) of the light (Harris's recurrence, report eq. 3.12,
along the ray), to the same share. The light behind effective depth E is e^-E, and a share
DIFFUSE of the sun falling as 1 / (1 + E) (light scattered many times), so that it never
reaches 0. A small cloud is lit so pair by pair; a big one through slabs of a grid, checked
against the small one's light.
"""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from cloud_tables import TABLES
from scipy import special, stats

import fishgen.clouds.light as light_module
from fishgen.clouds import Cloud, Lighting, export_cloud, fill_cloud, light_cloud, load_cubes, merge_clouds
from fishgen.clouds.light import DIFFUSE, incident_light, light_of_depth, lit_colors, peak_optical_depth
from fishgen.clouds.lighting import EXTRAS_KEY, from_extras
from fishgen.errors import FishgenError

SUNS = {"above": (0.35, 1.0, 0.55), "side": (1.0, 0.2, 0.0), "below": (0.2, -1.0, 0.3)}


def random_cloud(n=300, seed=3, radii=(1.0, 2.0), box=(8.0, 4.0, 6.0)):
    """Particles whose widths the light grid resolves (radii within a factor 2)."""
    rng = np.random.default_rng(seed)
    return (rng.random((n, 3)) * box).astype(np.float32), \
        rng.uniform(*radii, n).astype(np.float32), rng.uniform(0.05, 1, n).astype(np.float32)


def brute_force(centers, radii, density, lighting):
    """(light, tau) per particle over every pair, in float64: each other particle's Gaussian
    across the sun's rays at this one's centre (uncut), times the share of it nearer the sun than
    this one's sunward face."""
    sun = np.array(lighting.sun_unit)
    p = centers.astype(np.float64)
    sigma = 0.4 * radii.astype(np.float64)
    peak = special.spence(np.exp(-density.astype(np.float64) * lighting.extinction))   # Li2(1 - e^-x)
    f = lighting.forward_fraction
    n = len(p)
    light, tau = np.empty(n), np.empty(n)
    for i in range(n):
        q = p - p[i]
        t = q @ sun                                                   # > 0: nearer the sun than i
        r2 = np.maximum((q * q).sum(axis=1) - t * t, 0.0)
        depth = peak * np.exp(-r2 / (2 * sigma**2))
        share = special.ndtr((t - light_module.FRONT * sigma[i]) / sigma)
        share[i] = 0.0
        tau[i] = (share * depth).sum()
        light[i] = np.prod((np.exp(-depth) + f * -np.expm1(-depth)) ** share)
    return light, tau


def behind(depth):
    """The light behind an effective optical depth: e^-E, and DIFFUSE falling as 1 / (1 + E)."""
    depth = np.asarray(depth, np.float64)
    return np.exp(-depth) + DIFFUSE * (1 / (1 + depth) - np.exp(-depth))


def luminance(colors: np.ndarray) -> np.ndarray:
    from fishgen.numeric import srgb_to_linear

    return srgb_to_linear(colors / 255.0) @ np.array([0.2126, 0.7152, 0.0722])


# -- against brute force ----------------------------------------------------------------------

def test_peak_depth_is_the_shadow_of_skyworks_splat():
    d = np.linspace(0, 1, 101)
    np.testing.assert_allclose(peak_optical_depth(d, 80.0), special.spence(np.exp(-80 * d)), atol=1e-12)
    assert peak_optical_depth([1.0], 80.0)[0] == pytest.approx(math.pi**2 / 6)       # opaque: Li2(1)
    assert peak_optical_depth([0.5], 1e-3)[0] == pytest.approx(0.5e-3, rel=1e-3)     # faint: ext x density


@pytest.mark.parametrize("sun", sorted(SUNS))
@pytest.mark.parametrize("extinction", [80.0, 2.0])
def test_scattering_off_gives_the_light_behind_tau_exactly(sun, extinction):
    centers, radii, density = random_cloud()
    lighting = Lighting(sun=SUNS[sun], extinction=extinction, scattering=False)
    got = incident_light(centers, radii, density, lighting)
    _, tau = brute_force(centers, radii, density, lighting)
    np.testing.assert_allclose(got, behind(tau), rtol=1e-5, atol=1e-6)     # float32 and the CDF's table


def test_a_neighbour_shades_as_far_as_it_lies_nearer_the_sun():
    """Two particles on one ray, each lit at its sunward face a sigma before its centre: at the same
    depth each takes 16 % of the other's shadow, a sigma apart the one behind half and the one in
    front 2 % (Harris's recurrence gave all or none)."""
    lighting = Lighting(sun=(1.0, 0.0, 0.0), scattering=False)
    peak = peak_optical_depth([1.0], lighting.extinction)[0]
    for ahead in (0.0, 0.4, 1.2):           # how much nearer the sun the second one is, sigma = 0.4
        centers = np.array([[0, 0, 0], [ahead, 0, 0]], np.float32)
        light = incident_light(centers, np.ones(2, np.float32), np.ones(2, np.float32), lighting)
        back, front = special.ndtr((ahead - 0.4) / 0.4), special.ndtr((-ahead - 0.4) / 0.4)
        np.testing.assert_allclose(light, behind(peak * np.array([back, front])), rtol=1e-6)


@pytest.mark.parametrize("sun", sorted(SUNS))
def test_scattering_on_follows_harris_recurrence_along_the_ray(sun):
    centers, radii, density = random_cloud()
    lighting = Lighting(sun=SUNS[sun])
    got = incident_light(centers, radii, density, lighting)
    want, _ = brute_force(centers, radii, density, lighting)
    np.testing.assert_allclose(got, behind(-np.log(want)), rtol=1e-5, atol=1e-6)


def test_light_behind_a_depth_is_the_sun_at_none_and_never_reaches_zero():
    """Full sun is exactly 1; the light falls strictly with depth, within DIFFUSE of e^-E, and stays
    above 0 in float32 to depths of 10^6, where e^-E is 0 below a depth of ~100."""
    depth = np.concatenate([np.linspace(0, 30, 30_001), np.geomspace(30.01, 1e6, 10_000)])
    light = light_of_depth(depth)
    assert light.dtype == np.float32 and light[0] == 1.0
    assert (np.diff(light) < 0).all() and light[-1] > 0
    np.testing.assert_allclose(light, behind(depth), rtol=1e-5)
    assert np.abs(light - np.exp(-depth)).max() <= DIFFUSE
    assert np.exp(-depth.astype(np.float32))[depth > 110].max() == 0     # what e^-E alone would bake


# -- invariants -------------------------------------------------------------------------------

def test_a_lone_particle_and_particles_side_by_side_get_the_full_sun():
    one = incident_light(np.zeros((1, 3), np.float32), np.ones(1, np.float32), np.ones(1, np.float32))
    assert one.tolist() == [1.0]
    # a row across the sun's rays, 3 radii apart: nobody shadows anybody
    row = np.stack([np.arange(20) * 3.0, np.zeros(20), np.zeros(20)], axis=1).astype(np.float32)
    lit = incident_light(row, np.ones(20, np.float32), np.ones(20, np.float32), Lighting(sun=(0, 1, 0)))
    assert (lit == 1).all()


def strung_out(n=5000, clusters=50, seed=4):
    """``n`` particles in ``clusters`` 3-unit cubes 12 apart along x (radius 0.3-0.6), seen from
    above: 600 units of sky across the sun's rays, 3 deep."""
    rng = np.random.default_rng(seed)
    centers = rng.random((n, 3)) * 3
    centers[:, 0] += 12 * (np.arange(n) % clusters)
    return centers.astype(np.float32), rng.uniform(0.3, 0.6, n).astype(np.float32), \
        rng.uniform(0.05, 1, n).astype(np.float32)


@pytest.mark.parametrize("route", ["pair by pair", "slabs", "strung out, past SMALL"])
def test_input_order_changes_nothing(route, monkeypatch):
    small = route != "slabs"
    if not small:
        monkeypatch.setattr(light_module, "SMALL", 0)
    centers, radii, density = (strung_out() if route.startswith("strung") else
                               random_cloud(n=2000, box=(20, 10, 15)))
    lighting = Lighting(sun=SUNS["above" if route.startswith("strung") else "side"])
    a = incident_light(centers, radii, density, lighting)
    shuffle = np.random.default_rng(1).permutation(len(a))
    b = incident_light(centers[shuffle], radii[shuffle], density[shuffle], lighting)
    if small:
        np.testing.assert_array_equal(b, a[shuffle])
    else:  # the slabs' sums run in another order: float32 rounding only
        np.testing.assert_allclose(b, a[shuffle], atol=1e-5)


def _rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def test_moving_cloud_and_sun_together_changes_nothing():
    centers, radii, density = random_cloud()
    sun = np.array(SUNS["above"])
    base = incident_light(centers, radii, density, Lighting(sun=tuple(sun)))
    moved = incident_light(centers + np.float32([100, -40, 7]), radii, density, Lighting(sun=tuple(sun)))
    np.testing.assert_allclose(moved, base, atol=1e-4)
    for axis, angle in (((0, 0, 1), 0.7), ((1, 2, 3), 2.1)):
        r = _rotation(axis, angle)
        turned = incident_light((centers @ r.T).astype(np.float32), radii, density,
                                Lighting(sun=tuple(r @ sun)))
        np.testing.assert_allclose(turned, base, atol=1e-4)       # float32 positions, turned


@pytest.mark.parametrize("small", [True, False], ids=["pair by pair", "slabs"])
def test_scattering_only_adds_light_and_light_never_exceeds_the_sun(small, monkeypatch):
    if not small:
        monkeypatch.setattr(light_module, "SMALL", 0)
    cloud = fill_cloud(load_cubes(TABLES["4.2"]), seed=5)
    for sun in SUNS.values():
        for albedo, extinction in ((0.9, 80.0), (1.0, 1000.0), (0.3, 0.5)):
            kw = dict(sun=sun, albedo=albedo, extinction=extinction)
            off = incident_light(cloud.centers, cloud.radii, cloud.density, Lighting(**kw, scattering=False))
            on = incident_light(cloud.centers, cloud.radii, cloud.density, Lighting(**kw))
            assert (on >= off).all()
            assert (off >= 0).all() and (on <= 1).all()
            assert on.mean() > off.mean() or Lighting(**kw).forward_fraction == 0


@pytest.mark.parametrize("sun", sorted(SUNS))
def test_luminance_falls_with_optical_depth_towards_the_sun(sun):
    """Colour is light: under a sun from above, the side or below, the particles deeper in the
    cloud as the sun sees it are darker (the height gradient this replaced ranked at 0.37).

    The colour's luminance is taken in linear light, before it is stored as sRGB bytes: the
    bytes keep the order but tie the particles deep in shadow (light 1e-3 is a tenth of a byte)."""
    cloud = fill_cloud(load_cubes(TABLES["4.4"]), seed=0)
    lighting = Lighting(sun=SUNS[sun])
    lit = light_cloud(cloud, lighting)
    _, tau = brute_force(cloud.centers, cloud.radii, cloud.density, lighting)
    linear = lighting.albedo * (np.array(lighting.sky_color)
                                + np.array(lighting.sun_color) * lit.light[:, None])
    assert stats.spearmanr(linear @ [0.2126, 0.7152, 0.0722], tau).statistic < -0.8
    order = np.argsort(lit.light)
    assert (np.diff(luminance(lit.colors)[order]) >= 0).all()      # the bytes never invert it


def test_a_high_sun_leaves_the_base_darker_than_the_top():
    lit = light_cloud(fill_cloud(load_cubes(TABLES["4.4"]), seed=3), Lighting(sun=(0, 1, 0)))
    y = lit.centers[:, 1]
    bright = luminance(lit.colors)
    assert bright[y < np.quantile(y, 0.2)].mean() + 0.2 < bright[y > np.quantile(y, 0.8)].mean()


def test_a_big_cloud_in_slabs_agrees_with_the_pairs(monkeypatch):
    """The slabs rank the light as the pairs do (0.97 here). Their mean is looser: the pairs take
    a particle's light at its sunward face, the slabs at its centre, which leaves Table 4.2, a
    dense cloud whose light is 6 % of the sun's, 0.6x as bright in slabs."""
    cloud = fill_cloud(load_cubes(TABLES["4.2"]), seed=1)
    lighting = Lighting(sun=SUNS["side"])
    exact = incident_light(cloud.centers, cloud.radii, cloud.density, lighting)
    monkeypatch.setattr(light_module, "SMALL", 0)
    slabs = incident_light(cloud.centers, cloud.radii, cloud.density, lighting)
    assert stats.spearmanr(slabs, exact).statistic > 0.95
    assert exact.mean() / 2 < slabs.mean() < 2 * exact.mean()


def test_a_cloud_strung_out_across_the_rays_is_lit_pair_by_pair_past_small(monkeypatch):
    """5,000 particles in 50 small cubes along 600 units, the sun above: each particle's pairs
    within reach lie in its own cube and the next, fewer than a cloud of SMALL particles has, so
    no grid. Through the slabs (the grid's cells 3.2x the typical particle's sigma) this cloud
    ranked 0.90 against the pairs; random cube file 671 (2,059 particles) 0.81 against the
    reference, where the pairs give 0.998 (tests/clouds/test_suns.py)."""
    centers, radii, density = strung_out()
    lighting = Lighting(sun=(0, 1, 0))
    exact = incident_light(centers, radii, density, lighting, share=1.0)

    def no_grid(*args, **kwargs):
        raise AssertionError("lit through the slabs")

    monkeypatch.setattr(light_module, "SMALL", 10**9)       # every cloud pair by pair, along a
    along_a = incident_light(centers, radii, density, lighting, share=1.0)
    np.testing.assert_allclose(exact, along_a, rtol=1e-6, atol=1e-7)
    monkeypatch.undo()
    monkeypatch.setattr(light_module, "_slabs", no_grid)
    np.testing.assert_array_equal(incident_light(centers, radii, density, lighting, share=1.0), exact)
    # seen along the string, the same cloud's pairs are a dense cloud's: through the slabs
    monkeypatch.undo()
    monkeypatch.setattr(light_module, "_pairs", no_grid)
    incident_light(centers, radii, density, Lighting(sun=(1, 0, 0)), share=1.0)


def test_a_dense_cloud_past_small_goes_through_the_slabs(monkeypatch):
    def no_pairs(*args, **kwargs):
        raise AssertionError("lit pair by pair")

    monkeypatch.setattr(light_module, "_pairs", no_pairs)
    rng = np.random.default_rng(5)
    n = light_module.SMALL + 1
    incident_light((rng.random((n, 3)) * [3, 4, 3]).astype(np.float32), np.full(n, 2, np.float32),
                   np.ones(n, np.float32), Lighting(sun=(0, 1, 0)))


def test_a_dense_big_cloud_keeps_light_above_zero_and_in_order_in_its_slabs():
    """4,000 particles of radius 2 in a 3x4x3 box under a sun overhead: before the slabs carried
    depth and the light had its diffuse share, 58 % of it was exactly 0 (ranked 0.82 with height)."""
    rng = np.random.default_rng(5)
    centers = (rng.random((4000, 3)) * [3, 4, 3]).astype(np.float32)
    light = incident_light(centers, np.full(4000, 2, np.float32), np.ones(4000, np.float32),
                           Lighting(sun=(0, 1, 0)), share=1.0)   # its whole depth, uncapped
    assert light.min() > 0 and np.median(light) < 1e-5          # e^-E alone: 0 below ~1e-45
    assert stats.spearmanr(light, centers[:, 1]).statistic > 0.9


def test_a_dense_big_clouds_sunlit_face_is_lit():
    """Table 4.4's cubes holding 100,000 particles: each particle read half its own slab's depth,
    so the 20 nearest the sun, 1,000 to a slab, got exactly 0 (the pairs gave up to 0.57 at
    9,840). Each now reads the share of its slab nearer the sun than it: 0.96 down to 0.18."""
    cubes = load_cubes(TABLES["4.4"])
    total = sum(c.particles for c in cubes.cubes)
    scaled = tuple(c.__class__(c.particles * 100_000 // total, c.size, c.centre, c.max_radius, c.line)
                   for c in cubes.cubes)
    cloud = fill_cloud(cubes.__class__(cubes.path, sum(c.particles for c in scaled), scaled), seed=0)
    lighting = Lighting()
    light = incident_light(cloud.centers, cloud.radii, cloud.density, lighting)
    nearest = np.argsort(-(cloud.centers.astype(float) @ np.array(lighting.sun_unit)))[:20]
    assert light[nearest].max() > 0.9 and light[nearest].min() > 0.1


@pytest.mark.parametrize("n,slabs", [(1, 1), (1, 16), (3000, None)])
def test_particles_all_at_one_depth_go_through_the_slabs(n, slabs):
    """All at one depth make one depth level, and the empty levels past it counted as a slab that
    none is: an IndexError (a one-particle cloud in `fishgen sky`, which lights in 16 slabs)."""
    light = incident_light(np.zeros((n, 3), np.float32), np.full(n, 0.5, np.float32),
                           np.ones(n, np.float32), Lighting(), slabs=slabs)
    assert light.shape == (n,) and np.isfinite(light).all() and (light > 0).all()


def test_same_bytes_whatever_the_thread_count(monkeypatch):
    cubes = load_cubes(TABLES["4.4"])
    big = fill_cloud(cubes.__class__(cubes.path, 200_000, tuple(
        c.__class__(c.particles * 300, c.size, c.centre, c.max_radius, c.line) for c in cubes.cubes)), seed=2)
    one = fill_cloud(cubes, seed=2, workers=1)
    two = fill_cloud(cubes, seed=2, workers=2)
    assert light_cloud(one).light.tobytes() == light_cloud(two).light.tobytes()
    light = light_cloud(big).light.tobytes()
    monkeypatch.setattr(light_module, "WORKERS", 1)              # a big cloud's passes on one thread
    assert light_cloud(big).light.tobytes() == light
    monkeypatch.setattr(light_module, "MAP_VALUES", 4 * 10_000)  # and its slabs a few at a time
    assert light_cloud(big).light.tobytes() == light


# -- the lit cloud and its files --------------------------------------------------------------

def test_light_cloud_sets_light_lighting_and_colours():
    cloud = fill_cloud(load_cubes(TABLES["4.3"]), seed=0)
    lighting = Lighting(sun=(1, 0.3, 0), sky_color=(0.2, 0.3, 0.5))
    lit = light_cloud(cloud, lighting)
    assert cloud.light is None and (cloud.colors == 255).all()      # the input is left alone
    assert lit.lighting == lighting and lit.light.dtype == np.float32
    np.testing.assert_array_equal(lit.colors, lit_colors(lit.light, lighting))
    ends = lit_colors(np.array([0.0, 1.0], np.float32), lighting)
    from fishgen.numeric import linear_to_srgb
    np.testing.assert_array_equal(ends[0], np.round(linear_to_srgb(0.9 * np.array([0.2, 0.3, 0.5])) * 255))
    np.testing.assert_array_equal(ends[1], np.round(linear_to_srgb(0.9 * np.array([0.92, 1.0, 1.16])) * 255))
    assert (lit_colors(np.ones(1, np.float32), Lighting()) >= 250).all()   # by default full sun is white
    with pytest.raises(ValueError, match="go together"):
        Cloud(cloud.centers, cloud.radii, cloud.density, cloud.colors, cloud.cube_index, cloud.cube_bounds,
              light=lit.light)


def test_merge_keeps_light_only_when_lit_alike():
    a = light_cloud(fill_cloud(load_cubes(TABLES["4.3"]), seed=1))
    b = light_cloud(fill_cloud(load_cubes(TABLES["4.4"]), seed=2, offset=(40, 0, 0)))
    both = merge_clouds([a, b])
    np.testing.assert_array_equal(both.light, np.concatenate([a.light, b.light]))
    mixed = merge_clouds([a, light_cloud(b, Lighting(sun=(1, 0, 0)))])
    assert mixed.light is None and mixed.lighting is None


def test_glb_carries_the_light_and_the_sun(tmp_path, gltf_validator):
    from fishgen.exchange.gltf_reader import read_gltf
    from tests.clouds.test_clouds_export import accessor_array, glb_parts

    lighting = Lighting(sun=(2, 0.6, 0))
    lit = light_cloud(fill_cloud(load_cubes(TABLES["4.4"]), seed=0), lighting)
    for billboards in (False, True):
        path = tmp_path / f"lit{billboards}.glb"
        export_cloud(lit, path, billboards=billboards)
        gltf_validator(path)
        doc, blob = glb_parts(path)
        prim = doc["meshes"][0]["primitives"][0]
        stored = accessor_array(doc, blob, prim["attributes"]["_LIGHT"], "<f4", 1)[:, 0]
        np.testing.assert_array_equal(stored, np.repeat(lit.light, 12) if billboards else lit.light)
        record = doc["scenes"][0]["extras"][EXTRAS_KEY]
        np.testing.assert_allclose(record["sun"], np.array([2, 0.6, 0]) / math.hypot(2, 0.6), atol=1e-12)
        back = from_extras(read_gltf(path).extras)   # what the preview and the viewer use
        assert back == Lighting(sun=lighting.sun_unit)


def test_unlit_files_stay_as_they_were(tmp_path):
    """No light: no _LIGHT and no extras (fishgen clouds without lighting writes what it wrote)."""
    cloud = fill_cloud(load_cubes(TABLES["4.3"]), seed=0)
    export_cloud(cloud, tmp_path / "plain.glb")
    from tests.clouds.test_clouds_export import glb_parts

    doc, _ = glb_parts(tmp_path / "plain.glb")
    assert ("_LIGHT" not in doc["meshes"][0]["primitives"][0]["attributes"]
            and "extras" not in doc["scenes"][0])


# -- the lighting parameters ------------------------------------------------------------------

@pytest.mark.parametrize("kwargs", [{"extinction": 110}, {"anisotropy": 0.5}, {"solid_angle": 1.0},
                                    {"extinction": 1000, "albedo": 0.5}])
def test_a_particle_passes_on_at_most_what_it_scatters(kwargs):
    """Past SkyWorks' forward share of 1 (extinction 104 with the defaults) every particle passed
    all the light on: a cloud of one flat white. The share is capped at the albedo, so only an
    albedo of 1 (nothing absorbed) with a share that reaches it still lets all the light through."""
    lighting = Lighting(**kwargs)
    assert lighting.forward_fraction <= lighting.albedo
    cloud = light_cloud(fill_cloud(load_cubes(TABLES["4.4"]), seed=0), lighting)
    assert cloud.light.min() < 0.5 and len(np.unique(cloud.colors[:, 0])) > 20


def test_defaults_are_skyworks_constants():
    lighting = Lighting()
    assert (lighting.albedo, lighting.extinction, lighting.solid_angle) == (0.9, 80.0, 0.09)
    assert lighting.phase(1.0) == lighting.phase(-1.0) == pytest.approx(1.5)         # Rayleigh
    assert lighting.forward_fraction == pytest.approx(0.9 * 80 * 1.5 * 0.09 / (4 * math.pi))
    assert Lighting(scattering=False).forward_fraction == 0
    for g in (0.0, 0.5, -0.3):  # the phase function averages 1 over the sphere
        c = np.linspace(-1, 1, 20001)
        values = [Lighting(anisotropy=g).phase(v) for v in c]
        assert np.trapezoid(values, c) / 2 == pytest.approx(1.0, rel=1e-4)
    sun = Lighting().sun_unit
    assert sun[1] > 0.8 and math.isclose(sum(v * v for v in sun), 1.0)


@pytest.mark.parametrize("kwargs,message", [
    (dict(sun=(0, 0, 0)), "expected sun as X,Y,Z with three finite numbers within float32 range, not all 0, "
                          "found (0, 0, 0)"),
    (dict(sun=(1, float("nan"), 0)), "expected sun as X,Y,Z with three finite numbers"),
    (dict(sun=(1, 2)), "expected sun as X,Y,Z with three finite numbers within float32 range, not all 0, "
                       "found (1, 2)"),
    (dict(albedo=1.5), "expected albedo as a number from 0 to 1, found 1.5"),
    (dict(extinction=-1), "expected extinction as a number from 0 to 1000, found -1"),
    (dict(solid_angle=0), "expected solid angle as a number from 0 to 12.5664, found 0"),
    (dict(anisotropy=0.95), "expected anisotropy as a number from -0.9 to 0.9, found 0.95"),
    (dict(sun_color=(1, 1, -1)), "expected sun color as R,G,B with three finite numbers from 0 to 10, found"),
])
def test_bad_lighting_is_one_line(kwargs, message):
    with pytest.raises(FishgenError) as err:
        Lighting(**kwargs)
    assert str(err.value).startswith(message) and "\n" not in str(err.value)


def test_every_field_is_an_option_declared_once():
    from fishgen.options import declared

    names = {f.name for f, _ in declared(Lighting)}
    assert names == {"sun", "sun_color", "sky_color", "albedo", "extinction", "solid_angle", "anisotropy",
                     "scattering"}
    assert all(spec.help and spec.default == f.default for f, spec in declared(Lighting))


def test_the_parameters_module_imports_no_numpy():
    import subprocess
    import sys

    code = "import sys, fishgen.clouds.lighting; sys.exit('numpy' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


def test_lighting_warns_about_nothing():
    cloud = fill_cloud(load_cubes(TABLES["4.2"]), seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for sun in SUNS.values():
            light_cloud(cloud, Lighting(sun=sun, extinction=0.0))
            light_cloud(cloud, Lighting(sun=sun))


def _scaled(cube_file, n):
    """``cube_file``'s cubes with their counts scaled to a total of ``n``."""
    from fishgen.clouds import Cube, CubeFile

    total = sum(c.particles for c in cube_file.cubes)
    counts = [c.particles * n // total for c in cube_file.cubes]
    counts[0] += n - sum(counts)
    return CubeFile(cube_file.path, n, tuple(Cube(k, c.size, c.centre, c.max_radius, c.line)
                                             for k, c in zip(counts, cube_file.cubes, strict=True)))


@pytest.mark.parametrize("table", ["4.2", "4.3", "4.4"])
def test_one_particle_more_does_not_dim_the_cloud(table):
    """At 2,049 particles the light goes from pairs to slabs: the cloud's mean light stays within
    20 % of its 2,048-particle self (read at the centre, the slabs gave half)."""
    cubes = load_cubes(TABLES[table])
    pairs, slabs = (light_cloud(fill_cloud(_scaled(cubes, n), seed=0)).light.mean() for n in (2048, 2049))
    assert 0.8 < slabs / pairs < 1.25


def test_the_slabs_read_at_the_same_lead_at_every_size():
    assert {light_module.slab_lead(n) for n in (light_module.SMALL + 1, 10**5, 10**7)} == {light_module.LEAD}


def test_the_lead_holds_for_a_caller_that_sets_the_slabs_and_for_slabs_in_groups(monkeypatch):
    """A sky's clouds (slabs set) read their light ahead as every big cloud does, and a cloud whose
    maps go in groups reads it in the group of the slab its face lies in: the same bytes."""
    centers, radii, density = random_cloud(n=3000, box=(20, 10, 15))
    lighting = Lighting(sun=SUNS["side"])
    before = incident_light(centers, radii, density, lighting, slabs=16)
    automatic = incident_light(centers, radii, density, lighting)
    lead = light_module.LEAD
    monkeypatch.setattr(light_module, "LEAD", 0.9)
    assert incident_light(centers, radii, density, lighting, slabs=16).tobytes() != before.tobytes()
    assert incident_light(centers, radii, density, lighting).tobytes() != automatic.tobytes()
    monkeypatch.setattr(light_module, "LEAD", lead)
    monkeypatch.setattr(light_module, "MAP_VALUES", 1)        # every slab a group of its own
    assert incident_light(centers, radii, density, lighting).tobytes() == automatic.tobytes()


# -- dense clouds (the eleventh QA pass: grey) -------------------------------------------------

def _box(n: int, seed: int = 0):
    """The QA pass's cloud: one 7 x 3 x 3 cube of ``n`` particles of radius up to 2."""
    from fishgen.clouds import parse_cubes

    return fill_cloud(parse_cubes(f"{n}\n1\n{n}, 7, 3, 3, 0, 0, 0, 2\n".encode(), "box.awn"), seed=seed)


def _bright(colors: np.ndarray) -> np.ndarray:
    return colors.astype(int).mean(axis=1) > 200


@pytest.mark.parametrize("sun", list(SUNS))
def test_a_dense_box_is_white_where_the_sun_strikes_it_and_grey_beneath(sun):
    """8,000 particles in the box: every centre lies far inside the field, and the light read at
    the centres (the slabs past 8,192, nearly so at 8,000) left its sunlit side as grey as its
    belly (0.2 % of it brighter than 200). The 2 % of it nearest the sun, its sunlit skin, are now
    mostly white (68-96 % brighter than 200 under the three suns; 9-19 % before) and the tenth
    farthest from it grey."""
    lighting = Lighting(sun=SUNS[sun])
    lit = light_cloud(_box(8000), lighting)
    toward = lit.centers.astype(np.float64) @ np.array(lighting.sun_unit)
    order = np.argsort(toward)
    near, far = order[-160:], order[:800]
    assert _bright(lit.colors[near]).mean() > 0.6
    assert not _bright(lit.colors[far]).any()
    assert np.median(lit.colors[far].astype(int).mean(axis=1)) < 185


def test_more_particles_in_the_same_box_do_not_turn_it_grey():
    """615 particles in the box: 17.7 % brighter than 200; 8,000 gave 0.2 % and 32,000 less. A
    cloud more crowded than CROWDING shares out its optical depth, and the slabs read the light
    ahead as the pairs do, so filling the same cubes more finely keeps a sunlit share of the same
    order: 4.7 % and 4.4 % (the bigger a cloud of the same shape is in particles, the thinner its
    lit skin is in particles: what is seen of it is still white, test above)."""
    shares = [_bright(light_cloud(_box(n)).colors).mean() for n in (615, 8000, 32_000)]
    assert shares[0] == pytest.approx(0.177, abs=0.002)            # the pairs: as before
    assert min(shares[1:]) > shares[0] / 6


def test_the_report_s_clouds_are_not_crowded():
    """The share is 1, and their light as before, for every shipped table; a box of 8,000 more than
    CROWDING, and the share brings it back there."""
    lighting = Lighting()
    for table in TABLES.values():
        cloud = fill_cloud(load_cubes(table), seed=0)
        assert light_module.depth_share(cloud.centers, cloud.radii, cloud.density, lighting) == 1.0
    box = _box(8000)
    crowd = light_module.crowding(box.centers, box.radii, box.density, lighting.extinction)
    assert crowd > 4 * light_module.CROWDING
    share = light_module.depth_share(box.centers, box.radii, box.density, lighting)
    assert share == pytest.approx(light_module.CROWDING / crowd)


def test_the_crowding_of_a_big_cloud_is_estimated_without_bias():
    """Evenly spaced samples of a big cloud give its crowding to within 10 % of every particle's."""
    box = _box(20_000, seed=3)
    estimate = light_module.crowding(box.centers, box.radii, box.density, 80.0)
    sample = np.arange(0, 20_000, 7)
    sigma = box.radii.astype(np.float64) * 0.4
    p = box.centers.astype(np.float64)
    peak = peak_optical_depth(box.density, 80.0)
    total = 0.0
    for i in sample:
        d2 = ((p - p[i]) ** 2).sum(axis=1) / sigma ** 2
        w = peak / sigma * np.exp(-0.5 * d2)
        w[i] = 0
        total += w.sum() * sigma[i]
    assert estimate == pytest.approx(total / len(sample), rel=0.1)
