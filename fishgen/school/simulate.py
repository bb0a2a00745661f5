"""Simulate a school: VRFish's boids brain (Lobb 2002, ch. 7.2), the 2017 particle swarm, or
Couzin et al.'s zones (2002).

`simulate(config, progress=None) -> Tracks`. Vectorised numpy over all fish; neighbours from
scipy's cKDTree (fishgen.school.neighbours), so cost grows about linearly with fish count.

Each step the behaviour model (fishgen.school.behaviour) proposes a new velocity; the shared urges
(soft bounds, other species, a predator: fishgen.school.steering) add to it; the fish's heading
turns towards it by at most the model's turn rate, the speed is clamped, the fish moves, a hard
separation pushes apart any pair closer than HARD_SEPARATION mean body lengths (VRFish's fish swim
through each other, ch. 7.3; ours do not), and positions are kept inside `config.bounds`. The
velocity always points along the heading, so a fish faces where it swims.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

from fishgen.school.behaviour import Behaviour, behaviour
from fishgen.school.metrics import heading_checks, membership_matrix, nose_directions, order_parameters
from fishgen.school.model import NeighbourLog, SchoolConfig, Tracks
from fishgen.school.neighbours import Neighbours
from fishgen.school.paths import path_positions
from fishgen.school.state import SchoolState, norm
from fishgen.school.steering import (
    FLEE_SPEEDUP,
    bounds_accel,
    clamp,
    flee_accel,
    other_species_accel,
    separate,
    turn_towards,
)

Progress = Callable[[int], None]

HEADING_CHUNK_ELEMENTS = 4096  # fish x frames per vectorised heading pass
SEPARATION_PASSES = 1
START_SEPARATION_PASSES = 4


def simulate(config: SchoolConfig, progress: Progress | None = None) -> Tracks:
    """Run `config.frames` frames at `config.fps`; frame 0 is the start layout, or with
    `config.preroll` the school that many seconds after it (the steps before are not recorded).

    `progress(1)` is called after each step when given, preroll_frames + frames times in all: as a
    progress bar's ``update`` adds what it is given.
    """
    _check(config)
    state = SchoolState.start(config)
    model = behaviour(config, state)
    frames = int(config.frames)
    pre = config.preroll_frames
    times = np.arange(frames, dtype=np.float64) / config.fps
    target = path_positions(config.target, times) if config.model == "pso" else None
    predator = path_positions(config.predator, times) if config.predator is not None else None
    log = NeighbourLog()
    # the pre-roll's neighbour lists are not the measures' to reuse: not logged
    nbrs = Neighbours(state, model.neighbours, None if pre else log)
    nbrs.refresh(0)
    for _ in range(START_SEPARATION_PASSES):
        separate(state, nbrs)
    clamp(state)
    if pre:
        # the school forms round the target's start, and meets the predator only at frame 0
        for k in range(1, pre + 1):
            step(state, nbrs, model, k, None if target is None else target[0], None)
            if progress is not None:
                progress(1)
        nbrs.log = log
        nbrs.refresh(0)

    n = state.n
    polar, rotation = np.empty((frames, state.n_groups)), np.empty((frames, state.n_groups))
    member = membership_matrix(state.group, state.n_groups)
    positions = np.empty((frames, n, 3))
    velocities = np.empty((frames, n, 3))
    headings = np.empty((frames, n, 4))
    for f in range(frames):
        if f > 0:
            step(state, nbrs, model, f, None if target is None else target[f],
                 None if predator is None else predator[f])
        positions[f] = state.pos.T
        velocities[f] = state.vel.T
        polar[f], rotation[f] = order_parameters(state.pos, state.dir, state.group, state.n_groups, member)
        if progress is not None:
            progress(1)
    # headings for all frames, a few frames at a time: small chunks keep numpy's temporaries in the
    # CPU cache (at 1,000 fish, 64-frame chunks ran 2.5x slower than 4-frame ones). Each chunk's
    # sign follows the previous chunk's last frame (q and -q are one rotation, but a sign flip
    # breaks linear key interpolation).
    # The heading checks (the measures' heading_angle and turn) are taken on the same chunks.
    chunk = max(1, HEADING_CHUNK_ELEMENTS // max(n, 1))
    checks = np.empty((3, frames))
    before = None
    for start in range(0, frames, chunk):
        q = headings_from_velocities(velocities[start:start + chunk])
        if start > 0:
            q *= np.where(np.einsum("nk,nk->n", q[0], headings[start - 1]) < 0, -1.0, 1.0)[:, None]
        headings[start:start + chunk] = q
        checks[:, start:start + chunk] = heading_checks(q, velocities[start:start + chunk], before)
        before = nose_directions(q[-1]).T
    order = {"polarization": polar, "rotation": rotation, "heading_angle": checks[0],
             "heading_angle_max": checks[1], "turn": checks[2]}
    return Tracks(times=times, positions=positions, velocities=velocities,
                  headings=headings, group=state.group.copy(),
                  scale=state.scale.copy(), target=target, predator=predator, neighbours=log, order=order)


def step(state: SchoolState, nbrs: Neighbours, model: Behaviour, frame: int,
         target: np.ndarray | None, predator: np.ndarray | None) -> None:
    """Move the school one frame on."""
    n = state.n
    if n == 0:
        return
    if nbrs.due(frame):
        nbrs.refresh(frame)
    nbrs.begin_step()
    want = model.want(state, nbrs, target)
    new_vel = want.velocity
    acc = bounds_accel(state)
    if nbrs.other is not None:
        acc += other_species_accel(state, nbrs)
    flee_boost = np.zeros(n)
    if predator is not None:
        fa, flee_boost = flee_accel(state, predator)
        acc += fa
    new_vel += acc * state.dt
    v_max = want.v_max * (1.0 + FLEE_SPEEDUP * flee_boost)
    near_dist = nbrs.near_offsets()[1] if n > 1 else None  # at the step's start, for the separation
    state.dir = turn_towards(state.dir, new_vel, want.max_turn * state.dt)
    speed = np.minimum(np.maximum(norm(new_vel), want.v_min), v_max)
    if predator is not None:  # fleeing fish speed up
        fast = np.minimum(v_max, state.cruise * (1.0 + FLEE_SPEEDUP * flee_boost))
        speed = np.where(flee_boost > 0, np.maximum(speed, fast), speed)
    state.vel = state.dir * speed
    state.pos = state.pos + state.vel * state.dt
    if near_dist is not None:
        # only fish that were within one step's closing distance of a too-near neighbour can be
        # too near now (pairs close by at most both speeds x dt; the pushes add a little more)
        closing = 2.5 * float(np.max(v_max)) * state.dt
        rows = np.flatnonzero(np.any(near_dist < nbrs.near_need + closing, axis=0))
        for _ in range(SEPARATION_PASSES):
            separate(state, nbrs, rows)
    clamp(state)


def headings_from_velocities(velocities: np.ndarray) -> np.ndarray:
    """Quaternions (x, y, z, w) turning +Z to each velocity with no roll (+Y stays as up as it can).

    q = yaw about +Y then pitch about +X; signs are made continuous frame to frame (q and -q are
    one rotation, but a sign flip breaks linear key interpolation).
    """
    v = np.asarray(velocities, dtype=np.float64)
    vx, vy, vz = v[..., 0], v[..., 1], v[..., 2]
    # the half angles depend only on the direction: scaled so that squares neither overflow nor
    # vanish (component by component: a reduction over a trailing axis of 3 is slow in numpy)
    big = np.maximum(np.maximum(np.abs(vx), np.abs(vy)), np.abs(vz))
    inv = 1.0 / np.where(big > 0, big, 1.0)
    vx, vy, vz = vx * inv, vy * inv, vz * inv
    horiz = np.sqrt(vx * vx + vz * vz)
    # half-angle (cos, sin) pairs straight from the vector, no trigonometry: for the yaw,
    # (cos, sin)(yaw / 2) ~ (horiz + vz, vx), with horiz + vz = vx^2 / (horiz - vz) where vz < 0
    # so that a fish swimming almost straight back loses no precision; a vertical or zero velocity
    # has no yaw (atan2(0, 0) = 0) and a fish swimming straight back has yaw pi
    with np.errstate(invalid="ignore", divide="ignore"):
        cos_yaw = np.where(vz >= 0, horiz + vz, vx * vx / (horiz - vz))
    length = np.sqrt(cos_yaw * cos_yaw + vx * vx)
    turned = length > 0
    safe = np.where(turned, length, 1.0)
    b = np.where(turned, cos_yaw / safe, horiz == 0)     # cos(yaw / 2)
    a = np.where(turned, vx / safe, horiz > 0)           # sin(yaw / 2)
    # pitch: (cos, sin)(pitch / 2) ~ (|v| + horiz, -vy), never both 0 but for v = 0 (no pitch)
    cos_pitch = np.sqrt(horiz * horiz + vy * vy) + horiz
    length = np.sqrt(cos_pitch * cos_pitch + vy * vy)
    safe = np.where(length > 0, length, 1.0)
    e = np.where(length > 0, cos_pitch / safe, 1.0)      # cos(pitch / 2)
    c = -vy / safe                                       # sin(pitch / 2)
    q = np.stack([b * c, e * a, -a * c, b * e], axis=-1)
    if q.ndim == 3 and q.shape[0] > 1:
        dots = np.einsum("fnk,fnk->fn", q[1:], q[:-1])
        flips = np.cumprod(np.where(dots < 0, -1.0, 1.0), axis=0)
        q[1:] *= flips[..., None]
    return q


def _check(config: SchoolConfig) -> None:
    if not config.fps > 0 or not np.isfinite(config.fps):
        raise ValueError(f"fps must be > 0, found {config.fps}")
    if config.frames < 1:
        raise ValueError(f"frames must be >= 1, found {config.frames}")
    lo, hi = np.asarray(config.bounds[0], float), np.asarray(config.bounds[1], float)
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(hi > lo)):
        raise ValueError(f"bounds must be finite with min < max, found {config.bounds}")
    for g in config.groups:
        if g.count < 0 or not g.body_length > 0:
            raise ValueError(f"group {g.name!r}: count >= 0 and body_length > 0 needed")
