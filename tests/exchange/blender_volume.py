"""Import a .vdb with Blender's Python module (`bpy`) and render it; print what arrived, as JSON.

    /tmp/bpyvenv/bin/python tests/exchange/blender_volume.py FILE.vdb ALPHA.npy CX CY WIDTH PIXELS_X PIXELS_Y

Imports FILE.vdb as a volume object (``bpy.ops.object.volume_import``), shades it with a black
Volume Absorption whose density is the ``density`` grid as it is (extinction per unit), and renders
it with Cycles in front of a white world through an orthographic camera looking down -Z (x right,
y up: the cloud's front view) centred on CX, CY and WIDTH wide, with the Standard view transform,
so a pixel's value is the transmittance through the volume. Saves 1 - that (the opacity) as a
(PIXELS_Y, PIXELS_X) float array, top row first, and prints the grids Blender found and the
object's bounds.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path


def main(path: Path, alpha_path: Path, cx: float, cy: float, width: float, px: int, py: int) -> None:
    import bpy
    import numpy as np

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.object.volume_import(filepath=str(path), directory=str(path.parent),
                                 files=[{"name": path.name}])
    obj = next(o for o in bpy.context.scene.objects if o.type == "VOLUME")
    volume = obj.data
    volume.grids.load()
    grids = {g.name: {"type": g.data_type, "class": getattr(g, "grid_class", "")} for g in volume.grids}
    material = bpy.data.materials.new("cloud")
    nodes = material.node_tree.nodes
    nodes.clear()
    grid = nodes.new("ShaderNodeAttribute")
    grid.attribute_name = "density"
    shader = nodes.new("ShaderNodeVolumeAbsorption")
    shader.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    out = nodes.new("ShaderNodeOutputMaterial")
    material.node_tree.links.new(grid.outputs["Fac"], shader.inputs["Density"])
    material.node_tree.links.new(shader.outputs["Volume"], out.inputs["Volume"])
    obj.data.materials.append(material)
    world = bpy.data.worlds.new("white")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0

    scene = bpy.context.scene
    scene.world = world
    scene.view_settings.view_transform = "Standard"
    camera = bpy.data.cameras.new("front")
    camera.type = "ORTHO"
    camera.ortho_scale = width
    camera.clip_end = 10000.0
    cam = bpy.data.objects.new("front", camera)
    scene.collection.objects.link(cam)
    cam.location = (cx, cy, 1000.0)
    scene.camera = cam
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 8
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = px, py
    scene.render.resolution_percentage = 100
    out_png = alpha_path.with_suffix(".exr")
    scene.render.filepath = str(out_png)
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_mode = "RGB"
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(str(out_png))
    pixels = np.array(image.pixels[:], np.float32).reshape(py, px, 4)
    # pixels hold linear light; Blender's rows start at the bottom
    np.save(alpha_path, 1.0 - pixels[::-1, :, :3].mean(axis=2))
    corners = [obj.matrix_world @ __import__("mathutils").Vector(c) for c in obj.bound_box]
    print(json.dumps({"grids": grids, "objects": sum(o.type == "VOLUME" for o in scene.objects),
                      "min": [min(c[k] for c in corners) for k in range(3)],
                      "max": [max(c[k] for c in corners) for k in range(3)]}))


if __name__ == "__main__":
    a = sys.argv[1:]
    main(Path(a[0]), Path(a[1]), float(a[2]), float(a[3]), float(a[4]), int(a[5]), int(a[6]))
