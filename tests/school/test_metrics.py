"""fishgen.school.metrics, and the schooling behaviour it measures: school vs shoal, species apart."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.school.metrics import measures, summary
from fishgen.school.model import Brain, Group, SchoolConfig, Tracks
from fishgen.school.simulate import headings_from_velocities, simulate

L = 0.2
WARMUP = 150


def _tracks(pos, vel, group=None, scale=None) -> Tracks:
    pos, vel = np.asarray(pos, float), np.asarray(vel, float)
    n = pos.shape[1]
    return Tracks(times=np.arange(pos.shape[0]) / 30.0, positions=pos, velocities=vel,
                  headings=headings_from_velocities(vel),
                  group=np.zeros(n, int) if group is None else np.asarray(group),
                  scale=np.ones(n) if scale is None else np.asarray(scale, float))


def test_measures_on_hand_made_frames():
    # frame 0: 4 fish in a row 1 m apart, all swimming +X; frame 1: two pairs far apart, opposite
    pos = [[[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]],
           [[0, 0, 0], [0.4, 0, 0], [10, 0, 0], [10.9, 0, 0]]]
    vel = [[[1, 0, 0]] * 4, [[1, 0, 0], [1, 0, 0], [-1, 0, 0], [-1, 0, 0]]]
    m = measures(_tracks(pos, vel), 1.0)
    assert np.allclose(m["polarization"][:, 0], [1.0, 0.0])
    assert np.allclose(m["nearest_neighbour"], [1.0, (0.4 + 0.4 + 0.9 + 0.9) / 4])
    assert m["overlaps"].tolist() == [0, 1]           # 0.4 < 0.5 body length; 0.9 is not
    assert m["groups"][:, 0].tolist() == [1, 2]
    assert m["mixed_groups"].tolist() == [0, 0]
    assert np.allclose(m["heading_angle"], 0.0)
    assert m["turn"][1] == pytest.approx(np.pi)
    # body length per group times the per-fish scale: 3 m fish 1 m apart overlap
    m2 = measures(_tracks(pos, vel, scale=[3, 3, 3, 3]), [1.0])
    assert m2["overlaps"].tolist() == [3, 2] and m2["groups"][:, 0].tolist() == [1, 2]
    # two species: a mixed group when they are linked
    m3 = measures(_tracks(pos, vel, group=[0, 0, 1, 1]), [1.0, 1.0])
    assert m3["mixed_groups"].tolist() == [1, 0]
    assert m3["groups"].tolist() == [[1, 1], [1, 1]]
    s = summary(m, 1)
    assert s["polarization"] == [0.0] and s["overlaps"] == 1.0 and s["groups_peak"] == [2.0]


@pytest.fixture(scope="module")
def school():
    cfg = SchoolConfig(groups=(Group("a", 60, L),), frames=300, seed=0)
    return summary(measures(simulate(cfg), [L]), WARMUP)


@pytest.fixture(scope="module")
def shoal():
    cfg = SchoolConfig(groups=(Group("a", 60, L, brain=Brain(direction=0.0)),), frames=300, seed=0)
    return summary(measures(simulate(cfg), [L]), WARMUP)


def test_default_boids_school_is_cohesive_polarized_and_never_overlaps(school):
    assert school["groups_peak"] == [1.0]
    assert school["polarization"][0] > 0.8
    assert school["overlaps_peak"] == 0.0
    assert 0.6 < school["nearest_neighbour"] < 2.0


def test_shoal_without_alignment_is_cohesive_but_not_polarized(shoal):
    assert shoal["groups_peak"] == [1.0]
    assert shoal["polarization"][0] < 0.5
    assert shoal["overlaps_peak"] == 0.0


def test_fish_never_overlap_even_when_packed():
    # a strong pull together and no keepaway: only the hard separation keeps bodies apart
    brain = Brain(center=3.5, keepaway=0.0, repel_distance=0.1)
    cfg = SchoolConfig(groups=(Group("a", 60, L, brain=brain),), frames=200, seed=5, layout="box",
                       bounds=((-1, -0.5, -1), (1, 0.5, 1)))
    m = measures(simulate(cfg), [L])
    assert m["overlaps"].max() == 0
    assert m["nearest_neighbour"][50:].mean() < 1.0    # they are packed indeed


def test_two_species_keep_apart():
    cfg = SchoolConfig(groups=(Group("a", 40, L), Group("b", 30, 0.3)), frames=300, seed=0)
    tr = simulate(cfg)
    s = summary(measures(tr, [L, 0.3]), WARMUP)
    assert s["mixed_groups_peak"] == 0.0
    assert s["groups_peak"] == [1.0, 1.0]
    # inter-species nearest distance exceeds the intra-species one
    pos = tr.positions[WARMUP:]
    a, b = pos[:, tr.group == 0], pos[:, tr.group == 1]
    ab = np.linalg.norm(a[:, :, None] - b[:, None], axis=3)
    aa = np.linalg.norm(a[:, :, None] - a[:, None], axis=3) + np.eye(a.shape[1]) * 1e9
    assert ab.min(axis=2).mean() > 2 * aa.min(axis=2).mean()


def test_summary_table_has_mean_and_the_bad_extreme_per_species():
    from fishgen.school.metrics import format_table, summary_table

    per_frame = {"polarization": np.array([[0.1, 0.2], [0.9, 0.5], [0.7, 0.7]]),
                 "overlaps": np.array([9, 0, 2]), "heading_angle": np.array([0.0, np.pi / 2, 0.0])}
    rows = summary_table(per_frame, 1, ["a", "b"])
    assert rows == [("polarization (1 = parallel), a", "0.80", "0.70"),
                    ("polarization (1 = parallel), b", "0.60", "0.50"),
                    ("overlapping pairs", "1", "2"),
                    ("heading vs velocity (deg)", "45.0", "90.0")]
    text = format_table(rows, "after warm-up").splitlines()
    assert len(text) == 5 and len({len(line) for line in text}) == 1
