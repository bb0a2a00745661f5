"""Import fishgen cloud glbs with Blender's Python module (`bpy`) and print how each material is
wired, as JSON; with --render, also render them with Cycles from the front, the side and above.

Run with a Python that has `bpy` (PyPI's wheel: Python 3.11 only; keep it in its own venv):

    /tmp/bpyvenv/bin/python tests/clouds/blender_clouds.py FILE.glb [...] [--render OUT_PREFIX]

tests/clouds/test_blender.py runs it when such a Python is found ($FISHGEN_BPY_PYTHON or
/tmp/bpyvenv/bin/python). Blender is Z up: glTF's +Y (up) arrives as +Z, its +Z (front) as -Y.
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path


def _upstream(node, seen=None) -> set[str]:
    """Types of every node feeding ``node``."""
    seen = set() if seen is None else seen
    for socket in node.inputs:
        for link in socket.links:
            if link.from_node.name not in seen:
                seen.add(link.from_node.name)
                _upstream(link.from_node, seen)
    return {node.id_data.nodes[name].type for name in seen}


def inspect(path: Path) -> dict:
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=str(path))
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    out: dict = {"file": path.name, "blender": bpy.app.version_string,
                 "triangles": sum(len(o.data.polygons) for o in meshes),
                 "color_attributes": sorted({c.name for o in meshes for c in o.data.color_attributes}),
                 "attributes": sorted({a.name for o in meshes for a in o.data.attributes}),
                 "scene_extras": sorted(bpy.context.scene.keys()), "materials": []}
    for m in bpy.data.materials:
        tree = m.node_tree
        output = next(n for n in tree.nodes if n.type == "OUTPUT_MATERIAL")
        feeding = _upstream(output)
        alpha_from = set()
        for link in tree.links:
            if link.from_socket.name == "Alpha":
                alpha_from.add(link.from_node.type)
        out["materials"].append({
            "name": m.name, "render_method": getattr(m, "surface_render_method", None),
            "blend_method": getattr(m, "blend_method", None),
            "uses_vertex_colour": "VERTEX_COLOR" in feeding, "uses_image": "TEX_IMAGE" in feeding,
            "alpha_from": sorted(alpha_from), "transparent": "BSDF_TRANSPARENT" in feeding,
            "unlit": "EMISSION" in feeding or "BACKGROUND" in feeding,
            "images": sorted(n.image.name for n in tree.nodes if n.type == "TEX_IMAGE" and n.image)})
    return out


def render(path: Path, prefix: str) -> list[str]:
    """Cycles renders from the front, the side and above. Cycles stops a ray after 8 transparent
    surfaces by default; a cloud is hundreds deep, so the limit is raised (a user must too)."""
    import bpy
    from mathutils import Vector

    inspect(path)
    scene = bpy.context.scene
    points = [o.matrix_world @ v.co for o in scene.objects if o.type == "MESH" for v in o.data.vertices]
    lo = Vector([min(p[i] for p in points) for i in range(3)])
    hi = Vector([max(p[i] for p in points) for i in range(3)])
    centre, radius = (lo + hi) / 2, (hi - lo).length / 2
    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs[0].default_value = (0.25, 0.42, 0.6, 1)
    scene.world = world
    scene.render.engine = "CYCLES"
    scene.cycles.device, scene.cycles.samples = "CPU", 16
    scene.cycles.transparent_max_bounces = scene.cycles.max_bounces = 1024
    scene.render.resolution_x, scene.render.resolution_y = 320, 240
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.angle = math.radians(30)
    scene.collection.objects.link(camera)
    scene.camera = camera
    written = []
    for name, direction, up in (("front", (0, -1, 0), "Z"), ("side", (1, 0, 0), "Z"),
                                ("above", (0, 0, 1), "Y")):
        d = Vector(direction)
        camera.location = centre + d * radius * 1.05 / math.tan(math.radians(15))
        camera.rotation_euler = (-d).to_track_quat("-Z", up).to_euler()
        scene.render.filepath = f"{prefix}_{name}.png"
        bpy.ops.render.render(write_still=True)
        written.append(scene.render.filepath)
    return written


def main(argv: list[str]) -> int:
    prefix = None
    if "--render" in argv:
        k = argv.index("--render")
        prefix, argv = argv[k + 1], argv[:k] + argv[k + 2:]
    for arg in argv:
        print(json.dumps(inspect(Path(arg).resolve())), flush=True)
        if prefix:
            print(json.dumps({"rendered": render(Path(arg).resolve(), f"{prefix}{Path(arg).stem}")}),
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
