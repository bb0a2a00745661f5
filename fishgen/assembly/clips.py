"""The clips of a built fish, as key arrays: morph weights and fin angles over time.

Every clip drives the same morph targets (:data:`TARGET_NAMES`, those the fish carries) and the same
fins, so an engine can blend or cross-fade any two. A clip is planned here without knowing how the
fish is laid out (a node per part or one skinned mesh, one level of detail or several);
:mod:`fishgen.assembly.fish` puts the keys on the nodes. Sources and choices: docs/decisions.md,
"Fish for game engines".

- ``swim``: the cruising loop `fishgen build` has always made (tail-beat frequency from --speed by
  the Strouhal number, the file's fin swings).
- ``idle``: hovering. A faint, slow body wave; the pectoral fins scull (twice their swim amplitude,
  at least 10 degrees, four strokes in the 2 s loop) and the pelvic fins paddle (two).
- ``sprint``: 3 body lengths per second. The wave keeps its envelope (the tail's amplitude stays
  about 0.2 body length as fish speed up: Bainbridge 1958) and beats at the Strouhal frequency;
  the paired fins are folded against the body.
- ``turn_left`` / ``turn_right``: ``swim`` with the body bent into a steady arc of
  :data:`TURN_DEGREES` (the ``bend_left`` / ``bend_right`` target at full weight).
- ``burst``: a C-start (Domenici & Blake 1997): stage 1 bends the body into a C of
  :data:`C_START_DEGREES` to the left in :data:`STAGE_1` seconds; stage 2 sweeps the tail the other
  way (the ``bend_right`` arc) in :data:`STAGE_2`; stage 3 swims on at sprint frequency for
  :data:`STAGE_3_BEATS` beats, fading to straight. Played once, not looped; it turns the body, not the
  fish's node (an engine turns the node, or mirrors it for an escape to the right).
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from fishgen.assembly.animation import FinMotion
from fishgen.geometry.body_wave import BodyWave, wave_weights

WAVE_TARGETS = ("wave_sin+", "wave_sin-", "wave_cos+", "wave_cos-")
BEND_TARGETS = ("bend_left", "bend_right", "c_start")
TARGET_NAMES = WAVE_TARGETS + BEND_TARGETS
"""Every morph target a fish may carry, in file order; a fish carries the wave's four with the body
wave, and the bends its clips need."""

KEYS_PER_BEAT = 32
TURN_DEGREES = 45.0
"""The steady bend of a turn, nose tangent to tail tangent (curvature 0.79 rad per body length)."""
C_START_DEGREES = 110.0
"""The C at the end of a burst's stage 1 (the head turned 44 degrees about the centre of mass)."""
STAGE_1 = 0.08
STAGE_2 = 0.08
STAGE_3_BEATS = 2
SPRINT_SPEED = 3.0
IDLE_SECONDS = 2.0
IDLE_WAVE_HZ = 0.5
IDLE_WAVE_AMPLITUDE = 0.15
"""Hovering: one slow beat per loop at 15 % of the cruising amplitude (weights stay in [0, 0.15])."""
IDLE_STROKES = {"pectoral": 4, "pelvic": 2, "caudal": 1}
"""Strokes of each fin in the idle loop."""
FOLD_DEGREES = 15.0
"""How far a sprint folds the paired fins towards the body: most of their 20-degree splay."""


@dataclass(frozen=True)
class FinSwing:
    """One fin that moves: the file's swing, and which way (+1 or -1) lays it against the body."""

    name: str
    motion: FinMotion
    fold: float = 1.0

    @property
    def kind(self) -> str:
        return self.name.split("_")[0]


@dataclass(frozen=True)
class ClipPlan:
    name: str
    loop: bool
    times: np.ndarray                          # (K,) seconds of the weight keys
    weights: np.ndarray                        # (K, targets) in [0, 1]
    fins: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)  # name -> (s, degrees)
    tail_beat_hz: float | None = None
    bend_degrees: float = 0.0                  # the steady (turns) or peak (burst) bend

    @property
    def duration(self) -> float:
        ends = [float(self.times[-1])] if len(self.times) else []
        ends += [float(t[-1]) for t, _ in self.fins.values() if len(t)]
        return max(ends, default=0.0)


def targets_for(clips: Sequence[str], waving: bool) -> tuple[str, ...]:
    """The morph targets a fish with these clips carries (none on a rigid body)."""
    if not waving:
        return ()
    wanted = set(WAVE_TARGETS)
    if "turn_left" in clips or "burst" in clips:
        wanted.add("bend_left")
    if "turn_right" in clips or "burst" in clips:
        wanted.add("bend_right")
    if "burst" in clips:
        wanted.add("c_start")
    return tuple(t for t in TARGET_NAMES if t in wanted)


def _columns(targets: Sequence[str], keys: int) -> np.ndarray:
    return np.zeros((keys, len(targets)))


def _wave_into(out: np.ndarray, targets: Sequence[str], phase: np.ndarray, amplitude=1.0) -> None:
    if "wave_sin+" in targets:
        first = targets.index("wave_sin+")
        out[:, first:first + 4] = wave_weights(np.asarray(phase)) * np.asarray(amplitude)[..., None]


def _triangle(amplitude: float, cycles: int, seconds: float) -> tuple[np.ndarray, np.ndarray]:
    """A swing 0 -> +A -> 0 -> -A -> 0, ``cycles`` times in ``seconds``: keys at the turning points."""
    quarters = 4 * max(cycles, 1)
    t = np.arange(quarters + 1) * seconds / quarters
    return t, np.array([0.0, 1.0, 0.0, -1.0])[np.arange(quarters + 1) % 4] * amplitude


def _hold(angle: float, seconds: float) -> tuple[np.ndarray, np.ndarray]:
    return np.array([0.0, seconds]), np.array([angle, angle])


def wave_loop(wave: BodyWave, beats: int, frequency: float) -> tuple[np.ndarray, np.ndarray]:
    """(times, phases) of ``beats`` whole tail beats, KEYS_PER_BEAT keys each."""
    phase = np.linspace(0.0, 2.0 * np.pi * beats, beats * KEYS_PER_BEAT + 1)
    return phase / (2.0 * np.pi * frequency), phase


def swim_plan(name: str, targets: Sequence[str], fins: Sequence[FinSwing], fps: float,
              fin_loop_frames: int, wave_keys: tuple[np.ndarray, np.ndarray] | None,
              frequency: float | None, bend: str | None = None) -> ClipPlan:
    """The cruising loop (``swim``), or a turn (``bend`` names the target held at full weight).
    ``wave_keys``: the loop's (times, phases), None on a rigid body."""
    plan_fins = {}
    for fin in fins:
        keys, angles = fin.motion.keys(fin_loop_frames)
        plan_fins[fin.name] = (keys / fps, angles)
    if wave_keys is not None:
        times, phase = wave_keys
    else:
        times = np.array([0.0, fin_loop_frames / fps])
        phase = np.zeros(2)
    weights = _columns(targets, len(times))
    _wave_into(weights, targets, phase)
    if bend is not None:
        weights[:, targets.index(bend)] = 1.0
    return ClipPlan(name, True, times, weights, plan_fins, frequency,
                    TURN_DEGREES if bend is not None else 0.0)


def idle_plan(targets: Sequence[str], fins: Sequence[FinSwing]) -> ClipPlan:
    times, phase = wave_loop(BodyWave(), round(IDLE_WAVE_HZ * IDLE_SECONDS), IDLE_WAVE_HZ)
    weights = _columns(targets, len(times))
    _wave_into(weights, targets, phase, IDLE_WAVE_AMPLITUDE)
    plan_fins = {}
    for fin in fins:
        scale = 2.0 if fin.kind == "pectoral" else 1.0
        amplitude = max(scale * fin.motion.amplitude, 10.0 if fin.kind == "pectoral" else 0.0)
        strokes = IDLE_STROKES.get(fin.kind, 1)
        plan_fins[fin.name] = _triangle(amplitude * fin.motion.sign, strokes, IDLE_SECONDS)
    return ClipPlan("idle", True, times, weights, plan_fins, IDLE_WAVE_HZ if targets else None)


def sprint_plan(targets: Sequence[str], fins: Sequence[FinSwing], wave: BodyWave) -> ClipPlan:
    frequency = float(wave.frequency(SPRINT_SPEED))
    beats = max(1, round(frequency))                   # about a second of whole beats
    times, phase = wave_loop(wave, beats, frequency)
    seconds = beats / frequency
    weights = _columns(targets, len(times))
    _wave_into(weights, targets, phase)
    plan_fins = {}
    for fin in fins:
        if fin.kind == "caudal":                       # a rigid body beats its tail fin instead
            plan_fins[fin.name] = _triangle(fin.motion.amplitude * fin.motion.sign, beats, seconds)
        else:
            plan_fins[fin.name] = _hold(fin.fold * FOLD_DEGREES, seconds)
    return ClipPlan("sprint", True, times, weights, plan_fins, frequency)


def burst_plan(targets: Sequence[str], fins: Sequence[FinSwing], wave: BodyWave) -> ClipPlan:
    frequency = float(wave.frequency(SPRINT_SPEED))
    beat = 1.0 / frequency
    start3 = STAGE_1 + STAGE_2
    stage3 = start3 + np.linspace(0.0, STAGE_3_BEATS * beat, STAGE_3_BEATS * KEYS_PER_BEAT + 1)
    times = np.concatenate([[0.0, STAGE_1], stage3])
    weights = _columns(targets, len(times))
    left, right, c = (targets.index(n) for n in ("bend_left", "bend_right", "c_start"))
    weights[1, left] = weights[1, c] = 1.0                       # stage 1: the C
    # stage 2 ends with the tail swept across (the right arc); stage 3 lets it go over half a beat
    # while the wave takes over from where the tail is, at its right-hand extreme
    since = stage3 - start3
    weights[2:, right] = np.clip(1.0 - 2.0 * since / beat, 0.0, 1.0)
    k = 2.0 * np.pi / wave.wavelength                            # h(1, phi) = a(1) sin(k - phi)
    phase = k + np.pi / 2 + 2.0 * np.pi * frequency * since
    ramp_in = np.clip(2.0 * since / beat, 0.0, 1.0)
    fade_out = np.clip((STAGE_3_BEATS * beat - since) / beat, 0.0, 1.0)
    _wave_into(weights[2:], targets, phase, ramp_in * fade_out)
    end = float(times[-1])
    plan_fins = {}
    for fin in fins:
        folded = fin.fold * FOLD_DEGREES
        plan_fins[fin.name] = (np.array([0.0, STAGE_1, end - beat, end]),
                               np.array([0.0, folded, folded, 0.0]))
    return ClipPlan("burst", False, times, weights, plan_fins, frequency, C_START_DEGREES)
