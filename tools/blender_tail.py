"""Measure the tail tip's sideways travel in Blender's own evaluated meshes (run with a Python that
has Blender's `bpy`; see docs/clients.md):

    /tmp/bpyvenv/bin/python tools/blender_tail.py FILE.glb [FILE.glb ...]

Imports each file into an empty scene, steps through every frame of its animation, evaluates every
mesh object (shape keys, armatures and parents applied by Blender) and prints one line per file:
the tail tip's peak-to-peak lateral travel in body lengths, and the largest shape-key value seen.
glTF +Z (the nose) is Blender -Y, so the tail tip is the vertex with the largest Y; glTF +X is
Blender +X.
"""
from __future__ import annotations

import sys
from pathlib import Path


def measure(path: Path) -> str:
    import bpy
    import numpy as np

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=str(path))
    scene = bpy.context.scene
    start, end = 10**9, -10**9
    for action in bpy.data.actions:
        a, b = action.frame_range
        start, end = min(start, int(a)), max(end, int(b))
    if start > end:
        return f"{path.name}: no animation imported"
    meshes = [ob for ob in scene.objects if ob.type == "MESH" and ob.visible_get()]  # not bone shapes
    xs, length, top_key = [], None, 0.0
    for frame in range(start, end + 1):
        scene.frame_set(frame)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        points = []
        for ob in meshes:
            evaluated = ob.evaluated_get(depsgraph)
            mesh = evaluated.to_mesh()
            co = np.empty(len(mesh.vertices) * 3)
            mesh.vertices.foreach_get("co", co)
            co = (co.reshape(-1, 3) @ np.array(evaluated.matrix_world)[:3, :3].T
                  + np.array(evaluated.matrix_world)[:3, 3])
            points.append(co)
            evaluated.to_mesh_clear()
            keys = ob.data.shape_keys
            if keys is not None:
                top_key = max([top_key] + [k.value for k in keys.key_blocks[1:]])
        points = np.concatenate(points)
        if length is None:
            length = float(np.ptp(points[:, 1]))
        xs.append(points[np.argmax(points[:, 1]), 0])
    return (f"{path.name}: tail tip peak-to-peak {np.ptp(xs) / length:.3f} body lengths over frames "
            f"{start}-{end} (Blender {bpy.app.version_string}; largest shape-key value {top_key:.2f})")


def main(argv: list[str]) -> int:
    for arg in argv:
        print(measure(Path(arg).resolve()), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
