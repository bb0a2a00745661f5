"""The body wave on a built fish: four morph targets on every part, and their weight keys.

Every mesh of the fish (the body and each fin) gets the same four targets +S, -S, +C, -C of
:mod:`fishgen.geometry.body_wave`, each vertex displaced sideways (glTF +X) by the wave at its
own position along the fish at rest. Fins therefore ride the body: a fin vertex where it meets
the body moves exactly as the body does there. One weights key array per fish drives all its
parts (docs/decisions.md: morph targets chosen over a skin).
"""
from __future__ import annotations

import math

import numpy as np

from fishgen.geometry.body_wave import BodyWave, wave_targets, wave_weights
from fishgen.scene.model import Channel, Sampler, Scene
from fishgen.scene.pose import Pose, pose

TARGETS = 4
LOOP_FREQUENCY_SLACK = 0.05
"""A built fish's loop may beat this much off the speed's frequency (a whole number of beats)."""
MAX_LOOP_SECONDS = 30.0
"""Loops are lengthened (whole fin cycles) to fit the beats no further than this."""
KEYS_PER_BEAT = 32
"""Weight keys per tail beat in a built fish's loop: linear interpolation between them keeps the
tail within 0.5 % of the wave's amplitude."""


def wave_nodes(scene: Scene) -> list[int]:
    """Nodes whose meshes carry the body-wave targets (and no others: a weights key array of the
    wave's four drives them)."""
    return [i for i, node in enumerate(scene.nodes) if node.mesh is not None
            and len(scene.meshes[node.mesh].weights) == TARGETS]


def body_axis(scene: Scene, posed: Pose | None = None) -> tuple[float, float]:
    """(z of the nose, body length) in metres of the fish at rest (or ``posed``): the nose is +Z."""
    posed = posed or pose(scene)
    lo, hi = np.inf, -np.inf
    for i, node in enumerate(scene.nodes):
        if node.mesh is None:
            continue
        world = posed.matrix(i)
        for prim in scene.meshes[node.mesh].primitives:
            z = prim.positions.astype(np.float64) @ world[2, :3] + world[2, 3]
            lo, hi = min(lo, float(z.min())), max(hi, float(z.max()))
    return hi, hi - lo


def add_wave_targets(scene: Scene, wave: BodyWave) -> bool:
    """Give every mesh of the fish ``scene`` (at rest, one node per mesh) the four wave targets;
    False (and nothing added) for a fish with no length to bend along."""
    posed = pose(scene)
    nose, length = body_axis(scene, posed)
    if not (np.isfinite(length) and length > 0):
        return False
    for i, node in enumerate(scene.nodes):
        if node.mesh is None:
            continue
        world = posed.matrix(i)
        # world lateral (+X) displacement seen in the node's own frame
        lateral = np.linalg.solve(world[:3, :3], np.array([1.0, 0.0, 0.0]))
        mesh = scene.meshes[node.mesh]
        for prim in mesh.primitives:
            z = prim.positions.astype(np.float64) @ world[2, :3] + world[2, 3]
            shifts = wave_targets((nose - z) / length, wave) * length        # (4, n) metres
            prim.targets = [{"POSITION": (shift[:, None] * lateral).astype(np.float32)} for shift in shifts]
        mesh.weights = [0.0] * TARGETS
    return True


def weight_sampler(times: np.ndarray, phase: np.ndarray) -> Sampler:
    """Keys of the four target weights at ``times`` for the wave phases ``phase`` (radians)."""
    return Sampler(np.asarray(times, np.float32), wave_weights(np.asarray(phase)).astype(np.float32))


def wave_channels(scene: Scene, sampler: Sampler, nodes: list[int] | None = None) -> list[Channel]:
    """One weights channel per wave node (all sharing ``sampler``)."""
    return [Channel(node, "weights", sampler) for node in (wave_nodes(scene) if nodes is None else nodes)]


def loop_beats(wave: BodyWave, speed: float, clip_seconds: float) -> tuple[int, float]:
    """(beats, frequency in Hz): the whole number of tail beats closest to ``speed``'s frequency
    that fits the clip exactly, so the wave closes with the fin swings (at least one beat), and
    never more than the wave's cap allows."""
    target = float(wave.frequency(speed))
    beats = max(1, round(target * clip_seconds))
    if beats > wave.max_frequency * clip_seconds * (1 + 1e-12):
        # rounded up past the cap (8.12 Hz "capped at 8"): round down instead; a loop too short
        # for one beat under the cap keeps its one
        beats = max(1, math.floor(wave.max_frequency * clip_seconds * (1 + 1e-12)))
    return beats, beats / clip_seconds


def loop_laps(wave: BodyWave, speed: float, fin_loop_seconds: float, most: int) -> int:
    """How many fin loops the clip spans (1..most): the fewest whose whole number of beats is within
    LOOP_FREQUENCY_SLACK of the frequency ``speed`` asks for, else the closest of them, never one
    beating faster than the wave's cap (unless none can: then 1)."""
    target = float(wave.frequency(speed))
    best, best_error = 1, np.inf
    for laps in range(1, max(1, most) + 1):
        _, frequency = loop_beats(wave, speed, laps * fin_loop_seconds)
        error = abs(frequency - target) / target
        if frequency > wave.max_frequency * (1 + 1e-12):  # a loop too short for one beat under the cap
            error = np.inf
        if error <= LOOP_FREQUENCY_SLACK:
            return laps
        if error < best_error:
            best, best_error = laps, error
        if laps * fin_loop_seconds > MAX_LOOP_SECONDS:
            break
    return best


def loop_keys(beats: int, frequency: float) -> tuple[np.ndarray, np.ndarray]:
    """(times, phases) of a seamless loop of ``beats`` tail beats, KEYS_PER_BEAT keys each."""
    count = beats * KEYS_PER_BEAT + 1
    phase = np.linspace(0.0, 2.0 * np.pi * beats, count)
    return phase / (2.0 * np.pi * frequency), phase
