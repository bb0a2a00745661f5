"""The Couzin et al. (2002) model: its rules one at a time, and the paper's four collective states.

Couzin, Krause, James, Ruxton & Franks, "Collective memory and spatial sorting in animal groups",
J. Theor. Biol. 218 (2002) 1-11. The states are told apart as the paper's Figure 2 does, by the
group's polarization p and its rotation order parameter m (angular momentum about the centre),
with delta ra = 15 and delta ro swept from 0 to 15: swarm (delta ro 0-0.5: p and m low), torus
(0.5-2.5: m high, p low), dynamic parallel (2.5-6: p high but below the highly parallel group's),
highly parallel (6.5-15: p about 1). docs/decisions.md (Schools, issue 23) gives the thresholds.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from fishgen.school.behaviour.couzin import Couzin
from fishgen.school.metrics import measures, summary
from fishgen.school.model import COUZIN_PRESETS, CouzinParams, Group, SchoolConfig, couzin_params
from fishgen.school.neighbours import Neighbours
from fishgen.school.simulate import simulate
from fishgen.school.state import SchoolState

WIDE = ((-200.0, -200.0, -200.0), (200.0, 200.0, 200.0))   # walls far away: the group alone


def paper_config(preset: str, *, count: int = 100, seed: int = 1, frames: int = 600,
                 **couzin) -> SchoolConfig:
    """The paper's set-up: its speed (3 body lengths/s with rr = 1 body length), its time step
    (0.1 s: 10 frames/s), 60 s from a random start."""
    return SchoolConfig(groups=(Group("fish", count, 1.0, 3.0),), model="couzin", frames=frames, fps=10.0,
                        seed=seed, bounds=WIDE, couzin=couzin_params(preset, **couzin))


def order(config: SchoolConfig) -> tuple[float, float]:
    """Mean polarization and rotation over the second half of the run."""
    tracks = simulate(config)
    numbers = summary(measures(tracks, 1.0, only=("polarization", "rotation")), config.frames // 2)
    return numbers["polarization"][0], numbers["rotation"][0]


# thresholds read from the paper's Figure 2 (docs/decisions.md)
STATES = {
    "swarm": lambda p, m: p < 0.3 and m < 0.3,
    "torus": lambda p, m: p < 0.35 and m > 0.6,
    "dynamic parallel": lambda p, m: 0.8 < p < 0.97 and m < 0.2,
    "highly parallel": lambda p, m: p > 0.97 and m < 0.2,
}


@pytest.mark.parametrize("preset", list(COUZIN_PRESETS))
def test_each_preset_reaches_its_state_in_the_papers_setup(preset):
    p, m = order(paper_config(preset))
    assert STATES[preset](p, m), f"{preset}: polarization {p:.2f}, rotation {m:.2f}"
    others = [name for name, test in STATES.items() if name != preset and test(p, m)]
    assert not others, f"{preset} also reads as {others}"


def test_presets_sit_in_the_papers_bands_of_the_orientation_zone():
    bands = {"swarm": (0, 0.5), "torus": (0.5, 2.5), "dynamic parallel": (2.5, 6),
             "highly parallel": (6.5, 15)}
    for name, params in COUZIN_PRESETS.items():
        low, high = bands[name]
        assert low <= params.orientation <= high and params.attraction == 15.0 and params.repulsion == 1.0
    assert couzin_params("torus", noise=0.1).noise == 0.1 and couzin_params().orientation == 1.0
    with pytest.raises(KeyError):
        couzin_params("milling")
    with pytest.raises(TypeError):
        couzin_params("torus", width=3)


def test_a_school_bigger_than_the_nearest_plus_the_sample_still_mills():
    """300 fish: each takes its 40 nearest and 60 others at random, weighted for the rest."""
    p, m = order(paper_config("torus", count=300, frames=400))
    assert m > 0.6 and p < 0.35
    # without the sample a fish is attracted only by its 40 nearest, and the torus is lost
    p, m = order(paper_config("torus", count=300, frames=400, sampled=0))
    assert m < 0.4


def test_the_paper_clock_turns_in_proportion_to_speed():
    """The turning radius s / theta is the paper's at any cruising speed."""
    for speed in (1.0, 3.0, 4.5):
        config = replace(paper_config("torus", count=5), groups=(Group("fish", 5, 0.4, speed),))
        model = Couzin(config, SchoolState.start(config))
        assert np.allclose(model.max_turn, math.radians(40.0) * speed / 3.0)
        turning_radius = speed / model.max_turn          # body lengths
        assert np.allclose(turning_radius, 3.0 / math.radians(40.0))


def test_fish_turn_at_most_the_turning_rate():
    config = paper_config("swarm", count=30, frames=100)
    tracks = simulate(config)
    v = tracks.velocities / np.linalg.norm(tracks.velocities, axis=2, keepdims=True)
    step = np.arccos(np.clip(np.einsum("fnc,fnc->fn", v[1:], v[:-1]), -1, 1))
    limit = math.radians(40.0) / config.fps
    assert step.max() <= limit + 1e-9 and step.max() > 0.9 * limit
    speed = np.linalg.norm(tracks.velocities, axis=2) / tracks.scale      # body lengths per second
    assert np.allclose(speed, 3.0)                                         # cruising speed, always


def wanted(positions, headings, **params) -> np.ndarray:
    """Where fish 0 wants to head, with the others placed by hand (body length 1, no noise)."""
    n = len(positions)
    config = SchoolConfig(groups=(Group("fish", n, 1.0, 3.0),), model="couzin", bounds=WIDE, size_jitter=0.0,
                          couzin=CouzinParams(noise=0.0, **params))
    state = SchoolState.start(config)
    state.pos = np.asarray(positions, float).T.copy()
    d = np.asarray(headings, float).T
    state.dir = d / np.linalg.norm(d, axis=0)
    nbrs = Neighbours(state, Couzin(config, state).neighbours)
    nbrs.refresh(0)
    nbrs.begin_step()
    return Couzin(config, state).want(state, nbrs, None).velocity[:, 0] / 3.0


def test_rules_repulsion_first_and_all_round():
    # a fish just behind (inside rr) and one far ahead (attraction): repulsion alone decides
    w = wanted([[0, 0, 0], [0, 0, -0.5], [0, 0, 8]], [[0, 0, 1], [1, 0, 0], [0, 0, 1]])
    assert np.allclose(w, [0, 0, 1])


def test_rules_orientation_and_attraction_halve():
    # one fish heading +X in the zone of orientation, one straight to the side in the zone of attraction
    w = wanted([[0, 0, 0], [0, 0, 1.5], [6, 0, 0]], [[0, 0, 1], [1, 0, 0], [0, 0, 1]])
    d_o = np.array([1, 0, 1]) / math.sqrt(2)     # own heading + the neighbour's, made unit
    d_a = np.array([1, 0, 0])
    expected = (d_o + d_a) / np.linalg.norm(d_o + d_a)
    assert np.allclose(w, expected)


def test_rules_blind_angle():
    # a fish straight behind in the zone of attraction goes unseen with the paper's 270 degrees...
    positions, headings = [[0, 0, 0], [0, 0, -6]], [[0, 0, 1], [0, 0, 1]]
    assert np.allclose(wanted(positions, headings), [0, 0, 1])
    # ...and is swum towards by a fish that sees all round
    assert np.allclose(wanted(positions, headings, blind_angle=0.0), [0, 0, -1])
    # beyond the zone of attraction nobody counts
    assert np.allclose(wanted([[0, 0, 0], [0, 0, 20]], headings, blind_angle=0.0), [0, 0, 1])


def test_a_torus_keeps_milling_and_a_parallel_group_does_not():
    """From a ring of fish already milling: the torus rules keep the mill (the paper's collective
    memory), the highly parallel group's rules straighten it out."""
    mill = replace(paper_config("torus", frames=300), layout="ring")
    p, m = order(mill)
    assert m > 0.8 and p < 0.3
    p, m = order(replace(mill, couzin=couzin_params("highly parallel")))
    assert p > 0.9 and m < 0.3
