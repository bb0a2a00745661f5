"""A cloud's lower levels of detail: fewer, larger particles that look like the cloud from afar."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from fishgen.clouds.fill import fill_cloud
from fishgen.clouds.light import light_cloud
from fishgen.clouds.lod import coarsen
from fishgen.clouds.parser import load_cubes
from fishgen.clouds.scene import cloud_scene
from fishgen.sky.build import load_models
from fishgen.sky.compose import fill_sky, plan_sky
from fishgen.sky.light import light_sky
from fishgen.sky.modes import ALTITUDE, AREA, LOD_LEVELS, MODES
from fishgen.sky.scene import levels
from tests.conftest import PARAMS


@pytest.fixture(scope="module")
def thick_cloud():
    models = load_models()[0]
    plan = plan_sky(MODES["thick"], models, seed=0, area=AREA, altitude=ALTITUDE)
    one = replace(plan, placements=plan.placements[:1])
    return light_sky(fill_sky(one, models, noise=0.5))[0].cloud, one, models


def test_the_levels_keep_one_in_8_and_one_in_64(thick_cloud):
    cloud = thick_cloud[0]
    assert [round(len(cloud) / len(low)) for low in levels(cloud)] == [r for r, _ in LOD_LEVELS] == [8, 64]


@pytest.mark.parametrize("ratio", [8, 64])
def test_coarsen_keeps_about_one_in_ratio(thick_cloud, ratio):
    cloud = thick_cloud[0]
    low = coarsen(cloud, ratio)
    assert abs(len(low) - len(cloud) / ratio) <= 0.05 * len(cloud) / ratio
    assert np.all(low.radii > 0) and np.all((low.density > 0) & (low.density <= 1))
    assert low.radii.mean() > cloud.radii.mean()


def test_coarsen_keeps_optical_mass_and_weighted_light_exactly_where_nothing_saturates(thick_cloud):
    cloud = thick_cloud[0]
    faint = replace(cloud, density=(cloud.density * np.float32(0.001)).astype(np.float32))
    low = coarsen(faint, 8)
    mass, low_mass = (c.density.astype(float) * c.radii.astype(float) ** 2 for c in (faint, low))
    assert low_mass.sum() == pytest.approx(mass.sum(), rel=1e-4)
    assert np.sum(low.light * low_mass) == pytest.approx(np.sum(faint.light * mass), rel=1e-4)
    centre = lambda c, m: (c.centers.astype(float) * m[:, None]).sum(axis=0) / m.sum()  # noqa: E731
    assert np.allclose(centre(low, low_mass), centre(faint, mass), atol=1e-3)


def test_coarsen_of_a_dense_cloud_loses_only_what_saturates_and_stays_inside(thick_cloud):
    """Opaque cells clip at density 1: the linear mass drops (to about 40 % here), the picture does
    not (stacked opaque particles show no more than one: test_each_level_looks_like_the_cloud...)."""
    cloud = thick_cloud[0]
    low = coarsen(cloud, 8)
    mass, low_mass = (c.density.astype(float) * c.radii.astype(float) ** 2 for c in (cloud, low))
    assert 0.25 * mass.sum() < low_mass.sum() <= mass.sum() * (1 + 1e-5)
    assert cloud.light.min() - 1e-6 <= low.light.min() and low.light.max() <= cloud.light.max() + 1e-6
    lo, hi = cloud.centers.min(axis=0), cloud.centers.max(axis=0)
    assert np.all(low.centers >= lo - 1e-4) and np.all(low.centers <= hi + 1e-4)
    assert low.lighting == cloud.lighting and low.colors.shape == (len(low), 3)


def test_a_texture_clouds_billboards_merge_only_with_their_own_texture():
    cubes = load_cubes(PARAMS / "clouds" / "sky.awa")
    cloud = light_cloud(fill_cloud(cubes, seed=0))
    low = coarsen(cloud, 4)
    texture_of = lambda c: {cloud.textures[k] for k in np.unique(c.cube_index)}  # noqa: E731
    assert texture_of(low) == texture_of(cloud)
    for texture in set(cloud.textures):
        mine = [k for k, t in enumerate(cloud.textures) if t == texture]
        assert np.isin(low.cube_index, mine).sum() >= 1


def _render_difference(thick_cloud, coverage: float) -> dict[str, float]:
    """Mean |difference| (of 255) of each level's picture from full detail's at ``coverage`` of an
    800x600 view, over the cloud's pixels, beside another fill of the same cloud (the noise floor)."""
    from fishgen.clouds.noise import roughen
    from fishgen.preview.camera import FOV_Y, Camera
    from fishgen.preview.render import Renderer
    from fishgen.sky.compose import SkyCloud, model_box, scaled_model

    cloud, plan, models = thick_cloud
    p = plan.placements[0]
    other = replace(p, seed=p.seed + 1)
    lo, hi = model_box(scaled_model(models[p.source], p, plan.mode.puff))
    refill = fill_cloud(scaled_model(models[p.source], other, plan.mode.puff), seed=other.seed)
    refill = roughen(refill, 0.5, seed=p.seed, scale=float(hi[1] - lo[1]) / 3)
    refill = light_sky([SkyCloud(other, refill)])[0].cloud
    c = cloud.centers.astype(float)
    middle = (c.min(0) + c.max(0)) / 2
    reach = float(np.max(np.linalg.norm(c - middle, axis=1) + cloud.radii))
    distance = reach / (coverage * math.tan(FOV_Y / 2))
    way = np.array([1.0, 0.3, 0.6]) / np.linalg.norm([1.0, 0.3, 0.6])
    camera = Camera(eye=middle + way * distance, target=middle, up=np.array([0, 1.0, 0]), fov_y=FOV_Y,
                    aspect=4 / 3, near=distance / 100, far=distance * 10)
    background = (0.549, 0.678, 0.8, 1.0)
    renderer = Renderer(800, 600)
    try:
        shot = {name: renderer.render(cloud_scene(c), camera, None, background)[..., :3].astype(float)
                for name, c in (("full", cloud), ("other fill", refill),
                                *((f"LOD{k}", low) for k, low in enumerate(levels(cloud), 1)))}
    finally:
        renderer.release()
    inside = np.abs(shot["full"] - np.array(background[:3]) * 255).sum(axis=-1) > 5
    return {name: float(np.abs(img - shot["full"]).mean(axis=-1)[inside].mean())
            for name, img in shot.items() if name != "full"}


def test_each_level_looks_like_the_cloud_where_it_is_shown(thick_cloud, gl_available):
    """Level 1 differs from full detail less than another fill of the cloud does (at its switch,
    0.8 of the view's height); level 2, shown below 0.2, by at most twice as much."""
    (_, cover1), (_, cover2) = LOD_LEVELS
    at1 = _render_difference(thick_cloud, cover1)
    assert at1["LOD1"] < at1["other fill"]
    at2 = _render_difference(thick_cloud, cover2)
    assert at2["LOD2"] < 2 * at2["other fill"]
