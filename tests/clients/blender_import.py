"""Import fishgen files with Blender's Python module (`bpy`) and print what arrived, as JSON.

Run by tools/check_clients.py --blender with a Python that has `bpy`
(PyPI's bpy wheel: Python 3.11 only; keep it in its own venv):

    /tmp/bpyvenv/bin/python tests/clients/blender_import.py FILE [FILE ...]

Prints one JSON object per file: objects (type, vertices, triangles, point
attributes), materials with the images they use, actions with their channels.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path


def _import(path: Path) -> None:
    import bpy

    ext = path.suffix.lower()
    if ext in (".glb", ".gltf"):
        bpy.ops.import_scene.gltf(filepath=str(path))
    elif ext == ".obj":
        bpy.ops.wm.obj_import(filepath=str(path))
    elif ext == ".ply":
        bpy.ops.wm.ply_import(filepath=str(path))
    else:
        raise ValueError(f"Blender has no importer for {ext}")


def _images(material) -> list[dict]:
    out = []
    if material is None or not material.use_nodes or material.node_tree is None:
        return out
    for node in material.node_tree.nodes:
        if node.type == "TEX_IMAGE" and node.image is not None:
            img = node.image
            links = [f"{lk.to_node.name}.{lk.to_socket.name}" for o in node.outputs for lk in o.links]
            out.append({"name": img.name, "file": Path(img.filepath).name if img.filepath else "",
                        "size": list(img.size), "packed": img.packed_file is not None, "to": links})
    return out


def _channels(action) -> int:
    if hasattr(action, "fcurves") and action.fcurves is not None:
        try:
            return len(action.fcurves)
        except TypeError:
            pass
    n = 0  # Blender 4.4+: layered actions keep F-curves in channel bags
    for layer in getattr(action, "layers", []):
        for strip in layer.strips:
            for bag in getattr(strip, "channelbags", []):
                n += len(bag.fcurves)
    return n


def inspect(path: Path) -> dict:
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    try:
        _import(path)
    except Exception as e:  # noqa: BLE001 - reported, not raised
        return {"file": path.name, "error": f"{type(e).__name__}: {e}"}
    objects = []
    for ob in bpy.context.scene.objects:
        info = {"name": ob.name, "type": ob.type, "visible": ob.visible_get(), "render": not ob.hide_render,
                "parent": ob.parent.name if ob.parent else None,
                "armature": next((m.object.name for m in ob.modifiers
                                  if m.type == "ARMATURE" and m.object), None)}
        if ob.type == "MESH":
            me = ob.data
            me.calc_loop_triangles()
            info.update(vertices=len(me.vertices), faces=len(me.polygons), triangles=len(me.loop_triangles),
                        edges=len(me.edges),
                        attributes=sorted(a.name for a in me.attributes if not a.name.startswith(".")),
                        uv_layers=[u.name for u in me.uv_layers],
                        color_attributes=[c.name for c in me.color_attributes],
                        materials=[{"name": m.name if m else None, "images": _images(m),
                                    "blend": getattr(m, "surface_render_method",
                                                     getattr(m, "blend_method", ""))}
                                   for m in me.materials])
        elif ob.type == "POINTCLOUD":
            info.update(points=len(ob.data.points), attributes=sorted(a.name for a in ob.data.attributes))
        if ob.animation_data and ob.animation_data.action:
            info["action"] = ob.animation_data.action.name
        keys = getattr(ob.data, "shape_keys", None) if ob.type == "MESH" else None
        if keys is not None:  # morph targets: shape keys, animated through the key's own action
            info["shape_keys"] = len(keys.key_blocks) - 1
            if keys.animation_data and keys.animation_data.action:
                info["shape_key_action"] = keys.animation_data.action.name
        objects.append(info)
    # meshes only an armature's bones are drawn with (the importer's bone shapes), not the asset's
    shapes = {b.custom_shape.name for ob in bpy.context.scene.objects if ob.type == "ARMATURE"
              for b in ob.pose.bones if b.custom_shape is not None}
    for info in objects:
        info["bone_shape"] = info["name"] in shapes
    actions = [{"name": a.name, "channels": _channels(a), "users": a.users} for a in bpy.data.actions]
    return {"file": path.name, "blender": bpy.app.version_string, "objects": objects, "actions": actions,
            "images": sorted(i.name for i in bpy.data.images)}


def main(argv: list[str]) -> int:
    for arg in argv:
        print(json.dumps(inspect(Path(arg).resolve())), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
