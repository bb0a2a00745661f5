"""Clips to steer by, each read back from the written file (pygltflib and numpy, not fishgen's
posing) and measured by its defining motion."""
from __future__ import annotations

import numpy as np
import pygltflib
import pytest

from fishgen.assembly.clips import (
    C_START_DEGREES,
    IDLE_WAVE_AMPLITUDE,
    IDLE_WAVE_HZ,
    SPRINT_SPEED,
    STAGE_1,
    TURN_DEGREES,
)
from fishgen.assembly.fish import make_fish
from fishgen.errors import FishgenError
from fishgen.exchange import export
from fishgen.geometry.body_wave import BodyWave
from fishgen.species.parser import load_species
from tests.assembly.engine_clients import bend_curvature
from tests.assembly.glb_motion import morphed_parts, node_channels
from tests.conftest import PARAMS, assert_valid_gltf

CLIPS = ("swim", "idle", "sprint", "turn_left", "turn_right", "burst")
WAVE = BodyWave()


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    fish = make_fish(load_species(PARAMS / "bonybream.txt"), clips=CLIPS)
    path = tmp_path_factory.mktemp("clips") / "fish.glb"
    export(fish.scene, path)
    doc = pygltflib.GLTF2().load(str(path))
    return fish, path, {a.name: k for k, a in enumerate(doc.animations)}


class Body:
    """The body's and tail fin's motion in one clip, as the file says (morphs on the rest nodes)."""

    def __init__(self, path, animation):
        parts = morphed_parts(path, animation)
        self.body, self.caudal = parts["body"], parts["caudal_fin"]
        rest = [p.positions @ p.world[:3, :3].T + p.world[:3, 3] for p in parts.values()]   # no morph
        z = np.concatenate([r[:, 2] for r in rest])
        self.length = float(np.ptp(z))
        body = rest[list(parts).index("body")]
        self.top = []                       # the top vertex of each ring, nose to tail
        for ring in np.unique(np.round(body[:, 2], 7))[::-1]:
            members = np.flatnonzero(np.abs(body[:, 2] - ring) < 1e-6)
            self.top.append(int(members[np.argmax(body[members, 1])]))
        self.tip = int(np.argmin(rest[list(parts).index("caudal_fin")][:, 2]))
        self.duration = float(self.body.times[-1])

    def tail(self, t):
        return self.caudal.world_positions(t)[:, self.tip, 0]

    def midline(self, t):
        return self.body.world_positions(t)[:, self.top]


def _hz(signal, t):
    x = signal - signal.mean()
    return np.count_nonzero((x[:-1] < 0) & (x[1:] >= 0)) / float(t[-1] - t[0])


def test_every_clip_is_in_the_file_and_valid(written):
    _, path, animations = written
    assert_valid_gltf(path)
    assert list(animations) == list(CLIPS)


@pytest.mark.parametrize("clip,hz,ptp", [("swim", 1.5, 0.2),
                                         ("idle", IDLE_WAVE_HZ, 0.2 * IDLE_WAVE_AMPLITUDE),
                                         ("sprint", 1.5 * SPRINT_SPEED, 0.2)])
def test_swimming_clips_beat_at_their_frequency(written, clip, hz, ptp):
    """Tail frequency from the Strouhal number (0.3): 1.5 beats per body length; sprint at 3 body
    lengths per second keeps the tail's 0.2 body-length amplitude (Bainbridge 1958), idle beats slow
    and faint."""
    _, path, animations = written
    motion = Body(path, animations[clip])
    t = np.linspace(0.0, motion.duration, 4000, endpoint=False)
    tail = motion.tail(t)
    assert _hz(tail, t) == pytest.approx(hz, rel=0.05)
    assert np.ptp(tail) / motion.length == pytest.approx(ptp, rel=0.05)


@pytest.mark.parametrize("clip,sign", [("turn_left", 1.0), ("turn_right", -1.0)])
def test_turns_hold_a_steady_arc_with_the_wave_on_it(written, clip, sign):
    """Averaged over the loop the wave cancels and leaves the arc: its curvature is the turn's, to the
    fish's left (+X) for turn_left."""
    _, path, animations = written
    motion = Body(path, animations[clip])
    t = np.linspace(0.0, motion.duration, 512, endpoint=False)
    midline = motion.midline(t)
    mean = bend_curvature(midline.mean(axis=0)[None], motion.length)[0]
    assert mean == pytest.approx(sign * np.radians(TURN_DEGREES), rel=0.02)
    assert _hz(motion.tail(t), t) == pytest.approx(1.5, rel=0.05)                  # still swimming
    assert np.ptp(bend_curvature(midline, motion.length)) > 0.3                    # the wave runs on it


def test_burst_bends_into_a_c_then_strokes_the_other_way_once(written):
    """C-start (Domenici & Blake 1997): stage 1 bends the body into a C (110 degrees nose to tail,
    reached in 80 ms), stage 2 sweeps the tail to the other side, then the body straightens out."""
    _, path, animations = written
    motion = Body(path, animations["burst"])
    t = np.linspace(0.0, motion.duration, 2001)
    curvature = bend_curvature(motion.midline(t), motion.length)
    peak = int(np.argmax(curvature))
    assert np.degrees(curvature[peak]) == pytest.approx(C_START_DEGREES, rel=0.02)
    assert t[peak] == pytest.approx(STAGE_1, abs=0.002)
    tail = motion.tail(t)
    assert tail[peak] > 0 and tail[t > STAGE_1].min() < -0.05 * motion.length      # then the stroke across
    ends = motion.body.weights_at(np.array([0.0, motion.duration]))
    assert not ends.any()                                          # starts and ends straight: not a loop


def test_looping_clips_close_and_all_clips_drive_the_same_targets_and_fins(written):
    fish, path, animations = written
    driven = []
    for clip in CLIPS:
        doc, channels = node_channels(path, animations[clip])
        driven.append({(doc.nodes[n].name, p) for n, p in channels})
        widths = {v.shape[1] for (n, p), (_, v) in channels.items() if p == "weights"}
        assert widths == {len(fish.facts.targets)}
        if clip != "burst":
            for (_, p), (_, values) in channels.items():
                assert np.allclose(values[0], values[-1], atol=1e-6), (clip, p)
    assert all(d == driven[0] for d in driven)
    names = doc.meshes[0].extras["targetNames"]
    assert names == ["wave_sin+", "wave_sin-", "wave_cos+", "wave_cos-", "bend_left", "bend_right", "c_start"]


def test_fins_scull_when_idle_and_fold_in_a_sprint(written):
    _, path, animations = written

    def swing(clip):
        doc, channels = node_channels(path, animations[clip])
        (_, q), = [v for (n, p), v in channels.items()
                   if doc.nodes[n].name == "pectoral_fin_left" and p == "rotation"]
        return np.degrees(2 * np.arcsin(np.clip(np.linalg.norm(q[:, :3], axis=1), 0, 1)))

    assert swing("idle").max() >= max(2 * swing("swim").max(), 10.0) - 1e-3
    sprint = swing("sprint")
    assert np.allclose(sprint, sprint[0]) and sprint[0] == pytest.approx(15.0, abs=1e-3)


def test_a_rigid_body_cannot_bend():
    with pytest.raises(FishgenError, match="--swim body"):
        make_fish(load_species(PARAMS / "bonybream.txt"), swim="fins", clips=("swim", "turn_left"))
