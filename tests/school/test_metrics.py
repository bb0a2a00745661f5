"""fishgen.school.metrics, and the schooling behaviour it measures: school vs shoal, species apart."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from fishgen.school.metrics import MEASURES, PRINTED, measures, summary
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
    # the rotation order parameter's worst: the least of a mill, the most of a school that does not mill
    rotation = summary_table({"rotation": np.array([[0.0, 0.1], [0.9, 0.05], [0.7, 0.2]])}, 1, ["a", "b"])
    assert rotation == [("rotation (1 = milling), a", "0.80", "0.70"),
                        ("rotation (1 = milling), b", "0.12", "0.20")]
    text = format_table(rows, "after warm-up").splitlines()
    assert len(text) == 5 and len({len(line) for line in text}) == 1


def test_rotation_order_parameter_on_a_mill_and_a_parallel_line():
    # 24 fish round a ring swimming anticlockwise (a perfect mill), then all swimming +X in a row
    angle = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    ring = np.stack([np.cos(angle), 0 * angle, np.sin(angle)], 1) * 3.0
    tangent = np.stack([-np.sin(angle), 0 * angle, np.cos(angle)], 1)
    row = np.stack([np.arange(24.0), 0 * angle, 0 * angle], 1)
    m = measures(_tracks([ring, row], [tangent, np.tile([1.0, 0, 0], (24, 1))]), 0.5)
    assert m["rotation"][:, 0] == pytest.approx([1.0, 0.0], abs=1e-12)
    assert m["polarization"][:, 0] == pytest.approx([0.0, 1.0], abs=1e-12)
    # two species: each about its own centre
    m2 = measures(_tracks([ring, ring], [tangent, -tangent], group=np.arange(24) % 2), [0.5, 0.5])
    assert m2["rotation"][0] == pytest.approx([1.0, 1.0]) and m2["rotation"][1] == pytest.approx([1.0, 1.0])


def test_start_and_only_compute_just_what_is_asked():
    cfg = SchoolConfig(groups=(Group("a", 30, L),), frames=60, seed=1)
    tracks = simulate(cfg)
    whole = measures(tracks, L)
    assert list(whole) == [k for k in MEASURES if k in whole] and "rotation" in whole
    part = measures(tracks, L, start=20, only=PRINTED)
    assert set(part) == set(PRINTED) & set(whole)
    for name, values in part.items():
        assert np.isnan(values[:20]).all()
        assert np.allclose(values[20:], whole[name][20:], equal_nan=True), name
    with pytest.raises(ValueError):
        measures(tracks, L, only=("speed",))


def test_the_simulations_lists_give_what_a_fresh_search_gives():
    """At 400 fish the lists are rebuilt every half second; the measures still match a k-d tree
    search at every frame (the nearest neighbour to a hundredth of a body length)."""
    cfg = SchoolConfig(groups=(Group("a", 300, L), Group("b", 100, 0.3)), frames=45, seed=3,
                       bounds=((-4, -1.5, -4), (4, 1.5, 4)))
    tracks = simulate(cfg)
    assert len(tracks.neighbours.starts) < cfg.frames
    logged, searched = measures(tracks, [L, 0.3]), measures(replace(tracks, neighbours=None), [L, 0.3])
    for name in ("overlaps", "groups", "mixed_groups", "polarization", "rotation"):
        assert np.array_equal(logged[name], searched[name]), name
    assert np.allclose(logged["nearest_neighbour"], searched["nearest_neighbour"], atol=0.01)


def test_groups_are_fish_that_see_each_other_through_their_nearest():
    # two rows of 12 fish 0.6 m apart, 2.5 m between the rows: linked (within 3 body lengths)...
    a = np.stack([0.6 * np.arange(12.0), np.zeros(12), np.zeros(12)], 1)
    b = a + [0, 0, 2.5]
    vel = np.tile([1.0, 0, 0], (24, 1))
    assert measures(_tracks([np.concatenate([a, b])], [vel]), 1.0)["groups"][0, 0] == 1
    # ...but 3.5 m apart they are two groups
    assert measures(_tracks([np.concatenate([a, a + [0, 0, 3.5]])], [vel]), 1.0)["groups"][0, 0] == 2
    # two species side by side 2.5 m apart do not mingle: each fish's 4 nearest are its own kind
    two = measures(_tracks([np.concatenate([a, b])], [vel], group=[0] * 12 + [1] * 12), [1.0, 1.0])
    assert two["mixed_groups"][0] == 0 and two["groups"][0].tolist() == [1, 1]
    # interleaved, they do
    mixed = measures(_tracks([np.concatenate([a, a + [0.3, 0, 0]])], [vel], group=[0] * 12 + [1] * 12),
                     [1.0, 1.0])
    assert mixed["mixed_groups"][0] == 1


def test_the_order_the_simulation_logs_is_what_the_tracks_give():
    cfg = SchoolConfig(groups=(Group("a", 30, L), Group("b", 20, 0.3)), frames=80, seed=2)
    tracks = simulate(cfg)
    assert set(tracks.order) == {"polarization", "rotation", "heading_angle", "heading_angle_max", "turn"}
    logged, recomputed = measures(tracks, [L, 0.3]), measures(replace(tracks, order=None), [L, 0.3])
    for name in tracks.order:
        assert np.allclose(logged[name], recomputed[name], atol=1e-12, equal_nan=True), name
    for start in (1, 37):
        later = measures(replace(tracks, order=None), [L, 0.3], start=start, only=("turn", "heading_angle"))
        assert np.allclose(later["turn"][start:], recomputed["turn"][start:], atol=1e-15)
