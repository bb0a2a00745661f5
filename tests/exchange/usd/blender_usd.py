"""Run by Blender's Python (bpy): import a USD file with Blender's own importer and print, as one
JSON line, what Blender made of it: the frame range, and at each asked frame the points of its
point clouds (a PointInstancer's copies), the mesh instances the evaluated scene draws and the meshes it draws
as themselves, how many copies of each prototype's root it places, and the box around every drawn
mesh's vertices in world space.

Usage: python blender_usd.py FILE.usd FRAME [FRAME ...]
"""
import json
import sys
from collections import Counter

import bpy
import numpy as np


def main() -> None:
    path, frames = sys.argv[1], [int(f) for f in sys.argv[2:]]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.usd_import(filepath=path, set_frame_range=True, import_usd_preview=True)
    scene = bpy.context.scene
    report = {"frame_start": scene.frame_start, "frame_end": scene.frame_end, "fps": scene.render.fps,
              "objects": sorted(o.type for o in scene.objects), "frames": {}}
    for frame in frames:
        scene.frame_set(frame)
        graph = bpy.context.evaluated_depsgraph_get()
        points_ = sum(len(o.data.points) for o in scene.objects if o.type == "POINTCLOUD")
        roots = Counter(i.object.name for i in graph.object_instances
                        if i.is_instance and i.object.type == "EMPTY")
        instances, direct, low, high = 0, 0, np.full(3, np.inf), np.full(3, -np.inf)
        for inst in graph.object_instances:
            obj = inst.object
            if obj.type != "MESH":
                continue
            mesh = obj.data
            if not len(mesh.vertices):
                continue
            instances += inst.is_instance
            direct += not inst.is_instance
            points = np.empty(len(mesh.vertices) * 3)
            mesh.vertices.foreach_get("co", points)
            matrix = np.array(inst.matrix_world)
            world = points.reshape(-1, 3) @ matrix[:3, :3].T + matrix[:3, 3]
            low, high = np.minimum(low, world.min(axis=0)), np.maximum(high, world.max(axis=0))
        report["frames"][str(frame)] = {"points": points_, "instances": instances, "direct": direct,
                                        "roots": roots,
                                        "low": low.tolist(), "high": high.tolist()}
    print(json.dumps(report))


main()
