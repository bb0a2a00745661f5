"""Photograph fishgen fish in Blender (Cycles): run by a Python with PyPI's `bpy`, one job per line.

    /tmp/bpyvenv/bin/python tests/authoring/blender_photo_bpy.py JOBS.json

JOBS.json is a list of jobs made by tests/authoring/blender_photo.py: ``glb`` (the fish), ``camera``
(eye, target, up in glTF axes, metres; ``lens`` and ``sensor`` in mm, ``width`` x ``height`` px),
``sun`` (towards the sun, glTF axes), ``backdrop`` (none, or a plane's centre, normal and size),
``floor`` (none, or its height), ``photo`` (a PNG to write, or none) and ``mask`` (the PNG of the
fish's exact coverage from the same camera: of every triangle, or with ``alpha`` of what the file
shows, its materials' alpha kept). Prints one JSON line per job when it is written.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "assembly" / "engine"))


def _b(v):
    """glTF axes (+Y up, +Z forward) to Blender's (+Z up, -Y forward)."""
    from mathutils import Vector

    return Vector((v[0], -v[2], v[1]))


def _look(ob, eye, target, up) -> None:
    """Place ``ob`` at ``eye`` looking at ``target`` (its -Z) with ``up`` as its +Y."""
    from mathutils import Matrix

    f = (_b(target) - _b(eye)).normalized()
    r = f.cross(_b(up)).normalized()
    u = r.cross(f)
    m = Matrix((r, u, -f)).transposed().to_4x4()
    m.translation = _b(eye)
    ob.matrix_world = m


def _material(name: str, kind: str, seed: int):
    """A procedural backdrop (murky water: a vertical gradient and noise) or floor (sand)."""
    import bpy

    mat = bpy.data.materials.new(name)
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes.get("Principled BSDF")
    noise = nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 3.0 if kind == "water" else 40.0
    noise.inputs["Detail"].default_value = 6.0
    noise.noise_dimensions = "4D"
    noise.inputs["W"].default_value = float(seed)
    ramp = nodes.new("ShaderNodeValToRGB")
    low, high = ((0.05, 0.22, 0.30, 1), (0.25, 0.55, 0.62, 1)) if kind == "water" else \
        ((0.55, 0.47, 0.33, 1), (0.85, 0.78, 0.62, 1))
    ramp.color_ramp.elements[0].color, ramp.color_ramp.elements[1].color = low, high
    links.new(noise.outputs["Fac"], ramp.inputs["Fac"])
    links.new(ramp.outputs["Color"], bsdf.inputs["Base Color"])
    bsdf.inputs["Roughness"].default_value = 0.9
    return mat


def _plane(name: str, centre, normal, size: float, mat):
    import bpy
    from mathutils import Vector

    bpy.ops.mesh.primitive_plane_add(size=size)
    ob = bpy.context.active_object
    ob.name = name
    n = _b(normal).normalized()
    ob.rotation_euler = Vector((0, 0, 1)).rotation_difference(n).to_euler()
    ob.location = _b(centre)
    ob.data.materials.append(mat)
    return ob


def _flat_keeping_alpha(mat) -> None:
    """``mat`` made one opaque emission wherever its surface is drawn: the alpha the glTF importer
    wired into its Principled BSDF (a masked fin's clipped texture alpha, a blended one's) still
    decides where, so the coverage is what the file shows, not every triangle it holds."""
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
    output = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")
    emit, clear, mix = (nodes.new(kind) for kind in ("ShaderNodeEmission", "ShaderNodeBsdfTransparent",
                                                      "ShaderNodeMixShader"))
    alpha = bsdf.inputs["Alpha"]
    if alpha.links:
        links.new(alpha.links[0].from_socket, mix.inputs["Fac"])
    else:
        mix.inputs["Fac"].default_value = alpha.default_value
    links.new(clear.outputs["BSDF"], mix.inputs[1])
    links.new(emit.outputs["Emission"], mix.inputs[2])
    links.new(mix.outputs["Shader"], output.inputs["Surface"])


def shoot(job: dict) -> dict:
    import bpy
    from blender_engine import _rest

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=job["glb"])
    _rest()
    scene = bpy.context.scene
    fish = [ob for ob in scene.objects if ob.type == "MESH"]
    cam = job["camera"]
    data = bpy.data.cameras.new("camera")
    data.lens, data.sensor_width, data.sensor_fit = cam["lens"], cam["sensor"], "HORIZONTAL"
    data.clip_start, data.clip_end = 0.01, 1000.0
    camera = bpy.data.objects.new("camera", data)
    scene.collection.objects.link(camera)
    _look(camera, cam["eye"], cam["target"], cam["up"])
    scene.camera = camera
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy, sun.data.angle = 3.5, 0.12          # soft shadows
    scene.collection.objects.link(sun)
    _look(sun, [0.0, 0.0, 0.0], [-c for c in job["sun"]], [0.0, 0.0, 1.0] if abs(job["sun"][1]) > 0.9
          else [0.0, 1.0, 0.0])
    world = bpy.data.worlds.new("world")
    scene.world = world
    bg = world.node_tree.nodes.get("Background")
    bg.inputs["Color"].default_value = (0.45, 0.6, 0.7, 1.0)
    bg.inputs["Strength"].default_value = 0.8
    others = []
    if job.get("backdrop"):
        b = job["backdrop"]
        water = _material("water", "water", job["seed"])
        others.append(_plane("backdrop", b["centre"], b["normal"], b["size"], water))
    if job.get("floor") is not None:
        f = job["floor"]
        sand = _material("sand", "sand", job["seed"])
        others.append(_plane("floor", [cam["target"][0], f, cam["target"][2]], [0, 1, 0],
                             40 * abs(cam["eye"][0] - cam["target"][0]) + 10, sand))
    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = cam["width"], cam["height"], 100
    r.image_settings.file_format, r.image_settings.color_mode = "PNG", "RGBA"
    r.threads_mode, r.threads = "FIXED", 2
    scene.cycles.device = "CPU"
    scene.cycles.seed = job["seed"]
    if job.get("photo"):
        scene.cycles.samples = 16
        scene.cycles.use_denoising = True
        r.film_transparent = not others
        r.filepath = job["photo"]
        bpy.ops.render.render(write_still=True)
    # The mask: the fish alone, every surface one opaque emission, coverage as alpha.
    for ob in others:
        ob.hide_render = True
    if job.get("alpha"):
        for mat in {slot.material for ob in fish for slot in ob.material_slots if slot.material}:
            _flat_keeping_alpha(mat)
    else:
        flat = bpy.data.materials.new("flat")
        emit = flat.node_tree.nodes.new("ShaderNodeEmission")
        output = flat.node_tree.nodes["Material Output"]
        flat.node_tree.links.new(emit.outputs["Emission"], output.inputs["Surface"])
        scene.view_layers[0].material_override = flat
    scene.cycles.samples = 16
    scene.cycles.use_denoising = False
    scene.cycles.pixel_filter_type, scene.cycles.filter_width = "BOX", 1.0
    r.film_transparent = True
    r.filepath = job["mask"]
    bpy.ops.render.render(write_still=True)
    return {"mask": job["mask"], "photo": job.get("photo"), "objects": len(fish),
            "blender": bpy.app.version_string}


if __name__ == "__main__":
    for job in json.loads(Path(sys.argv[1]).read_text()):
        print(json.dumps(shoot(job)), flush=True)
