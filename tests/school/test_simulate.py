"""fishgen.school.simulate: determinism, bounds, turning, pso target following, fleeing; paths."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.school.behaviour import BEHAVIOURS, behaviour
from fishgen.school.metrics import measures, nose_directions, summary
from fishgen.school.model import MODELS, Brain, Group, PsoParams, SchoolConfig, TargetPath
from fishgen.school.paths import path_positions
from fishgen.school.simulate import headings_from_velocities, simulate
from fishgen.school.state import SchoolState

L = 0.2


def _cfg(**kw) -> SchoolConfig:
    base = dict(groups=(Group("a", 40, L),), frames=120)
    base.update(kw)
    return SchoolConfig(**base)


@pytest.mark.parametrize("model", MODELS)
def test_same_seed_same_tracks_other_seed_other_tracks(model):
    a = simulate(_cfg(model=model, seed=3))
    b = simulate(_cfg(model=model, seed=3))
    c = simulate(_cfg(model=model, seed=4))
    for name in ("times", "positions", "velocities", "headings", "group", "scale"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert not np.allclose(a.positions, c.positions)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("layout", ["sphere", "box", "line", "ring"])
def test_tracks_finite_shaped_and_inside_bounds(model, layout):
    bounds = ((-2.0, -1.0, -2.0), (2.0, 1.0, 2.0))
    cfg = _cfg(model=model, layout=layout, bounds=bounds, frames=150,
               groups=(Group("a", 30, L), Group("b", 10, 0.3)),
               target=TargetPath(kind="figure8", radius=1.5, period=8.0),
               predator=TargetPath(kind="circle", radius=1.0, period=5.0))
    tr = simulate(cfg)
    n = 40
    assert tr.positions.shape == (150, n, 3) and tr.velocities.shape == (150, n, 3)
    assert tr.headings.shape == (150, n, 4) and tr.times.shape == (150,)
    assert np.allclose(tr.times, np.arange(150) / cfg.fps)
    assert tr.group.tolist() == [0] * 30 + [1] * 10
    for arr in (tr.positions, tr.velocities, tr.headings, tr.scale):
        assert np.all(np.isfinite(arr))
    lo, hi = np.array(bounds[0]), np.array(bounds[1])
    assert np.all(tr.positions >= lo - 1e-9) and np.all(tr.positions <= hi + 1e-9)
    # soft bounds do the work: few fish sit on the wall
    on_wall = np.isclose(tr.positions, lo) | np.isclose(tr.positions, hi)
    assert on_wall.mean() < 0.02
    assert np.allclose(np.linalg.norm(tr.headings, axis=2), 1.0)
    assert np.all((tr.scale > 0.8) & (tr.scale < 1.2)) and np.std(tr.scale) > 0


@pytest.mark.parametrize("model", ["boids", "pso"])
def test_heading_turns_at_most_max_turn_and_faces_velocity(model):
    cfg = _cfg(model=model, max_turn=1.5, frames=150,
               predator=TargetPath(kind="points", points=((0, -3, 0, 0), (5, 3, 0, 0))))
    tr = simulate(cfg)
    nose = nose_directions(tr.headings)
    step = np.arccos(np.clip(np.einsum("fnc,fnc->fn", nose[1:], nose[:-1]), -1, 1))
    assert step.max() <= cfg.max_turn / cfg.fps + 1e-6
    assert step.max() > 0.5 * cfg.max_turn / cfg.fps   # they do turn
    m = measures(tr, [L])
    assert m["heading_angle_max"].max() < 1e-6
    # no roll: the fish's +X (side) stays horizontal, so +Y is as up as it can be
    x, y, z, w = (tr.headings[..., i] for i in range(4))
    side_y = 2 * (x * y + w * z)
    assert np.abs(side_y).max() < 1e-9
    # quaternion signs are continuous frame to frame (for linear key interpolation)
    assert np.all(np.einsum("fnk,fnk->fn", tr.headings[1:], tr.headings[:-1]) > 0)


def test_headings_turn_plus_z_to_velocity():
    v = np.array([[1.0, 0, 0], [0, 0, -2], [0.3, 0.9, -0.2], [0, -1, 0], [-1, 0.5, 0]])
    q = headings_from_velocities(v)
    assert np.allclose(nose_directions(q), v / np.linalg.norm(v, axis=1, keepdims=True))


def test_pso_school_follows_its_target():
    body = 0.3
    cfg = SchoolConfig(groups=(Group("a", 50, body),), model="pso", frames=450, seed=1,
                       target=TargetPath(kind="circle", radius=2.0, period=20.0))
    tr = simulate(cfg)
    m = measures(tr, [body])
    s = summary(m, 150)
    assert s["target_distance"] < 5.0                  # body lengths
    assert m["target_distance"][150:].max() < 8.0
    assert s["overlaps_peak"] == 0 and s["groups_peak"] == [1.0]
    # the target went half way round: the school went with it, not stayed put
    centre = tr.positions.mean(axis=1)
    assert np.linalg.norm(centre[-1] - centre[150]) > 2.0
    # with no global weight nobody seeks the target: the check above would fail
    lazy = simulate(SchoolConfig(groups=cfg.groups, model="pso", frames=450, seed=1,
                                 target=cfg.target, pso=PsoParams(global_weight=0.0)))
    assert summary(measures(lazy, [body]), 150)["target_distance"] > 2 * s["target_distance"]


def test_fish_flee_an_approaching_predator():
    # the predator swims straight through the school's start centre at 1 body length / s
    path = TargetPath(kind="points", points=((0.0, -1.2, 0.0, 0.0), (10.0, 0.8, 0.0, 0.0)))
    cfg = SchoolConfig(groups=(Group("a", 40, L),), frames=150, seed=2, predator=path)
    tr = simulate(cfg)
    d = measures(tr, [L])["predator_distance"]
    calm = simulate(SchoolConfig(groups=(Group("a", 40, L, brain=Brain(flee=(0.0, 10.0))),),
                                 frames=150, seed=2, predator=path))
    d_calm = measures(calm, [L])["predator_distance"]
    assert d[0] < 10.0                 # it starts inside the flee distance
    assert d[-1] > d[0] + 2.0          # and the school gets further away while it approaches
    assert d[-1] > d_calm[-1] + 2.0    # which a school that does not flee does not
    speed = np.linalg.norm(tr.velocities, axis=2).mean(axis=1)
    calm_speed = np.linalg.norm(calm.velocities, axis=2).mean(axis=1)
    assert speed[10:60].mean() > 1.3 * calm_speed[10:60].mean()   # fleeing fish speed up


def test_paths():
    t = np.linspace(0, 20, 81)
    c = path_positions(TargetPath(kind="circle", centre=(1, 2, 3), radius=2.0, period=20.0), t)
    assert np.allclose(np.linalg.norm(c - [1, 2, 3], axis=1), 2.0) and np.allclose(c[0], c[-1])
    assert np.allclose(c[20], [1, 2, 5])     # a quarter lap
    e = path_positions(TargetPath(kind="figure8", radius=1.0, period=20.0), t)
    assert np.allclose(e[0], e[-1]) and np.allclose(e[40], [0, 0, 0]) and np.abs(e[:, 0]).max() > 0.99
    s1 = path_positions(TargetPath(kind="spline", radius=2.0, period=20.0, seed=5), t)
    s2 = path_positions(TargetPath(kind="spline", radius=2.0, period=20.0, seed=5), t)
    assert np.array_equal(s1, s2) and np.allclose(s1[0], s1[-1])
    assert np.abs(np.diff(s1, axis=0)).max() < 0.5      # continuous
    p = path_positions(TargetPath(kind="points", points=((1, 0, 0, 0), (3, 2, 4, 0))), np.array([0, 2, 5]))
    assert np.allclose(p, [[0, 0, 0], [1, 2, 0], [2, 4, 0]])
    n = path_positions(TargetPath(kind="none", centre=(1, 1, 1)), t)
    assert np.allclose(n, 1.0)
    with pytest.raises(ValueError):
        path_positions(TargetPath(kind="points", points=((2, 0, 0, 0), (1, 0, 0, 0))), t)


def test_headings_agree_with_yaw_then_pitch_angles_at_the_awkward_directions():
    """The trigonometry-free half angles match atan2's yaw and pitch, including straight back,
    straight up and down, no velocity at all, and almost straight back (no lost precision)."""
    v = np.array([[0.0, 0, -1], [-0.0, 0, -3], [1e-12, 0, -1], [-1e-12, 0.2, -1], [0, 1, 0],
                  [0, -2, 0], [0, 0, 0], [1, 0, 0], [-0.5, -0.5, 0.1], [2, 1, -1e-9],
                  [1e200, 0, -1e200], [1e-300, 0, 0], [3e-200, -1e-200, 2e-200]])
    yaw = np.arctan2(v[:, 0], v[:, 2])
    pitch = np.arctan2(-v[:, 1], np.hypot(v[:, 0], v[:, 2]))
    a, b, c, e = np.sin(yaw / 2), np.cos(yaw / 2), np.sin(pitch / 2), np.cos(pitch / 2)
    expected = np.stack([b * c, e * a, -a * c, b * e], axis=-1)
    q = headings_from_velocities(v)
    same = np.minimum(np.abs(q - expected).max(axis=1), np.abs(q + expected).max(axis=1))
    assert same.max() < 1e-12
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0)


def test_every_model_is_a_module_of_its_own_behind_one_interface():
    assert tuple(BEHAVIOURS) == MODELS
    modules = {where.split(":")[0] for where in BEHAVIOURS.values()}
    assert len(modules) == len(MODELS)
    for model in MODELS:
        config = _cfg(model=model, frames=2)
        state = SchoolState.start(config)
        chosen = behaviour(config, state)
        assert type(chosen).__module__ == BEHAVIOURS[model].split(":")[0]
        assert chosen.neighbours >= 1 and callable(chosen.want)
    with pytest.raises(ValueError):
        behaviour(_cfg(model="vicsek"), SchoolState.start(_cfg()))


def test_the_simulation_logs_the_lists_it_used():
    small = simulate(_cfg(frames=30))                       # below 300 fish: rebuilt every frame
    assert small.neighbours.starts == list(range(30))
    big = simulate(_cfg(groups=(Group("a", 320, L),), frames=40, bounds=((-4, -1, -4), (4, 1, 4))))
    assert big.neighbours.starts == [0, 15, 30]            # half a second apart at 30 fps
    mates = big.neighbours.mates[1]
    assert mates.shape == (7, 320) and mates.dtype == np.int16 and (mates >= 0).all()
    # nearest first, from where the fish were when the list was built (the step to frame 15 starts
    # from frame 14)
    pos = big.positions[14]
    d = np.linalg.norm(pos[mates] - pos[None], axis=2)
    assert np.all(np.diff(d, axis=0) >= -1e-12)


def test_a_ring_layout_starts_each_species_milling_round_its_own_ring():
    cfg = _cfg(layout="ring", frames=2, groups=(Group("a", 60, L), Group("b", 40, 0.3)),
               bounds=((-4, -1, -4), (4, 1, 4)))
    tr = simulate(cfg)
    m = measures(tr, [L, 0.3], only=("rotation", "polarization"))
    assert np.all(m["rotation"][0] > 0.9) and np.all(m["polarization"][0] < 0.3)
    for g in (0, 1):   # a horizontal ring: flat, and hollow
        pos = tr.positions[0, tr.group == g]
        out = pos - pos.mean(axis=0)
        assert np.ptp(out[:, 1]) < 0.6 * np.ptp(out[:, 0])
        assert (np.linalg.norm(out[:, [0, 2]], axis=1).min()
                > 0.3 * np.linalg.norm(out[:, [0, 2]], axis=1).max())


@pytest.mark.parametrize("model", ["boids", "couzin"])
def test_a_preroll_is_the_same_school_run_on_and_only_its_frames_are_kept(model):
    """A pre-roll of P seconds gives the frames a run P seconds longer has after them: the
    school forms in the steps before frame 0, which are neither recorded nor logged."""
    long = simulate(_cfg(model=model, frames=90, seed=2))
    steps: list[int] = []
    rolled = simulate(_cfg(model=model, frames=60, seed=2, preroll=1.0), progress=steps.append)
    assert rolled.positions.shape == (60, 40, 3) and rolled.times[0] == 0.0
    assert np.allclose(rolled.positions, long.positions[30:], atol=1e-9)
    assert np.allclose(rolled.velocities, long.velocities[30:], atol=1e-9)
    assert rolled.neighbours.starts == list(range(60))        # the frames' lists, from frame 0
    assert steps == [1] * 90                                  # a bar's update: one step each

