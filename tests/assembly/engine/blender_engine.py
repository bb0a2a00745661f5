"""Import a fishgen fish with Blender's glTF importer and play each clip as Blender does; print JSON.

Run with a Python that has PyPI's `bpy` (3.11 only; see docs/clients.md):

    /tmp/bpyvenv/bin/python tests/assembly/engine/blender_engine.py FILE.glb SPEC.json

SPEC holds ``probes`` (rest positions in glTF axes: each is matched to the nearest vertex of the
visible meshes at rest) and ``clips`` ({name: [times in seconds]}). The output: which mesh objects
are visible, the actions, and per clip each probe's posed position (glTF axes) at each time, taken
from Blender's own evaluated meshes (shape keys, armature and parents applied by Blender). With
``"shading": true`` in SPEC, also ``shading``: per clip, per visible mesh, its triangles and at each
time its evaluated vertices and the normals Blender shades them with (its corner normals, one per
vertex: fishgen's vertices are already split where normals differ; ``corner_spread`` says how far
a vertex's corners disagree; ``fin`` marks the vertices of fins), all in the object's own space.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path


def _to_gltf(points):
    """Blender axes (+Z up, -Y forward) to glTF's (+Y up, +Z forward)."""
    return points[:, [0, 2, 1]] * [1.0, 1.0, -1.0]


def _use_clip(name: str) -> None:
    """Make every object (and shape-key block) play the importer's action for clip ``name``."""
    import bpy

    holders = list(bpy.data.objects) + [k for k in bpy.data.shape_keys]
    for data in holders:
        ad = getattr(data, "animation_data", None)
        if ad is None:
            continue
        for track in ad.nla_tracks:
            if track.name == name and track.strips:
                ad.action = track.strips[0].action
                ad.action_slot = track.strips[0].action_slot
                break
        else:
            if ad.action is not None:
                ad.action_slot = None
            ad.action = None


def _rest() -> None:
    """No clip: every object at the rest transform the importer recorded, bones and shape keys at rest
    (taking an action away leaves the values it last set)."""
    import bpy

    _use_clip("__none__")
    for ob in bpy.data.objects:
        rest = getattr(ob, "gltf2_animation_rest", None)
        if rest is not None:
            ob.matrix_basis = rest
        if ob.type == "ARMATURE":
            for bone in ob.pose.bones:
                bone.location, bone.rotation_quaternion, bone.scale = (0, 0, 0), (1, 0, 0, 0), (1, 1, 1)
    for key in bpy.data.shape_keys:
        for block in key.key_blocks[1:]:
            block.value = 0.0


def main(path: Path, spec: dict) -> dict:
    import bpy
    import numpy as np

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=str(path))
    scene = bpy.context.scene
    fps = scene.render.fps / scene.render.fps_base
    meshes = [ob for ob in scene.objects if ob.type == "MESH" and ob.visible_get()]
    hidden = sorted(ob.name for ob in bpy.data.objects if ob.type == "MESH" and not ob.visible_get())
    depsgraph = bpy.context.evaluated_depsgraph_get()

    def evaluated(ob):
        """The object as the depsgraph evaluates it, its mesh (free with ``to_mesh_clear``) and the
        mesh's vertices in the object's own space."""
        ev = ob.evaluated_get(depsgraph)
        mesh = ev.to_mesh()
        co = np.empty(len(mesh.vertices) * 3)
        mesh.vertices.foreach_get("co", co)
        return ev, mesh, co

    def world_vertices() -> list[np.ndarray]:
        out = []
        for ob in meshes:
            ev, _, co = evaluated(ob)
            m = np.array(ev.matrix_world)
            out.append(co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3])
            ev.to_mesh_clear()
        return out

    _rest()
    scene.frame_set(0)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    rest = [_to_gltf(part) for part in world_vertices()]
    owners = np.concatenate([np.full(len(r), k) for k, r in enumerate(rest)])
    every = np.concatenate(rest)
    probes = np.asarray(spec["probes"], float)
    nearest = [int(np.argmin(np.linalg.norm(every - p, axis=1))) for p in probes]
    gaps = [np.linalg.norm(every[n] - p) for n, p in zip(nearest, probes, strict=True)]
    found = float(max(gaps)) if gaps else 0.0

    def shaded() -> list[dict]:
        out = []
        for ob in meshes:
            ev, mesh, co = evaluated(ob)
            corners = np.empty(len(mesh.loops), np.int64)
            mesh.loops.foreach_get("vertex_index", corners)
            normals = np.empty(len(mesh.loops) * 3)
            mesh.corner_normals.foreach_get("vector", normals)
            normals = normals.reshape(-1, 3)
            per_vertex = np.zeros((len(mesh.vertices), 3))
            per_vertex[corners[::-1]] = normals[::-1]          # each vertex's first corner
            cos = np.sum(per_vertex[corners] * normals, axis=1)
            tris = np.empty(len(mesh.loop_triangles) * 3, np.int64)
            mesh.loop_triangles.foreach_get("vertices", tris)
            slots = np.empty(len(mesh.loop_triangles), np.int64)
            mesh.loop_triangles.foreach_get("material_index", slots)
            names = [s.material.name if s.material else "" for s in ob.material_slots] or [""]
            fins = np.array([n.endswith("_fins") for n in names])[slots] | ("_fin" in ob.name)
            fin_vertex = np.zeros(len(mesh.vertices), bool)
            fin_vertex[tris.reshape(-1, 3)[fins].ravel()] = True
            spread = float(np.degrees(np.arccos(np.clip(cos.min(), -1, 1)))) if len(cos) else 0.0
            out.append({"name": ob.name, "faces": tris.tolist(), "positions": co.tolist(),
                        "normals": per_vertex.ravel().tolist(), "fin": fin_vertex.tolist(),
                        "corner_spread": spread})
            ev.to_mesh_clear()
        return out

    clips, shading = {}, {}
    if spec.get("shading"):    # the rest pose: the normals the importer made of the file's
        shading["__rest__"] = [shaded()]
    for name, times in spec["clips"].items():
        _use_clip(name)
        track, shades = [], []
        for t in times:
            frame = t * fps
            scene.frame_set(int(np.floor(frame)), subframe=float(frame - np.floor(frame)))
            depsgraph = bpy.context.evaluated_depsgraph_get()
            posed = np.concatenate([_to_gltf(part) for part in world_vertices()])
            track.append(posed[nearest].tolist())
            if spec.get("shading"):
                shades.append(shaded())
        clips[name] = track
        if shades:
            shading[name] = shades
    actions = sorted(a.name for a in bpy.data.actions)
    return {"file": path.name, "blender": bpy.app.version_string, "visible": sorted(ob.name for ob in meshes),
            "hidden": hidden, "actions": actions, "probe_distance": found, "fps": fps,
            "owners": [meshes[int(owners[n])].name for n in nearest], "clips": clips, "shading": shading}


if __name__ == "__main__":
    spec = json.loads(Path(sys.argv[2]).read_text())
    print(json.dumps(main(Path(sys.argv[1]).resolve(), spec)), flush=True)
