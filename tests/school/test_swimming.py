"""Swimming bodies in a school: each fish's tail beats at the frequency its own speed asks for,
read back from the written glb (independently of fishgen's pose code)."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.exchange import export
from fishgen.school import run_school
from fishgen.school.model import TargetPath
from fishgen.school.scene_file import SceneFile, SpeciesEntry
from tests.assembly.glb_motion import node_channels
from tests.conftest import PARAMS, assert_valid_gltf

FPS = 30.0


@pytest.fixture(scope="module")
def fleeing(tmp_path_factory):
    """40 fish cruising, then a predator sweeping through: speeds change a lot."""
    scene = SceneFile(species=(SpeciesEntry(PARAMS / "bonybream.txt", 40),), frames=240, fps=FPS, seed=2,
                      predator=TargetPath(kind="circle", radius=1.5, period=6.0))
    run = run_school(scene)
    path = tmp_path_factory.mktemp("swim") / "school.glb"
    export(run.scene, path)
    return run, path


def _fish(doc):
    """(fish node, its part nodes) for every fish: the roots of the scene."""
    return [(root, doc.nodes[root].children) for root in doc.scenes[0].nodes]


def test_every_part_of_a_fish_shares_one_weights_track(fleeing):
    _, path = fleeing
    assert_valid_gltf(path)
    doc, channels = node_channels(path)
    for _, parts in _fish(doc):
        tracks = [channels[(p, "weights")] for p in parts if (p, "weights") in channels]
        assert len(tracks) == len(parts)                         # body and every fin
        times, first = tracks[0]
        assert len(times) == 240 and first.shape[1] == 4 and 0 <= first.min() and first.max() <= 1
        assert all(np.array_equal(first, w) for _, w in tracks)


def _sample(times, values, t):
    return np.stack([np.interp(t, times, values[:, k]) for k in range(values.shape[1])], axis=1)


def test_tail_beat_follows_each_fishs_speed(fleeing):
    """Speed from the baked translation keys, frequency from the baked weights: correlated > 0.9."""
    run, path = fleeing
    doc, channels = node_channels(path)
    t = np.arange(240) / FPS
    speeds, beats = [], []
    for (root, parts), length in zip(_fish(doc), run.body_lengths, strict=True):
        position = _sample(*channels[(root, "translation")], t)
        w = _sample(*channels[(parts[0], "weights")], t)
        phase = np.unwrap(np.arctan2(w[:, 3] - w[:, 2], w[:, 0] - w[:, 1]))   # sin, cos of the phase
        assert np.all(np.diff(phase) >= -1e-6)                    # never runs backwards: no pops
        window = 9                                                  # smooth over 0.3 s both ways
        kernel = np.ones(window) / window
        speed = np.linalg.norm(np.diff(position, axis=0), axis=1) * FPS / length
        beat = np.diff(phase) * FPS / (2 * np.pi)
        speeds.append(np.convolve(speed, kernel, "valid"))
        beats.append(np.convolve(beat, kernel, "valid"))
    speeds, beats = np.concatenate(speeds), np.concatenate(beats)
    assert np.ptp(speeds) > 0.5                                    # the predator made them speed up
    correlation = np.corrcoef(speeds, beats)[0, 1]
    print(f"speed vs tail-beat frequency: r = {correlation:.3f} over {len(speeds)} fish-frames")
    assert correlation > 0.9


def test_a_fleeing_fish_beats_faster(fleeing):
    run, path = fleeing
    doc, channels = node_channels(path)
    speed = np.linalg.norm(run.tracks.velocities, axis=2) / run.body_lengths[None]
    fastest = int(np.argmax(speed.max(axis=0)))
    _, parts = _fish(doc)[fastest]
    times, w = channels[(parts[0], "weights")]
    phase = np.unwrap(np.arctan2(w[:, 3] - w[:, 2], w[:, 0] - w[:, 1]))
    rate = np.gradient(phase, times)
    frame_fast, frame_slow = int(np.argmax(speed[:, fastest])), int(np.argmin(speed[:, fastest]))
    assert rate[frame_fast] > 1.3 * rate[frame_slow]
