"""Bake simulated tracks into one animated scene: shared meshes, one node per fish, one clip.

Each species is built once by the same code as `fishgen build`; its meshes, materials
and texture are shared by all its fish. A fish is a node (translation and rotation
keys for the whole run, its size as a constant scale) whose children are the species'
parts; its moving fins swing for the whole run, phase-shifted per fish, keyed at
their turning points so a fin costs a few keys per cycle. Position and rotation keys
are thinned per fish to the longest step whose linear interpolation stays within
``tolerance`` (metres, and the matching angle at one body length) of every frame.

A species built with the body wave (`fishgen build`'s default) shares its four wave targets too;
each fish gets one weights key array for all its parts, keyed every frame, whose tail-beat
frequency follows the fish's own speed (Strouhal number) with the phase integrated over time, so a
fish that speeds up beats faster without a jump.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from fishgen.assembly.body_wave import wave_nodes
from fishgen.assembly.instance import add_species
from fishgen.geometry.body_wave import BodyWave, integrate_phase, wave_weights
from fishgen.scene.model import Channel, Clip, Instancer, Material, Node, Path_, Sampler, Scene
from fishgen.scene.pose import sample
from fishgen.school.model import Tracks

STEPS = (2, 3, 4, 6, 8, 12, 16, 24, 30)
"""Key spacings tried, in frames; the longest is a one-second horizon at 30 fps."""
TINT_STREAM = 0x7157
"""Mixed into the seed of the generators that tint: the fin and wave phases keep their own."""
PROTOTYPE_STREAM = 0x1A57
"""Mixed into the seed of the generator that gives each fish its prototype (:func:`bake_prototypes`)."""
FIN_PHASES = 16
"""Distinct fin phases per species: fish sharing one share its fin keys in the file, and 16 phases
already keep neighbours from beating in step."""


def merge_species(school: Scene, fish: Scene) -> list[tuple[Node, int | None, bool]]:
    """Add one built fish's meshes, materials and images to ``school``; return its part nodes
    (as templates with re-indexed meshes), the index of each part's fin swing channel in the swim
    clip, and whether the part carries the body-wave targets."""
    mesh_base = add_species(school, fish).mesh_base
    (root,) = fish.roots
    swim = fish.clip("swim")
    channel_of = ({c.node: k for k, c in enumerate(swim.channels) if c.path == "rotation"}
                  if swim is not None else {})
    parts = []
    waving = set(wave_nodes(fish))
    for child in fish.nodes[root].children:
        node = fish.nodes[child]
        parts.append((replace(node, children=[], mesh=None if node.mesh is None else node.mesh + mesh_base),
                      channel_of.get(child), child in waving))
    return parts


def key_steps(values: np.ndarray, tolerance: float) -> np.ndarray:
    """Per fish, the key spacing in frames: the longest step of STEPS, tried shortest first, whose
    linear interpolation reproduces every frame of ``values`` (F, N, W) within ``tolerance``, up to
    the first that does not (1: every frame is a key).

    Component-major, and only the fish that passed the step before try the next: most of a
    school's rotations need every frame, and measuring their every step cost two thirds of a bake.
    (Over 1,000 fish x 600 frames, no fish's step differs from trying every step for every fish.)"""
    frames, count = values.shape[:2]
    best = np.ones(count, np.int64)
    v = np.ascontiguousarray(np.asarray(values, np.float32).transpose(2, 0, 1))   # (W, F, N)
    t = np.arange(frames)
    active = np.arange(count)
    for step in [s for s in STEPS if s < frames]:
        if active.size == 0:
            break
        keys = _keys(frames, step)
        k1 = np.clip(np.searchsorted(keys, t, side="right"), 1, len(keys) - 1)
        a, b = keys[k1 - 1], keys[k1]
        w = ((t - a) / np.maximum(b - a, 1))[:, None]
        sub = v if active.size == count else v[:, :, active]
        error = np.zeros((frames, active.size))
        for c in range(sub.shape[0]):
            error += np.square(sub[c][a] * (1 - w) + sub[c][b] * w - sub[c])
        passed = error.max(axis=0) <= tolerance * tolerance
        best[active[passed]] = step
        active = active[passed]
    return best


def reduce_keys(values: np.ndarray, tolerance: float) -> list[np.ndarray]:
    """Per fish, the frame indices to keep (key_steps); fish with one spacing share one array."""
    frames = values.shape[0]
    steps = key_steps(values, tolerance)
    shared = {int(s): _keys(frames, int(s)) for s in np.unique(steps)}
    return [shared[int(s)] for s in steps]


def _keys(frames: int, step: int) -> np.ndarray:
    return np.unique(np.append(np.arange(0, frames, step), frames - 1))


def _fin_keys(channel: Channel, phase: float, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """A fin's swing keys (the turning points of its cycle) shifted by ``phase`` seconds and
    repeated to cover [0, duration], with the exact pose at both ends."""
    times = np.asarray(channel.sampler.times, np.float64)
    values = np.asarray(channel.sampler.values, np.float64)
    period = float(times[-1])
    if period <= 0 or len(times) < 2:
        return np.array([0.0]), values[:1]
    laps = int(np.ceil((duration + phase) / period)) + 1
    all_t = (times[None, :-1] + period * np.arange(laps)[:, None]).ravel() - phase
    all_v = np.tile(values[:-1], (laps, 1))
    inside = (all_t > 0) & (all_t < duration)
    ends = [sample(channel, (edge + phase) % period) for edge in (0.0, duration)]
    return (np.concatenate([[0.0], all_t[inside], [duration]]),
            np.concatenate([ends[0][None], all_v[inside], ends[1][None]]))


def bake(fish_scenes: list[Scene], tracks: Tracks, *, tolerance: float = 0.002, seed: int = 0,
         body_lengths: np.ndarray | None = None, wave: BodyWave | None = None, tints: int = 1,
         tint: float = 0.15) -> Scene:
    """One scene of every fish of ``tracks``; ``fish_scenes[g]`` is the built fish of group ``g``.

    ``wave``: the body wave the species were built with (default :class:`BodyWave`); it drives
    the species whose meshes carry the wave targets. ``tints`` colour variants per species
    (:class:`fishgen.school.model.Variety`; 1: the species' own colours only, and the file is
    what it was before variants existed), each channel of a variant's colour 1 - ``tint`` to 1."""
    school = Scene(name="school")
    templates = [merge_species(school, fish) for fish in fish_scenes]
    wears = _wears(len(tracks.group), tints, seed)
    worn = [set(wears[np.asarray(tracks.group) == g].tolist()) for g in range(len(fish_scenes))]
    variants = _tint_variants(school, templates, tints, tint, seed, worn)
    swims = [fish.clip("swim") for fish in fish_scenes]
    plan = _school_keys(fish_scenes, tracks, tolerance, seed, body_lengths, wave)
    duration, rng, times32 = plan.duration, plan.rng, plan.times32
    position_keys, rotation_keys, weights_all = plan.positions, plan.rotations, plan.weights
    # fish-major float32 copies: each fish's keys are then gathered from one contiguous block
    positions32 = np.ascontiguousarray(np.asarray(tracks.positions).transpose(1, 0, 2), np.float32)
    headings32 = np.ascontiguousarray(np.asarray(tracks.headings).transpose(1, 0, 2), np.float32)
    key_times: dict[int, np.ndarray] = {}   # one key-times array per key spacing
    channels: list[Channel] = []
    fin_samplers: dict[tuple[int, int, int], Sampler] = {}
    for i, group in enumerate(np.asarray(tracks.group)):
        size = float(tracks.scale[i])
        x, y, z = (float(v) for v in tracks.positions[0, i])
        qx, qy, qz, qw = (float(v) for v in tracks.headings[0, i])
        node = school.add_node(Node(name=f"{fish_scenes[group].name}_{i:05d}", scale=(size, size, size),
                                    translation=(x, y, z), rotation=(qx, qy, qz, qw)))
        paths: tuple[tuple[Path_, np.ndarray, np.ndarray], ...] = (
            ("translation", position_keys[i], positions32), ("rotation", rotation_keys[i], headings32))
        for path, keys, values in paths:
            if id(keys) not in key_times:
                key_times[id(keys)] = times32[keys]
            sampler = Sampler(key_times[id(keys)], values[i][keys])
            channels.append(Channel(node, path, sampler))
        swim = swims[group]
        phase = int(rng.integers(FIN_PHASES))
        weights = None if weights_all is None else Sampler(times32, weights_all[i])
        for template, channel_index, waving in variants[group][int(wears[i])]:
            part = school.add_node(_part(template), parent=node)
            if waving and weights is not None:
                channels.append(Channel(part, "weights", weights))
            if channel_index is not None and swim is not None and duration > 0:
                key = (int(group), channel_index, phase)
                if key not in fin_samplers:
                    shift = swim.duration * phase / FIN_PHASES
                    t, v = _fin_keys(swim.channels[channel_index], shift, duration)
                    fin_samplers[key] = Sampler(t.astype(np.float32), v.astype(np.float32))
                channels.append(Channel(part, "rotation", fin_samplers[key]))
    if duration > 0:
        school.clips.append(Clip("school", channels))
    return school


Part = tuple[Node, int | None, bool]


def _part(template: Node) -> Node:
    """A fish's own copy of a part node (dataclasses.replace costs four times as much, 10,000 times)."""
    return Node(template.name, template.translation, template.rotation, template.scale, [], template.mesh,
                template.skin, template.matrix)


def _tint_variants(school: Scene, templates: list[list[Part]], tints: int, tint: float,
                   seed: int, worn: list[set[int]]) -> list[list[list[Part]]]:
    """Per species, per variant, its part templates. Variant 0 is the species as merged; each other
    that a fish of the species wears (``worn[species]``) adds a copy of every species material with
    its base colour tinted, and a copy of every mesh whose primitives name those materials: the
    same vertex, index and morph arrays, which the writer stores once.

    The file holds only what some fish shows: a variant nobody wears keeps its place in the list
    but adds nothing, and when no fish wears the species' own colours, its first worn variant takes
    their materials' and meshes' places (the validator notes every object nothing uses)."""
    out = []
    factors = _tint_factors(len(templates), tints, tint, seed)
    for parts, species_factors, wearing in zip(templates, factors, worn, strict=True):
        meshes = sorted({t.mesh for t, _, _ in parts if t.mesh is not None})
        materials = sorted({p.material for m in meshes for p in school.meshes[m].primitives
                            if p.material is not None})
        own_materials = {m: school.materials[m] for m in materials}  # before a variant takes their place
        own_meshes = {m: school.meshes[m] for m in meshes}
        variants: list[list[Part]] = [parts if 0 in wearing else []]
        in_place = 0 not in wearing
        for v, factor in enumerate(species_factors[1:], start=1):
            if v not in wearing:
                variants.append([])
                continue
            new_material = {m: _placed(school.materials, m, _tint(own_materials[m], factor, v), in_place)
                            for m in materials}
            new_mesh = {}
            for m in meshes:
                mesh = own_meshes[m]
                prims = [replace(p, material=None if p.material is None else new_material[p.material])
                         for p in mesh.primitives]
                new_mesh[m] = _placed(school.meshes, m, replace(mesh, name=f"{mesh.name}_tint{v}",
                                                                primitives=prims), in_place)
            variants.append([(replace(t, mesh=None if t.mesh is None else new_mesh[t.mesh]), c, w)
                             for t, c, w in parts])
            in_place = False
        out.append(variants)
    return out


def _tint(material: Material, factor: np.ndarray, variant: int) -> Material:
    """``material`` as colour variant ``variant`` wears it: its base colour times ``factor``."""
    r, g, b, a = material.base_color
    return replace(material, name=f"{material.name}_tint{variant}",
                   base_color=(r * float(factor[0]), g * float(factor[1]), b * float(factor[2]), a))


def _placed(items: list, at: int, item: Any, in_place: bool) -> int:
    """Put ``item`` at ``at`` in ``items`` (in place of what is there) or after the last; its index."""
    if in_place:
        items[at] = item
        return at
    items.append(item)
    return len(items) - 1


def _tint_factors(species: int, tints: int, tint: float, seed: int) -> list[list[np.ndarray]]:
    """Per species, per colour variant, the (r, g, b) its materials' base colours are multiplied by
    (variant 0: ones, the species' own colours), seeded."""
    rng = np.random.default_rng((seed, TINT_STREAM, 1))
    return [[np.ones(3)] + [1.0 - float(tint) * rng.uniform(0.0, 1.0, 3)
                            for _ in range(1, max(1, int(tints)))] for _ in range(species)]


def _wears(fish: int, tints: int, seed: int) -> np.ndarray:
    """Which colour variant each fish wears: its own generator, so that the phases stay as they were."""
    return (np.random.default_rng((seed, TINT_STREAM)).integers(0, tints, fish) if tints > 1
            else np.zeros(fish, np.int64))


def _wave_phases(fish_scenes: list[Scene], tracks: Tracks, lengths: np.ndarray,
                 rng: np.random.Generator, wave: BodyWave) -> np.ndarray | None:
    """Per frame and fish (F, N), the body wave's phase: a seeded start, then 2 pi times the
    integral of the tail-beat frequency at the fish's own speed in body lengths per second."""
    waving = [bool(wave_nodes(fish)) for fish in fish_scenes]
    start = rng.uniform(0.0, 2.0 * np.pi, len(tracks.group))  # drawn always: seeds stay in step
    if not any(waving):
        return None
    times = np.asarray(tracks.times, np.float64)
    dt = float(times[1] - times[0]) if len(times) > 1 else 0.0
    speed = np.linalg.norm(np.asarray(tracks.velocities, np.float64), axis=2) / lengths[None, :]
    frequency = np.zeros_like(speed)
    for g, waves in enumerate(waving):
        if waves:
            members = np.asarray(tracks.group) == g
            frequency[:, members] = wave.frequency(speed[:, members])
    return integrate_phase(frequency, dt, start)


def bake_instanced(fish_scenes: list[Scene], tracks: Tracks, *, tolerance: float = 0.002, seed: int = 0,
                   body_lengths: np.ndarray | None = None, wave: BodyWave | None = None) -> Scene:
    """:func:`bake` for fish built with levels of detail or as one skinned mesh (``fishgen build
    --lods/--merge``): every fish is a copy of its species' node tree (its levels, their MSFT_lod
    ids, its own skin in the merged layout) over the species' shared meshes
    (:mod:`fishgen.assembly.instance`). The same keys as :func:`bake`: roots thinned to the
    tolerance, the wave's phase integrated at each fish's speed, fin swings phase-shifted."""
    from fishgen.assembly.instance import add_fish, add_species, pad_weights

    school = Scene(name="school")
    templates = [add_species(school, fish) for fish in fish_scenes]
    plan = _school_keys(fish_scenes, tracks, tolerance, seed, body_lengths, wave)
    duration, rng, times32 = plan.duration, plan.rng, plan.times32
    position_keys, rotation_keys, weights_all = plan.positions, plan.rotations, plan.weights
    channels: list[Channel] = []
    fin_samplers: dict[tuple[int, int, int], Sampler] = {}
    for i, group in enumerate(np.asarray(tracks.group)):
        made = add_fish(school, templates[group], f"{fish_scenes[group].name}_{i:05d}")
        size = float(tracks.scale[i])
        x, y, z = (float(v) for v in tracks.positions[0, i])
        qx, qy, qz, qw = (float(v) for v in tracks.headings[0, i])
        for m in made.movers:
            school.nodes[m] = replace(school.nodes[m], translation=(x, y, z), rotation=(qx, qy, qz, qw),
                                      scale=(size, size, size))
        k = position_keys[i]
        move = Sampler(times32[k], tracks.positions[k, i].astype(np.float32))
        k = rotation_keys[i]
        turn = Sampler(times32[k], tracks.headings[k, i].astype(np.float32))
        for m in made.movers:
            channels += [Channel(m, "translation", move), Channel(m, "rotation", turn)]
        phase = int(rng.integers(FIN_PHASES))
        weights = (None if weights_all is None
                   else Sampler(times32, pad_weights(weights_all[i], templates[group].targets)))
        swings = dict(made.fins)
        swim = fish_scenes[group].clip("swim")
        for node in sorted(set(made.waving) | set(swings)):
            if node in made.waving and weights is not None:
                channels.append(Channel(node, "weights", weights))
            if node in swings and swim is not None and duration > 0:
                key = (int(group), id(swings[node]), phase)
                if key not in fin_samplers:
                    t, v = _fin_keys(swings[node], swim.duration * phase / FIN_PHASES, duration)
                    fin_samplers[key] = Sampler(t.astype(np.float32), v.astype(np.float32))
                channels.append(Channel(node, "rotation", fin_samplers[key]))
    if duration > 0:
        school.clips.append(Clip("school", channels))
    return school


@dataclass
class _Keys:
    """What both bakes key every fish from."""

    times32: np.ndarray
    duration: float
    rng: np.random.Generator          # after the wave phases' draws: the fin phases come next
    positions: list[np.ndarray]       # per fish, the frames its translation keeps
    rotations: list[np.ndarray]       # per fish, the frames its rotation keeps
    weights: np.ndarray | None        # (fish, frames, 4) wave weights, or None without a wave


def _school_keys(fish_scenes: list[Scene], tracks: Tracks, tolerance: float, seed: int,
                 body_lengths: np.ndarray | None, wave: BodyWave | None) -> _Keys:
    times = np.asarray(tracks.times, np.float64)
    duration = float(times[-1]) if len(times) else 0.0
    rng = np.random.default_rng(seed)
    # A rotation error of e radians moves a point one body length away by about e body lengths.
    reach = np.ones(len(tracks.group)) if body_lengths is None else np.asarray(body_lengths, np.float64)
    position_keys = reduce_keys(tracks.positions, tolerance)
    rotation_keys = reduce_keys(tracks.headings * reach[None, :, None], tolerance)
    phases = _wave_phases(fish_scenes, tracks, reach, rng, wave or BodyWave())
    # every fish's four target weights at once, fish-major: one contiguous (F, 4) block per fish
    weights = (None if phases is None or duration <= 0
               else wave_weights(np.ascontiguousarray(phases.T)).astype(np.float32))
    return _Keys(times.astype(np.float32), duration, rng, position_keys, rotation_keys, weights)


def bake_prototypes(fish_scenes: list[Scene], tracks: Tracks, *, prototypes: int = 4, seed: int = 0,
                    fps: float = 30.0, tints: int = 1, tint: float = 0.15) -> Scene:
    """The school as one :class:`Instancer`: ``prototypes`` copies of each species' fish (of each of
    its ``tints`` colour variants, as :func:`bake` tints them and its fish wear them) whose swim
    clips run phase-shifted (by 1/``prototypes`` of a loop each) over the whole run, and every fish
    one of its species' prototypes, seeded, placed every frame by its tracks; only the prototypes
    some fish is are kept. Fish of one prototype share one pose: the tail beats at the species' own
    speed, not the fish's (:func:`bake`'s)."""
    times = np.asarray(tracks.times, np.float64)
    duration = float(times[-1]) if len(times) else 0.0
    factors = _tint_factors(len(fish_scenes), tints, tint, seed)
    phase = np.random.default_rng((seed, PROTOTYPE_STREAM)).integers(0, prototypes, len(tracks.group))
    variant = _wears(len(tracks.group), tints, seed)
    index = (np.asarray(tracks.group, np.int64) * max(1, tints) + variant) * prototypes + phase
    # Only the prototypes some fish is: a small school with many tints would otherwise carry
    # meshes and materials nobody shows (the validator's "unused" notices, and their bytes).
    used, index = np.unique(index, return_inverse=True)
    protos = []
    for key in used.tolist():
        g, p = divmod(key, prototypes)
        g, v = divmod(g, max(1, tints))
        fish = fish_scenes[g]
        protos.append(_phase_shifted(_tinted(fish, factors[g][v], v),
                                     f"{fish.name}{f'_tint{v}' if v else ''}_{p}", p / prototypes, duration))
    crowd = Instancer("fish", protos, index, times, np.asarray(tracks.positions, np.float32),
                      np.asarray(tracks.headings, np.float32), np.asarray(tracks.scale, np.float32))
    return Scene(name="school", instancers=[crowd], fps=fps)


def _tinted(fish: Scene, factor: np.ndarray, variant: int) -> Scene:
    """``fish`` with every material's base colour multiplied by ``factor`` (variant 0: as it is)."""
    if variant == 0:
        return fish
    return replace(fish, materials=[_tint(m, factor, variant) for m in fish.materials])


def _phase_shifted(fish: Scene, name: str, share: float, duration: float) -> Scene:
    """``fish`` whose swim clip starts ``share`` of a loop in and runs for ``duration`` seconds;
    channels that shared a sampler still share one."""
    swim = fish.clip("swim")
    if swim is None or duration <= 0:
        return replace(fish, name=name, clips=[])
    shifted: dict[int, Sampler] = {}
    channels = []
    for channel in swim.channels:
        if id(channel.sampler) not in shifted:
            t, v = _fin_keys(channel, swim.duration * share, duration)
            shifted[id(channel.sampler)] = Sampler(t.astype(np.float32), v.astype(np.float32))
        channels.append(Channel(channel.node, channel.path, shifted[id(channel.sampler)]))
    return replace(fish, name=name, clips=[Clip("swim", channels)])
