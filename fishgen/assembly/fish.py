"""Build a game-ready fish from a species: a scene in glTF axes and metres, materials, textures
and its clips.

Two layouts (docs/decisions.md, "Fish for game engines"):

- **parts** (the default): one root node named after the species and one child node per part,
  each with its own mesh; moving fins carry their pivot as the node translation and swing about
  their hinge.
- **merged** (``merge=True``): one mesh of at most two primitives (the opaque body, the fins with
  their alpha mode), skinned: a root joint named after the species carries the body, and each
  moving fin has a joint at its pivot. The mesh node stands at the scene's root (a skinned mesh
  ignores its own node's transform); moving the root joint moves the fish.

With the body wave (the default) every mesh carries the wave's four morph targets, and the bend
targets its clips need (:mod:`fishgen.assembly.clips`), each with POSITION and NORMAL deltas. With
several levels of detail the finest level is the one a scene shows; it names the coarser ones
(MSFT_lod), which stand in a second glTF scene that clients without levels of detail do not show.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from fishgen.assembly.animation import MAX_CLIP_FRAMES, FinMotion, axis_rotation_quaternions, clip_frames
from fishgen.assembly.body_wave import loop_beats, loop_laps
from fishgen.assembly.clip_names import DEFAULT_CLIPS
from fishgen.assembly.clips import (
    C_START_DEGREES,
    TURN_DEGREES,
    ClipPlan,
    FinSwing,
    burst_plan,
    idle_plan,
    sprint_plan,
    swim_plan,
    targets_for,
    wave_loop,
)
from fishgen.assembly.fins import build_fins
from fishgen.assembly.fish_options import FishOptions
from fishgen.assembly.levels import at_level
from fishgen.assembly.materials import default_fin_mode, load_textures, make_materials
from fishgen.errors import FishgenError
from fishgen.fish_modes import DEFAULT_SPEED
from fishgen.geometry.bend import arc_offsets
from fishgen.geometry.body import build_body
from fishgen.geometry.body_wave import BodyWave, check_wave, wave_targets
from fishgen.geometry.fins import Fin
from fishgen.geometry.mesh import normal_deltas, vertex_normals
from fishgen.geometry.shapes import profile_for
from fishgen.scene.model import Channel, Clip, Image, Mesh, Node, Primitive, Sampler, Scene, Skin
from fishgen.species.model import METRES_PER_WORLD_UNIT, Species

#: Thesis axes (x nose->tail, y up, z left) to glTF (+Y up, head towards +Z, left = +X).
THESIS_TO_GLTF = np.array([[0.0, 0.0, 1.0],
                           [0.0, 1.0, 0.0],
                           [-1.0, 0.0, 0.0]])

SCREEN_PIXELS = 1080
"""Switch points are set for a screen this many pixels tall: a level takes over where the coarser
level's error would show as one pixel."""
LAST_COVERAGE = 2.0 / SCREEN_PIXELS
"""The coarsest level is drawn down to a fish two pixels long, then nothing (MSFT_screencoverage)."""


@dataclass(frozen=True)
class LevelFacts:
    bodies: int
    circles: int
    triangles: int
    vertices: int
    coverage: float              # screen coverage (fish length / screen height) down to which it shows
    missing: tuple[str, ...] = ()  # fins the file's own level has and this one lost (too few sections)


@dataclass(frozen=True)
class ClipFacts:
    name: str
    seconds: float
    loop: bool
    tail_beat_hz: float | None   # the body wave's (or a rigid tail fin's) frequency
    bend_degrees: float          # a turn's steady bend, a burst's peak C


@dataclass(frozen=True)
class FishFacts:
    """What the builder knows about the fish it built, so that nobody measures it again."""

    name: str
    body_length: float           # nose to tail-fin tip in metres, at rest (the scene's extent along Z)
    fin_mode: str                # blend | mask | opaque
    swim: str                    # body | fins
    fps: float
    speed: float                 # cruising speed of the swim loop, body lengths per second
    tail_beat_hz: float | None   # the swim loop's body-wave frequency; None without a body wave
    clip_seconds: float | None   # the swim loop's length; None when nothing moves
    levels: tuple[LevelFacts, ...] = ()
    clips: tuple[ClipFacts, ...] = ()
    merged: bool = False
    targets: tuple[str, ...] = ()
    draw_calls: int = 0          # primitives a client draws for one fish at its finest level
    capped_hz: float | None = None  # the tail-beat cap, when the speed asked for a faster wave


@dataclass(frozen=True)
class Fish:
    scene: Scene
    facts: FishFacts


@dataclass(frozen=True)
class Part:
    """One part of one level, in the fish's frame (glTF axes, metres, origin mid-body)."""

    name: str
    positions: np.ndarray
    faces: np.ndarray
    uvs: np.ndarray
    fin: bool                          # drawn with the fins' material
    swing: FinSwing | None = None
    pivot: np.ndarray | None = None    # hinge point of a moving fin
    axis: np.ndarray | None = None     # unit hinge axis (None: +Y)


def build_fish(species: Species, *, fins: str | None = None, length: float | None = None,
               fps: float = 30.0, swim: str = "body", speed: float = DEFAULT_SPEED,
               wave: BodyWave | None = None, lods: str | Sequence[tuple[int, int]] | None = None,
               merge: bool = False, clips: str | Sequence[str] = DEFAULT_CLIPS,
               compact: bool = False, still: bool = False) -> Scene:
    """The scene of :func:`make_fish` (the library's one-line way to a fish)."""
    return make_fish(species, fins=fins, length=length, fps=fps, swim=swim, speed=speed, wave=wave,
                     lods=lods, merge=merge, clips=clips, compact=compact, still=still).scene


def make_fish(species: Species, *, fins: str | None = None, length: float | None = None,
              fps: float = 30.0, swim: str = "body", speed: float = DEFAULT_SPEED,
              wave: BodyWave | None = None, lods: str | Sequence[tuple[int, int]] | None = None,
              merge: bool = False, clips: str | Sequence[str] = DEFAULT_CLIPS, compact: bool = False,
              still: bool = False) -> Fish:
    """Build the fish of ``species``, and say what was built.

    ``fins``: ``blend``, ``mask`` or ``opaque`` (default: ``mask`` when the file
    says masked and the fish is textured, else ``blend``). ``length``: nose-to-tail
    length in metres (default: world scale x scaleX x 0.05 m per world unit for the
    body). ``fps``: frame rate the fins' step sizes are counted in. ``swim``: one
    of SWIM_MODES. ``speed``: body lengths per second, which sets the tail-beat
    frequency of the body wave (``wave``, default :class:`BodyWave`). ``lods``: levels of detail,
    (BodySections, CircleSections) from finest to coarsest (default: the file's own level only).
    ``merge``: one skinned mesh of two primitives instead of a node per part. ``clips``: names of
    CLIP_NAMES. ``compact``: rotation and weight keys as normalized 16-bit integers. Each is
    checked as `fishgen build` checks its option (:class:`FishOptions`). ``still``: the fish at rest
    alone, without its clips and morph targets, for a picture of it at rest (the same vertices).
    """
    # a string is the command line's "swim,idle" or "32x24,16x12" (FishOptions converts it as the
    # option does), not its letters
    options = FishOptions(fins=fins, length=length, fps=fps, swim=swim, speed=speed, merge=merge,
                          lods=cast(Any, lods if isinstance(lods, str) else tuple(lods)) if lods else None,
                          clips=cast(Any, clips if isinstance(clips, str) else tuple(clips)), compact=compact)
    return fish_of(species, options, wave, still)


def fish_of(species: Species, options: FishOptions, wave: BodyWave | None = None,
            still: bool = False) -> Fish:
    """The fish of ``species`` built as ``options`` (checked when they were made) say: what
    `fishgen build` runs for each species file (``still``: as :func:`make_fish`)."""
    length, fps, swim = options.length, options.fps, options.swim
    speed = options.speed if options.speed is not None else DEFAULT_SPEED
    merge, clips, compact = options.merge, options.clips, options.compact
    mode = options.fins or default_fin_mode(species)
    if mode == "mask" and not species.textured:
        raise FishgenError("expected a textured species for --fins mask (the mask is a texture), "
                           "found textured false", species.source, species.line_of("shape"))
    levels = options.lods or ((species.body_sections, species.circle_sections),)
    wave = wave or BodyWave()
    try:
        check_wave(wave)
    except ValueError as err:
        raise FishgenError(str(err)) from None

    built = [_level_geometry(species, b, c) for b, c in levels]
    own = (species.body_sections, species.circle_sections)
    file_fins = [f.name for f in (built[levels.index(own)] if own in levels
                                  else _level_geometry(species, *own))[2]]
    body0, fins0 = built[0][1], built[0][2]
    # Scaled thesis space -> glTF axes in metres, centred on the body's middle, set by the finest level.
    xs = [body0.mesh.positions[:, 0], *(f.mesh.positions[:, 0] for f in fins0)]
    nose_to_tail, foremost = max(float(x.max()) for x in xs), min(float(x.min()) for x in xs)
    metres = (length / nose_to_tail) if length is not None else species.world_scale * METRES_PER_WORLD_UNIT
    centre = np.array([0.5 * species.scale[0], 0.0, 0.0])

    def place(points: np.ndarray) -> np.ndarray:
        return (points - centre) @ THESIS_TO_GLTF.T * metres

    swings = _swings(species, fins0, swim, place)
    parts = [_parts(body, fin_list, place, swings) for _, body, fin_list in built]
    fin_loop = _fin_loop_frames(species, list(swings.values()))

    scene = Scene(name=species.name, fps=float(fps))
    skin_pictures = load_textures(species, mode)
    texture = scene.add_image(Image("skin", skin_pictures["skin"])) if "skin" in skin_pictures else None
    materials = tuple(scene.add_material(m) for m in make_materials(species, mode, texture))

    waving = swim == "body"
    # a fit draws a still fish hundreds of times: its morph targets were half of each build
    targets = () if still else targets_for(clips, waving)
    first = parts[0]
    nose = max(float(p.positions[:, 2].max()) for p in first)
    body_length = nose - min(float(p.positions[:, 2].min()) for p in first)
    if not (np.isfinite(body_length) and body_length > 0):
        targets = ()
    plans = [] if still else _plans(clips, targets, list(swings.values()), wave, speed, fps, fin_loop, waving)
    coverage = _coverages(species, levels)
    look = _Look(targets, nose, body_length, wave, materials, texture)
    lay = (_merged if merge else _separate)(scene, species.name, parts, look, coverage)
    for plan in plans:
        channels = _channels(plan, lay, swings)
        if channels:
            scene.clips.append(Clip(plan.name, channels))
    if compact:
        from fishgen.assembly.compact import compact_clips

        compact_clips(scene)

    swim_plan_ = next((p for p in plans if p.name == "swim"), None)
    swim_clip = scene.clip("swim")
    has_swim = swim_plan_ is not None and swim_clip is not None
    level_facts = tuple(LevelFacts(b, c, sum(len(p.faces) for p in level_parts),
                                   sum(len(p.positions) for p in level_parts), cov,
                                   tuple(n for n in file_fins if n not in {f.name for f in fins}))
                        for (b, c), level_parts, cov, (_, _, fins)
                        in zip(levels, parts, coverage, built, strict=True))
    clip_facts = tuple(ClipFacts(p.name, clip.duration, p.loop, p.tail_beat_hz, p.bend_degrees)
                       for p in plans if (clip := scene.clip(p.name)) is not None)
    draw_calls = (len({m for m in (False, True) if any(p.fin == m for p in first)}) if merge
                  else len(first))
    facts = FishFacts(species.name, (nose_to_tail - foremost) * metres, mode, swim, float(fps), float(speed),
                      swim_plan_.tail_beat_hz if has_swim and swim_plan_ is not None else None,
                      swim_clip.duration if has_swim and swim_clip is not None else None,
                      level_facts, clip_facts, merge, targets, draw_calls,
                      wave.max_frequency if has_swim and waving and wave.capped(speed) else None)
    return Fish(scene, facts)


def _fin_loop_frames(species: Species, swings: list[FinSwing]) -> int:
    frames = clip_frames([s.motion for s in swings])
    if frames > MAX_CLIP_FRAMES:
        slowest = max(swings, key=lambda s: s.motion.period_frames)
        raise FishgenError(f"expected fin cycles that loop within {MAX_CLIP_FRAMES} frames, found "
                           f"{frames} (periods {sorted({s.motion.period_frames for s in swings})}); "
                           "choose movement angles and step sizes with a small common multiple",
                           species.source, species.line_of(slowest.name.split("_")[0]))
    return frames


# -- geometry of each level -------------------------------------------------------------------------

def _level_geometry(species: Species, bodies: int, circles: int):
    level = at_level(species, bodies, circles)
    tp = level.texture_points
    body_uv = None
    if tp is not None:
        body_uv = np.asarray(tp.body, dtype=np.float64).reshape(level.body_sections, level.circle_sections, 2)
    body = build_body(profile_for(level.shape_class, level.shape_params), level.body_sections,
                      level.circle_sections, level.scale, body_uv)
    return level, body, build_fins(level, body.rings)


def _swings(species: Species, fins: list[Fin], swim: str, place) -> dict[str, FinSwing]:
    """The fins that move (their swing from the file), by name, and which way folds each to the body."""
    out = {}
    for fin in fins:
        if fin.pivot is None:
            continue
        try:
            motion = FinMotion.from_fin(fin.movement_angle, fin.step_size, -1.0 if fin.mirror_of else 1.0)
        except ValueError as err:  # a subnormal step size would loop for days
            raise FishgenError(f"expected a fin cycle (4 x movement angle / step size) of at most "
                               f"{MAX_CLIP_FRAMES} frames, found {err} (movement angle "
                               f"{fin.movement_angle:g}, step size {fin.step_size:g})", species.source,
                               species.line_of(fin.name.split("_")[0])) from None
        if motion is None:
            continue
        if swim == "body" and fin.name == "caudal_fin":
            # The wave sweeps the tail fin with the tail's displacement and slope (about 38 degrees of
            # yaw at the tip, against the thesis' 10-degree swing); a swing on top would turn the
            # fin's share of the wave with it and tear the fin off the tail (docs/decisions.md).
            continue
        pivot = place(fin.pivot[None, :])[0]
        axis = None if fin.axis is None else THESIS_TO_GLTF @ fin.axis
        points = place(fin.mesh.positions) - pivot
        spread = []
        for sign in (1.0, -1.0):
            q = axis_rotation_quaternions(np.array([sign * 15.0]), axis)[0]
            spread.append(float(np.abs(pivot[0] + _rotate(q, points)[:, 0]).sum()))
        out[fin.name] = FinSwing(fin.name, motion, 1.0 if spread[0] <= spread[1] else -1.0)
    return out


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    x, y, z, w = q
    u = np.array([x, y, z])
    return v + 2.0 * np.cross(u, np.cross(u, v) + w * v)


def _parts(body, fin_list: list[Fin], place, swings: dict[str, FinSwing]) -> list[Part]:
    parts = [Part("body", place(body.mesh.positions), body.mesh.faces, body.mesh.uvs, False)]
    for fin in fin_list:
        swing = swings.get(fin.name)
        pivot = axis = None
        if swing is not None and fin.pivot is not None:
            pivot = place(fin.pivot[None, :])[0]
            axis = None if fin.axis is None else THESIS_TO_GLTF @ fin.axis
        parts.append(Part(fin.name, place(fin.mesh.positions), fin.mesh.faces, fin.mesh.uvs, True, swing,
                          pivot, axis))
    return parts


def _coverages(species: Species, levels: tuple[tuple[int, int], ...]) -> list[float]:
    """MSFT_screencoverage: per level, the fish's length on screen over the screen's height below
    which the next level takes over (docs/decisions.md)."""
    profile = profile_for(species.shape_class, species.shape_params)
    x = np.linspace(0.0, 1.0, 2049)
    r = np.maximum(profile(x), 0.0)
    half_width = max(species.scale[1], species.scale[2]) * 0.5 / species.scale[0]   # lengths per unit radius

    def error(bodies: int, circles: int) -> float:
        xs = np.arange(bodies) / (bodies - 1)
        along = float(np.abs(r - np.interp(x, xs, np.maximum(profile(xs), 0.0))).max())
        around = float(r.max()) * (1.0 - np.cos(np.pi / circles))
        return 2.0 * half_width * (along + around)

    out, above = [], 1.0
    for k in range(len(levels)):
        if k + 1 < len(levels):
            e = error(*levels[k + 1])
            cover = min(above, 1.0 / (SCREEN_PIXELS * e)) if e > 0 else above
        else:
            cover = min(above, LAST_COVERAGE)
        out.append(float(cover))
        above = cover
    return out


# -- morph targets --------------------------------------------------------------------------------

@dataclass(frozen=True)
class _Look:
    """What every part of every level is made with: its morph targets (and the body axis and wave
    they follow), the body's and fins' materials, and the texture."""

    targets: tuple[str, ...]
    nose: float
    length: float
    wave: BodyWave
    materials: tuple[int, ...]
    texture: int | None


def _displacements(part: Part, look: _Look) -> np.ndarray:
    """(targets, n, 3) metres: each vertex moved as the midline at its own place along the fish."""
    targets, length, wave = look.targets, look.length, look.wave
    x = (look.nose - part.positions[:, 2]) / length
    out = np.zeros((len(targets), len(x), 3))
    for k, name in enumerate(targets):
        if name.startswith("wave_"):
            out[k, :, 0] = wave_targets(x, wave)[k] * length
    turn = np.radians(TURN_DEGREES)
    lateral, axial = arc_offsets(x, turn)
    for name, side in (("bend_left", 1.0), ("bend_right", -1.0)):
        if name in targets:
            k = targets.index(name)
            out[k, :, 0], out[k, :, 2] = side * lateral * length, axial * length
    if "c_start" in targets:
        k = targets.index("c_start")
        c_lateral, c_axial = arc_offsets(x, np.radians(C_START_DEGREES))
        out[k, :, 0], out[k, :, 2] = (c_lateral - lateral) * length, (c_axial - axial) * length
    return out


def _morphs(part: Part, look: _Look) -> list[dict[str, np.ndarray]]:
    if not look.targets:
        return []
    moves = _displacements(part, look)
    normals = normal_deltas(part.positions, part.faces, moves)
    return [{"POSITION": m.astype(np.float32), "NORMAL": n.astype(np.float32)}
            for m, n in zip(moves, normals, strict=True)]


def _attributes(part: Part, origin: np.ndarray, texture: int | None) -> dict[str, np.ndarray]:
    out = {"POSITION": (part.positions - origin).astype(np.float32),
           "NORMAL": vertex_normals(part.positions, part.faces).astype(np.float32)}
    if texture is not None:
        out["TEXCOORD_0"] = part.uvs.astype(np.float32)
    return out


# -- layouts ----------------------------------------------------------------------------------------

@dataclass
class Layout:
    """Where a level's animated things ended up: weights go to ``wave_nodes``, a fin's swing to
    ``fin_nodes[level][name]`` (its node, pivot-relative rotation about ``axes[level][name]``)."""

    wave_nodes: list[list[int]]
    fin_nodes: list[dict[str, int]]
    axes: list[dict[str, np.ndarray | None]]


def _level_name(name: str, level: int, levels: int) -> str:
    return name if levels == 1 or level == 0 else f"{name}_LOD{level}"


def _separate(scene: Scene, name: str, parts: list[list[Part]], look: _Look, coverage: list[float]) -> Layout:
    """A root node per level (``name``, or ``name_LODk``) with a child node and mesh per part."""
    lay = Layout([], [], [])
    roots = []
    count = len(parts)
    for level, level_parts in enumerate(parts):
        root_name = name if count == 1 else f"{name}_LOD{level}"
        root = _add_level_root(scene, Node(name=root_name), level)
        roots.append(root)
        waves, fins, axes = [], {}, {}
        for part in level_parts:
            pivot = part.pivot if part.pivot is not None else np.zeros(3)
            attributes = _attributes(part, pivot, look.texture)
            prim = Primitive(attributes, part.faces.astype(np.uint32), look.materials[1 if part.fin else 0],
                             targets=_morphs(part, look))
            part_name = _level_name(part.name, level, count)
            names = list(look.targets) if prim.targets else []
            mesh = scene.add_mesh(Mesh(part_name, [prim], [0.0] * len(prim.targets), names))
            x, y, z = (float(v) for v in pivot)
            node = scene.add_node(Node(name=part_name, mesh=mesh, translation=(x, y, z)), parent=root)
            if prim.targets:
                waves.append(node)
            if part.swing is not None:
                fins[part.name], axes[part.name] = node, part.axis
        lay.wave_nodes.append(waves)
        lay.fin_nodes.append(fins)
        lay.axes.append(axes)
    scene.add_levels(roots[0], roots[1:], coverage)
    return lay


def _merged(scene: Scene, name: str, parts: list[list[Part]], look: _Look, coverage: list[float]) -> Layout:
    """One skinned mesh per level: a body primitive and a fins primitive; the root joint ``name``
    carries the body and still fins, a joint per moving fin (per level) swings it."""
    lay = Layout([], [], [])
    root = scene.add_node(Node(name=name))
    meshes = []
    count = len(parts)
    for level, level_parts in enumerate(parts):
        joints = [root]
        fins, axes = {}, {}
        for part in level_parts:
            if part.swing is not None and part.pivot is not None:
                x, y, z = (float(v) for v in part.pivot)
                joint = Node(name=_level_name(part.name, level, count), translation=(x, y, z))
                fins[part.name] = scene.add_node(joint, parent=root)
                axes[part.name] = part.axis
                joints.append(fins[part.name])
        ibm = np.tile(np.eye(4), (len(joints), 1, 1))
        for j, node in enumerate(joints[1:], 1):
            ibm[j, :3, 3] = -np.asarray(scene.nodes[node].translation)
        skin = len(scene.skins)
        scene.skins.append(Skin(f"{name}_armature", joints, ibm, skeleton=root))
        prims = []
        for fin_group in (False, True):
            group = [p for p in level_parts if p.fin == fin_group]
            if group:
                material = look.materials[1 if fin_group else 0]
                prims.append(_merged_primitive(group, joints, fins, look, material))
        mesh_name = f"{name}_LOD{level}" if count > 1 else f"{name}_mesh"
        morphed = bool(prims and prims[0].targets)
        mesh = scene.add_mesh(Mesh(mesh_name, prims, [0.0] * len(look.targets) if morphed else [],
                                   list(look.targets) if morphed else []))
        node = _add_level_root(scene, Node(name=mesh_name, mesh=mesh, skin=skin), level)
        meshes.append(node)
        lay.wave_nodes.append([node] if scene.meshes[mesh].weights else [])
        lay.fin_nodes.append(fins)
        lay.axes.append(axes)
    scene.add_levels(meshes[0], meshes[1:], coverage, needs=[root])  # a scene holds a skin's joints
    return lay


def _merged_primitive(group: list[Part], joints: list[int], fins: dict[str, int], look: _Look,
                      material: int) -> Primitive:
    attributes: dict[str, list[np.ndarray]] = {}
    faces, morphs, joint_ids = [], [], []
    offset = 0
    for part in group:
        for key, value in _attributes(part, np.zeros(3), look.texture).items():
            attributes.setdefault(key, []).append(value)
        faces.append(part.faces + offset)
        offset += len(part.positions)
        morphs.append(_morphs(part, look))
        joint = joints.index(fins[part.name]) if part.name in fins else 0
        joint_ids.append(np.full(len(part.positions), joint))
    merged = {key: np.concatenate(values) for key, values in attributes.items()}
    n = len(merged["POSITION"])
    merged["JOINTS_0"] = np.zeros((n, 4), np.uint8)
    merged["JOINTS_0"][:, 0] = np.concatenate(joint_ids)
    merged["WEIGHTS_0"] = np.zeros((n, 4), np.uint8)
    merged["WEIGHTS_0"][:, 0] = 255           # normalized: exactly 1.0 on one joint
    target_list = [{key: np.concatenate([m[k][key] for m in morphs]) for key in ("POSITION", "NORMAL")}
                   for k in range(len(look.targets))] if look.targets else []
    return Primitive(merged, np.concatenate(faces).astype(np.uint32), material, targets=target_list)


def _add_level_root(scene: Scene, node: Node, level: int) -> int:
    """The finest level's node among the scene's roots; a coarser level's in no tree until linked."""
    return scene.add_node(node, root=level == 0)


# -- clips ----------------------------------------------------------------------------------------

def _plans(clips: Sequence[str], targets: Sequence[str], swings: list[FinSwing], wave: BodyWave, speed: float,
           fps: float, fin_loop: int, waving: bool) -> list[ClipPlan]:
    frames = fin_loop
    wave_keys = frequency = None
    if waving and targets:
        if frames:
            frames *= loop_laps(wave, speed, frames / fps, MAX_CLIP_FRAMES // frames)
        seconds = frames / fps if frames else 1.0 / float(wave.frequency(speed))
        beats, frequency = loop_beats(wave, speed, seconds)
        wave_keys = wave_loop(wave, beats, frequency)
    plans = []
    for name in clips:
        if name == "swim":
            plans.append(swim_plan("swim", targets, swings, fps, frames, wave_keys, frequency))
        elif name in ("turn_left", "turn_right"):
            plans.append(swim_plan(name, targets, swings, fps, frames, wave_keys, frequency,
                                   bend="bend_left" if name == "turn_left" else "bend_right"))
        elif name == "idle":
            plans.append(idle_plan(targets, swings))
        elif name == "sprint":
            plans.append(sprint_plan(targets, swings, wave))
        else:
            plans.append(burst_plan(targets, swings, wave))
    return plans


def _channels(plan: ClipPlan, lay: Layout, swings: dict[str, FinSwing]) -> list[Channel]:
    """The plan's keys on every level's nodes: fin swings first, then the weights (one sampler per
    level, shared by its parts, so the file stores it once)."""
    channels: list[Channel] = []
    for level, fins in enumerate(lay.fin_nodes):
        for fin_name, node in fins.items():
            if fin_name not in plan.fins:
                continue
            times, angles = plan.fins[fin_name]
            quaternions = axis_rotation_quaternions(angles, lay.axes[level][fin_name]).astype(np.float32)
            channels.append(Channel(node, "rotation", Sampler(np.asarray(times, np.float32), quaternions)))
    if plan.weights.shape[1]:
        sampler = Sampler(np.asarray(plan.times, np.float32), plan.weights.astype(np.float32))
        for nodes in lay.wave_nodes:
            channels += [Channel(node, "weights", sampler) for node in nodes]
    return channels


def species_scene(path, *, textures_dir=None) -> Scene:
    """The fish a species file builds with default options (the registry's species reader)."""
    from fishgen.species.parser import load_species

    return build_fish(load_species(path, textures_dir=textures_dir))

