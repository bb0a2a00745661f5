"""Build a game-ready fish from a species: a scene of parts in glTF axes and metres,
materials, textures and the looping ``swim`` clip.

The scene has one root node named after the species and one child node per
part, each with its own mesh; moving fins carry their pivot as the node
translation and swing about their hinge in the ``swim`` clip. With the body
wave (the default), every mesh also carries four morph targets and the clip
drives their weights (:mod:`fishgen.assembly.body_wave`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fishgen.assembly.animation import MAX_CLIP_FRAMES, FinMotion, axis_rotation_quaternions, clip_frames
from fishgen.assembly.body_wave import (
    add_wave_targets,
    loop_beats,
    loop_keys,
    loop_laps,
    wave_channels,
    weight_sampler,
)
from fishgen.assembly.fin_modes import FIN_MODES
from fishgen.assembly.fins import build_fins
from fishgen.assembly.materials import default_fin_mode, load_textures, make_materials
from fishgen.assembly.swim_modes import DEFAULT_SPEED, SWIM_MODES
from fishgen.errors import FishgenError
from fishgen.geometry.body import build_body
from fishgen.geometry.body_wave import BodyWave, check_wave
from fishgen.geometry.mesh import vertex_normals
from fishgen.geometry.shapes import profile_for
from fishgen.scene.model import Channel, Clip, Image, Mesh, Node, Primitive, Sampler, Scene
from fishgen.species.model import Species

#: One VRFish world unit in metres (docs/decisions.md): BonyBream's world scale
#: 25.5 x scaleX 0.26 then gives a 0.33 m body, a typical adult bony bream.
METRES_PER_WORLD_UNIT = 0.05

#: Thesis axes (x nose->tail, y up, z left) to glTF (+Y up, head towards +Z, left = +X).
THESIS_TO_GLTF = np.array([[0.0, 0.0, 1.0],
                           [0.0, 1.0, 0.0],
                           [-1.0, 0.0, 0.0]])


@dataclass(frozen=True)
class FishFacts:
    """What the builder knows about the fish it built, so that nobody measures it again."""

    name: str
    body_length: float           # nose to tail-fin tip in metres, at rest (the scene's extent along Z)
    fin_mode: str                # blend | mask | opaque
    swim: str                    # body | fins
    fps: float
    speed: float                 # cruising speed of the swim loop, body lengths per second
    tail_beat_hz: float | None   # the body wave's frequency; None without a body wave
    clip_seconds: float | None   # the swim loop's length; None when nothing moves


@dataclass(frozen=True)
class Fish:
    scene: Scene
    facts: FishFacts


def build_fish(species: Species, *, fins: str | None = None, length: float | None = None,
               fps: float = 30.0, swim: str = "body", speed: float = DEFAULT_SPEED,
               wave: BodyWave | None = None) -> Scene:
    """The scene of :func:`make_fish` (the library's one-line way to a fish)."""
    return make_fish(species, fins=fins, length=length, fps=fps, swim=swim, speed=speed, wave=wave).scene


def make_fish(species: Species, *, fins: str | None = None, length: float | None = None,
              fps: float = 30.0, swim: str = "body", speed: float = DEFAULT_SPEED,
              wave: BodyWave | None = None) -> Fish:
    """Build the fish of ``species``, and say what was built.

    ``fins``: ``blend``, ``mask`` or ``opaque`` (default: ``mask`` when the file
    says masked and the fish is textured, else ``blend``). ``length``: nose-to-tail
    length in metres (default: world scale x scaleX x 0.05 m per world unit for the
    body). ``fps``: frame rate the fins' step sizes are counted in. ``swim``: one
    of SWIM_MODES. ``speed``: body lengths per second, which sets the tail-beat
    frequency of the body wave (``wave``, default :class:`BodyWave`).
    """
    mode = fins or default_fin_mode(species)
    if mode not in FIN_MODES:
        raise FishgenError(f"expected a fin mode ({', '.join(FIN_MODES)}), found {mode!r}")
    if mode == "mask" and not species.textured:
        raise FishgenError("expected a textured species for --fins mask (the mask is a texture), "
                           "found textured false", species.source, species.line_of("shape"))
    if not 1 <= fps <= 1000:
        raise FishgenError(f"expected --fps from 1 to 1000, found {fps}")
    if length is not None and not 0.001 <= length <= 1e4:
        raise FishgenError(f"expected --length in metres from 0.001 to 10000, found {length}")
    if swim not in SWIM_MODES:
        raise FishgenError(f"expected a swim mode ({', '.join(SWIM_MODES)}), found {swim!r}")
    if not 0.01 <= speed <= 100:
        raise FishgenError(f"expected --speed in body lengths per second from 0.01 to 100, found {speed}")
    wave = wave or BodyWave()
    try:
        check_wave(wave)
    except ValueError as err:
        raise FishgenError(str(err)) from None

    tp = species.texture_points
    body_uv = None
    if tp is not None:
        body_uv = np.asarray(tp.body, dtype=np.float64).reshape(
            species.body_sections, species.circle_sections, 2)
    body = build_body(profile_for(species.shape_class, species.shape_params), species.body_sections,
                      species.circle_sections, species.scale, body_uv)
    fin_list = build_fins(species, body.rings)

    # Scaled thesis space -> glTF axes in metres, centred on the body's middle.
    nose_to_tail = max(float(body.mesh.positions[:, 0].max()),
                       *(float(f.mesh.positions[:, 0].max()) for f in fin_list))
    foremost = min(float(body.mesh.positions[:, 0].min()),
                   *(float(f.mesh.positions[:, 0].min()) for f in fin_list))
    metres = (length / nose_to_tail) if length is not None else (
        species.world_scale * METRES_PER_WORLD_UNIT)
    centre = np.array([0.5 * species.scale[0], 0.0, 0.0])

    def place(points: np.ndarray) -> np.ndarray:
        return (points - centre) @ THESIS_TO_GLTF.T * metres

    scene = Scene(name=species.name)
    root = scene.add_node(Node(name=species.name))
    skin = load_textures(species, mode)
    texture = scene.add_image(Image("skin", skin["skin"])) if "skin" in skin else None
    body_material, fin_material = (scene.add_material(m) for m in make_materials(species, mode, texture))

    def add_part(name: str, positions: np.ndarray, faces: np.ndarray, uvs: np.ndarray, material: int,
                 pivot: np.ndarray) -> int:
        attributes = {"POSITION": positions.astype(np.float32),
                      "NORMAL": vertex_normals(positions, faces).astype(np.float32)}
        if texture is not None:
            attributes["TEXCOORD_0"] = uvs.astype(np.float32)
        mesh = scene.add_mesh(Mesh(name, [Primitive(attributes, faces.astype(np.uint32), material)]))
        x, y, z = (float(v) for v in pivot)
        return scene.add_node(Node(name=name, mesh=mesh, translation=(x, y, z)),
                              parent=root)

    add_part("body", place(body.mesh.positions), body.mesh.faces, body.mesh.uvs, body_material, np.zeros(3))
    motions: list[tuple[int, str, FinMotion, np.ndarray | None]] = []
    for fin in fin_list:
        try:
            motion = FinMotion.from_fin(fin.movement_angle, fin.step_size,
                                        -1.0 if fin.mirror_of else 1.0) if fin.pivot is not None else None
        except ValueError as err:  # a subnormal step size would loop for days
            raise FishgenError(f"expected a fin cycle (4 x movement angle / step size) of at most "
                               f"{MAX_CLIP_FRAMES} frames, found {err} (movement angle "
                               f"{fin.movement_angle:g}, step size {fin.step_size:g})", species.source,
                               species.line_of(fin.name.split("_")[0])) from None
        if swim == "body" and fin.name == "caudal_fin":
            # The wave sweeps the tail fin with the tail's displacement and slope (about 38 degrees of
            # yaw at the tip, against the thesis' 10-degree swing); a swing on top would turn the
            # fin's share of the wave with it and tear the fin off the tail (docs/decisions.md).
            motion = None
        pivot = place(fin.pivot[None, :])[0] if motion is not None and fin.pivot is not None else np.zeros(3)
        node = add_part(fin.name, place(fin.mesh.positions) - pivot, fin.mesh.faces, fin.mesh.uvs,
                        fin_material, pivot)
        if motion is not None:
            axis = None if fin.axis is None else THESIS_TO_GLTF @ fin.axis
            motions.append((node, fin.name, motion, axis))

    frames = clip_frames([m for _, _, m, _ in motions])
    if frames > MAX_CLIP_FRAMES:
        _, slowest, _, _ = max(motions, key=lambda nm: nm[2].period_frames)
        raise FishgenError(f"expected fin cycles that loop within {MAX_CLIP_FRAMES} frames, found "
                           f"{frames} (periods {sorted({m.period_frames for _, _, m, _ in motions})}); "
                           "choose movement angles and step sizes with a small common multiple",
                           species.source, species.line_of(slowest.split("_")[0]))
    if swim == "body" and frames:
        frames *= loop_laps(wave, speed, frames / fps, MAX_CLIP_FRAMES // frames)
    channels: list[Channel] = []
    for node, _, motion, axis in motions:
        keys, angles = motion.keys(frames)
        quaternions = axis_rotation_quaternions(angles, axis).astype(np.float32)
        channels.append(Channel(node, "rotation", Sampler((keys / fps).astype(np.float32), quaternions)))
    frequency = None
    if swim == "body":
        waved, frequency = _body_wave(scene, wave, speed, frames / fps if frames else None)
        channels += waved
    if channels:
        scene.clips.append(Clip("swim", channels))
    clip = scene.clip("swim")
    facts = FishFacts(species.name, (nose_to_tail - foremost) * metres, mode, swim, float(fps), float(speed),
                      frequency, clip.duration if clip is not None else None)
    return Fish(scene, facts)


def _body_wave(scene: Scene, wave: BodyWave, speed: float,
               clip_seconds: float | None) -> tuple[list[Channel], float | None]:
    """Wave targets on every part and the weights channels of a seamless loop (a whole number of
    beats in the fins' loop, or one beat when no fin moves), and the tail-beat frequency."""
    if not add_wave_targets(scene, wave):
        return [], None
    seconds = clip_seconds if clip_seconds else 1.0 / float(wave.frequency(speed))
    beats, frequency = loop_beats(wave, speed, seconds)
    return wave_channels(scene, weight_sampler(*loop_keys(beats, frequency))), float(frequency)


def species_scene(path, *, textures_dir=None) -> Scene:
    """The fish a species file builds with default options (the registry's species reader)."""
    from fishgen.species.parser import load_species

    return build_fish(load_species(path, textures_dir=textures_dir))
