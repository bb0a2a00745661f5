"""A sky's plan: which clouds, how big, where, and how many particles each, from a seed."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from fishgen.sky.build import load_models
from fishgen.sky.compose import _apportion, fill_sky, model_box, plan_sky, scaled_model, to_world
from fishgen.sky.modes import ALTITUDE, AREA, MODES


@pytest.fixture(scope="module")
def models():
    return load_models()[0]


def test_the_modes_grow_from_thin_to_thick_in_clouds_particles_and_size():
    thin, medium, thick = MODES["thin"], MODES["medium"], MODES["thick"]
    assert thin.clouds < medium.clouds < thick.clouds
    assert thin.particles < medium.particles < thick.particles
    assert thin.scale[1] <= medium.scale[1] <= thick.scale[1] and thin.scale[0] < thick.scale[0]
    assert thick.particles == 1_000_000


@pytest.mark.parametrize("mode", list(MODES))
def test_a_plan_shares_out_exactly_the_particles_and_keeps_clouds_in_the_area_and_band(models, mode):
    plan = plan_sky(MODES[mode], models, seed=3, area=AREA, altitude=ALTITUDE)
    assert len(plan.placements) == MODES[mode].clouds
    assert plan.particles == MODES[mode].particles
    assert len({p.name for p in plan.placements}) == len(plan.placements)
    for p in plan.placements:
        lo, hi = model_box(models[p.source])
        height = (hi[1] - lo[1]) * p.scale[1]
        base = p.position[1] - height / 2
        assert ALTITUDE[0] - 1e-9 <= base <= ALTITUDE[1] + 1e-9
        assert abs(p.position[0]) <= AREA[0] / 2 and abs(p.position[2]) <= AREA[1] / 2
        assert MODES[mode].scale[0] <= p.scale[0] <= MODES[mode].scale[1]
        assert p.scale[2] >= p.scale[0]            # depth stretched: the editor's clouds are flat
        assert 0 <= p.yaw < 2 * math.pi


def test_a_bigger_cloud_gets_more_particles(models):
    plan = plan_sky(MODES["medium"], models, seed=1, area=AREA, altitude=ALTITUDE)
    volume = [p.scale[0] * p.scale[1] * p.scale[2] * (models[p.source].total > 0) for p in plan.placements]
    counts = [p.particles for p in plan.placements]
    same_model = [k for k, p in enumerate(plan.placements) if p.source == plan.placements[0].source]
    pairs = [(volume[a], counts[a], volume[b], counts[b]) for a in same_model for b in same_model if a != b]
    assert all(ca >= cb for va, ca, vb, cb in pairs if va > vb * 1.01)


def test_the_same_seed_plans_the_same_sky_and_another_seed_another(models):
    a = plan_sky(MODES["thin"], models, seed=7, area=AREA, altitude=ALTITUDE)
    b = plan_sky(MODES["thin"], models, seed=7, area=AREA, altitude=ALTITUDE)
    c = plan_sky(MODES["thin"], models, seed=8, area=AREA, altitude=ALTITUDE)
    assert a == b
    assert [p.position for p in a.placements] != [p.position for p in c.placements]


def test_clouds_are_spread_out_not_heaped(models):
    plan = plan_sky(MODES["thin"], models, seed=0, area=AREA, altitude=ALTITUDE)
    xz = np.array([(p.position[0], p.position[2]) for p in plan.placements])
    gaps = np.linalg.norm(xz[:, None] - xz[None], axis=2) + np.eye(len(xz)) * 1e9
    # 16 clouds in 400 x 400: evenly spread they stand ~100 apart; the least crowded try keeps them apart
    assert gaps.min(axis=1).mean() > 40


def test_apportion_sums_exactly_keeps_minimums_and_follows_weights():
    out = _apportion(10, np.array([1.0, 1.0, 1.0]))
    assert out.sum() == 10 and sorted(out) == [3, 3, 4]
    out = _apportion(100, np.array([0.0, 1.0, 3.0]), minimum=np.array([1, 1, 1]))
    assert out.sum() == 100 and out[0] >= 1 and out[2] > out[1]


def test_a_scaled_model_is_centred_scaled_and_finer_as_it_holds_more_particles(models):
    model = models[1]
    plan = plan_sky(MODES["medium"], models, seed=0, area=AREA, altitude=ALTITUDE)
    p = replace(plan.placements[0], source=1, scale=(2.0, 2.0, 3.0), particles=model.total * 12)
    scaled = scaled_model(model, p, puff=1.0)
    lo, hi = model_box(scaled)
    assert np.allclose((lo + hi) / 2, 0, atol=1e-9)
    src_lo, src_hi = model_box(model)
    inner = lambda m: (np.array([c.size for c in m.cubes]) * 1.0).sum(axis=0)  # noqa: E731
    assert np.allclose(inner(scaled), inner(model) * (2, 2, 3))
    assert scaled.total == p.particles
    # 12x the particles in 12x the volume: the packing is the model's, so radii scale with the size alone
    finer = (2 * 2 * 3 * model.total / p.particles) ** (1 / 3)
    assert scaled.cubes[0].max_radius == pytest.approx(model.cubes[0].max_radius * finer)


def test_filled_clouds_hold_their_share_and_sit_where_placed(models):
    plan = plan_sky(MODES["thin"], models, seed=0, area=AREA, altitude=ALTITUDE, particles=4_000)
    clouds = fill_sky(plan, models, noise=0.5)
    assert [len(c.cloud) for c in clouds] == [p.particles for p in plan.placements]
    for c in clouds:
        world = c.world_centers()
        middle = (world.min(axis=0) + world.max(axis=0)) / 2
        size = world.max(axis=0) - world.min(axis=0)
        assert np.all(np.abs(middle - c.placement.position) < size / 2 + 1e-6)


def test_the_turn_is_a_rotation_about_up():
    plan_point = np.array([[1.0, 2.0, 0.0]])
    from fishgen.sky.compose import Placement

    p = Placement("c", 0, (1, 1, 1), math.pi / 2, (10.0, 0.0, 0.0), 1, 0)
    moved = to_world(plan_point, p)[0]
    # glTF's quaternion for the node turns +X towards -Z by a positive angle about +Y
    q = np.array(p.rotation)
    assert np.allclose(moved, (10.0, 2.0, -1.0))
    assert np.allclose(q, (0, math.sin(math.pi / 4), 0, math.cos(math.pi / 4)))
