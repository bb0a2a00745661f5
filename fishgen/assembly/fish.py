"""Build a game-ready fish from a species: a scene of parts in glTF axes and metres,
materials, textures and the looping ``swim`` clip.

The scene has one root node named after the species and one child node per
part, each with its own mesh; moving fins carry their pivot as the node
translation and swing about +Y in the ``swim`` clip.
"""
from __future__ import annotations

import numpy as np

from fishgen.assembly.animation import MAX_CLIP_FRAMES, FinMotion, clip_frames, y_rotation_quaternions
from fishgen.assembly.fin_modes import FIN_MODES
from fishgen.assembly.fins import build_fins
from fishgen.assembly.materials import default_fin_mode, load_textures, make_materials
from fishgen.errors import FishgenError
from fishgen.geometry.body import build_body
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


def build_fish(species: Species, *, fins: str | None = None, length: float | None = None,
               fps: float = 30.0) -> Scene:
    """Build the fish of ``species``.

    ``fins``: ``blend``, ``mask`` or ``opaque`` (default: ``mask`` when the file
    says masked and the fish is textured, else ``blend``). ``length``: nose-to-tail
    length in metres (default: world scale x scaleX x 0.05 m per world unit for the
    body). ``fps``: frame rate the fins' step sizes are counted in.
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
    metres = (length / nose_to_tail) if length is not None else (
        species.world_scale * METRES_PER_WORLD_UNIT)
    centre = np.array([0.5 * species.scale[0], 0.0, 0.0])

    def place(points: np.ndarray) -> np.ndarray:
        return (points - centre) @ THESIS_TO_GLTF.T * metres

    scene = Scene(name=species.name, info={"fin_mode": mode, "kind": "fish"})
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
    motions: list[tuple[int, str, FinMotion]] = []
    for fin in fin_list:
        try:
            motion = FinMotion.from_fin(fin.movement_angle, fin.step_size,
                                        -1.0 if fin.mirror_of else 1.0) if fin.pivot is not None else None
        except ValueError as err:  # a subnormal step size would loop for days
            raise FishgenError(f"expected a fin cycle (4 x movement angle / step size) of at most "
                               f"{MAX_CLIP_FRAMES} frames, found {err} (movement angle "
                               f"{fin.movement_angle:g}, step size {fin.step_size:g})", species.source,
                               species.line_of(fin.name.split("_")[0])) from None
        pivot = place(fin.pivot[None, :])[0] if motion is not None and fin.pivot is not None else np.zeros(3)
        node = add_part(fin.name, place(fin.mesh.positions) - pivot, fin.mesh.faces, fin.mesh.uvs,
                        fin_material, pivot)
        if motion is not None:
            motions.append((node, fin.name, motion))

    frames = clip_frames([m for _, _, m in motions])
    if frames > MAX_CLIP_FRAMES:
        _, slowest, _ = max(motions, key=lambda nm: nm[2].period_frames)
        raise FishgenError(f"expected fin cycles that loop within {MAX_CLIP_FRAMES} frames, found "
                           f"{frames} (periods {sorted({m.period_frames for _, _, m in motions})}); "
                           "choose movement angles and step sizes with a small common multiple",
                           species.source, species.line_of(slowest.split("_")[0]))
    if motions:
        channels = []
        for node, _, motion in motions:
            keys, angles = motion.keys(frames)
            channels.append(Channel(node, "rotation", Sampler((keys / fps).astype(np.float32),
                                                              y_rotation_quaternions(angles).astype(np.float32))))
        scene.clips.append(Clip("swim", channels))
    scene.info["fps"] = float(fps)
    return scene


def species_scene(path, *, textures_dir=None, **_) -> Scene:
    """The fish a species file builds with default options (the registry's species reader)."""
    from fishgen.species.parser import load_species

    return build_fish(load_species(path, textures_dir=textures_dir))
