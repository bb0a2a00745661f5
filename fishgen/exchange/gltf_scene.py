"""Scene building: a checked glTF document, decoded, becomes the scene model.

Materials, meshes (triangle strips and fans as triangle lists; lines, which have no surface to
preview, dropped), nodes, skins and animation clips map one to one onto
:mod:`fishgen.scene.model`. The few rules only decoded values can break are checked on the way:
vertex indices below the vertex count, skin weights that sum to 1, joints within their skin,
keyframe times that never decrease; and, last, that the scene poses within reach (:data:`REACH`).
"""
from __future__ import annotations

from typing import cast

import numpy as np

from fishgen.errors import expected
from fishgen.exchange.gltf_accessors import Decoder
from fishgen.exchange.gltf_checks import Document, item_name
from fishgen.scene.model import (
    PATHS,
    Channel,
    Clip,
    Image,
    Material,
    Mesh,
    Node,
    Primitive,
    PrimitiveMode,
    Sampler,
    Scene,
    Skin,
)

_MODES: dict[int, PrimitiveMode] = {0: "POINTS", 4: "TRIANGLES", 5: "TRIANGLES", 6: "TRIANGLES"}
_IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]


def build_scene(document: Document, label: str, source: str) -> Scene:
    """The scene named ``label`` that ``document`` describes; ``source`` says where it came from."""
    data = Decoder(document)
    lists = document.lists
    scene = Scene(name=label, source=source)
    for k, m in enumerate(lists["meshes"]):
        prims = [_primitive(data, p, f"meshes[{k}].primitives[{j}]") for j, p in enumerate(m["primitives"])]
        scene.meshes.append(Mesh(item_name(m, f"mesh{k}"), [p for p in prims if p is not None],
                                 [float(w) for w in m.get("weights", [])], _target_names(m)))
    scene.images = [Image(item_name(img, f"image{k}"), data.image_bytes(k), _mime(img))
                    for k, img in enumerate(lists["images"])]
    scene.materials = [_material(lists, k) for k in range(len(lists["materials"]))]
    scene.nodes = [_node(i, n) for i, n in enumerate(lists["nodes"])]
    for k, skin in enumerate(lists["skins"]):
        joints = list(skin["joints"])
        if skin.get("inverseBindMatrices") is not None:
            ibm = (data.accessor(skin["inverseBindMatrices"]).astype(float)
                   .reshape(-1, 4, 4).transpose(0, 2, 1))
        else:
            ibm = np.repeat(np.eye(4)[None], len(joints), axis=0)
        scene.skins.append(Skin(item_name(skin, f"skin{k}"), joints, ibm, skin.get("skeleton")))
    _check_joints(scene)
    # Only nodes reachable from the default scene are drawn, as an engine would.
    scenes = lists["scenes"]
    scene.roots = (list(scenes[document.doc.get("scene", 0)].get("nodes", [])) if scenes
                   else [i for i in range(len(lists["nodes"])) if i not in document.parent])
    extras = scenes[document.doc.get("scene", 0)].get("extras") if scenes else None
    if isinstance(extras, dict):  # kept as read; whoever uses a member checks it
        scene.extras = extras
    scene.clips = [_clip(data, k, a) for k, a in enumerate(lists["animations"])]
    _check_reach(scene)
    return scene


#: How far from the origin a posed vertex may lie: what a float32 camera can frame (the preview
#: refuses a scene past it). Every consumer poses the scene, the preview at rest, the viewer and
#: the fly-through through its clips, so a file whose finite numbers multiply past it (morph
#: weights of 1e300, nested scales of 1e20) is refused here, once, not in each of them. Only rest
#: and each clip's middle are posed (the school's 2,000 nodes take about 60 ms a pose): keyframes
#: that reach past it at other moments are left to the preview's own check of each frame it draws.
REACH = 1e30


def _check_reach(scene: Scene) -> None:
    """Refuse a scene whose drawn vertices, posed at rest or halfway through each clip, are not
    finite numbers within :data:`REACH` of the origin. Each moment is first bounded
    from the node matrices and each primitive's largest coordinates (cheap: a school's 200 fish
    are not deformed vertex by vertex), and posed exactly only when that bound is past reach."""
    from fishgen.scene.pose import bounds, pose

    drawn = [(node, prim) for node, prim in scene.drawn() if prim.vertex_count]
    if not drawn:
        return
    with np.errstate(all="ignore"):   # an overflow is what is being looked for
        sizes = [(float(np.abs(prim.attributes["POSITION"]).max()),
                  [float(np.abs(t["POSITION"]).max()) if "POSITION" in t else 0.0 for t in prim.targets])
                 for _, prim in drawn]
    moments: list[tuple[float | None, Clip | None]] = [(None, None)]
    moments += [(clip.duration / 2, clip) for clip in scene.clips]
    for t, clip in moments:
        with np.errstate(all="ignore"):
            posed = pose(scene, t, clip)
            reach = 0.0
            for (node, prim), (size, targets) in zip(drawn, sizes, strict=True):
                w = posed.weights.get(node)
                if prim.targets and w is not None:
                    size += sum(abs(float(a)) * b for a, b in zip(w, targets, strict=False))
                skin = scene.nodes[node].skin
                mats = ([posed.world[j] @ m for j, m in zip(scene.skins[skin].joints,
                                                             scene.skins[skin].inverse_bind_matrices,
                                                             strict=False)]
                        if skin is not None and "JOINTS_0" in prim.attributes else [posed.world[node]])
                for m in mats:   # |M x + c| <= (largest row sum of |M|) |x| + |c|, each axis
                    reach = max(reach, float(np.abs(m[:3, :3]).sum(axis=1).max()) * size
                                + float(np.abs(m[:3, 3]).max()))
            # half the reach: a skinned vertex's weights may sum to 1.02, and the exact pose settles
            # anything near the line
            if reach < REACH / 2:   # NaN fails too
                continue
            box = bounds(scene, t, clip)   # the bound is loose: pose every vertex to be sure
        if (np.abs(box) < REACH).all():
            continue
        when = "at rest" if clip is None else f"in animation {clip.name!r} at {t:g} s"
        found = ("a vertex that is not a number" if np.isnan(box).any()
                 else f"one {float(np.abs(box).max()):.3g} away")
        far = f"{REACH:.0e}".replace("e+", "e")
        raise expected(f"drawn vertices within {far} of the origin posed {when} (morph weights, "
                       "scales and translations that multiply within reach)", found)


def _mime(img: dict) -> str:
    mime = img.get("mimeType")
    return mime if isinstance(mime, str) else "image/png"


def _material(lists: dict[str, list[dict]], k: int) -> Material:
    m = lists["materials"][k]
    pbr = m.get("pbrMetallicRoughness") or {}
    texture = None
    if pbr.get("baseColorTexture") is not None:
        texture = lists["textures"][pbr["baseColorTexture"]["index"]].get("source")
    factor = pbr.get("baseColorFactor") or [1, 1, 1, 1]
    base_color = cast(tuple[float, float, float, float], tuple(float(v) for v in factor))
    cutoff = m.get("alphaCutoff")
    return Material(name=item_name(m, f"material{k}"), base_color=base_color,
                    texture=texture, alpha_mode=m.get("alphaMode", "OPAQUE"),
                    alpha_cutoff=None if cutoff is None else float(cutoff),
                    double_sided=bool(m.get("doubleSided", False)),
                    unlit="KHR_materials_unlit" in (m.get("extensions") or {}))


def _primitive(data: Decoder, prim: dict, where: str) -> Primitive | None:
    mode = prim.get("mode", 4)
    attrs = prim["attributes"]
    if "POSITION" not in attrs or mode not in _MODES:
        return None  # lines have no surface to preview
    attributes = {name: data.accessor(index) for name, index in attrs.items()}
    attributes = {name: (a.ravel() if a.shape[1] == 1 else a) for name, a in attributes.items()}
    attributes["POSITION"] = attributes["POSITION"].astype(np.float32)
    n = len(attributes["POSITION"])
    weights = attributes.get("WEIGHTS_0")
    if weights is not None and "JOINTS_0" in attributes:
        sums = np.asarray(weights, np.float64).sum(axis=1)
        if (weights < 0).any() or not np.allclose(sums, 1.0, atol=0.02):
            bad = int(np.argmax(np.abs(sums - 1.0) + (weights < 0).any(axis=1)))
            raise expected(f"WEIGHTS_0 of each vertex non-negative and summing to 1 at {where}",
                           f"{np.round(weights[bad], 4).tolist()} at vertex {bad}")
    indices = None
    named = _indices(data, prim, n, where)
    if _MODES[mode] == "TRIANGLES":
        indices = _triangles(np.arange(n, dtype=np.uint32) if named is None else named, mode)
    targets = [{name: data.accessor(index).astype(np.float32) for name, index in target.items()}
               for target in prim.get("targets", [])]
    if _MODES[mode] == "POINTS" and named is not None:
        # indexed points draw the vertices they name, once each time they are named
        attributes = {name: a[named] for name, a in attributes.items()}
        targets = [{name: t[named] for name, t in target.items()} for target in targets]
    return Primitive(attributes, indices, prim.get("material"), _MODES[mode], targets)


def _indices(data: Decoder, prim: dict, n: int, where: str) -> np.ndarray | None:
    """A primitive's vertex indices (uint32), checked below its ``n`` vertices, or None."""
    if "indices" not in prim:
        return None
    flat = data.accessor(prim["indices"]).ravel().astype(np.uint32)
    if len(flat) and int(flat.max()) >= n:  # the GPU would read past the vertices
        raise expected(f"vertex indices below {n} at {where}", str(int(flat.max())))
    return flat


def _triangles(flat: np.ndarray, mode: int) -> np.ndarray:
    """Triangle list from TRIANGLES / TRIANGLE_STRIP / TRIANGLE_FAN indices."""
    if mode == 4:
        return flat[: len(flat) // 3 * 3].reshape(-1, 3)
    n = len(flat) - 2
    if n <= 0:
        return np.zeros((0, 3), np.uint32)
    k = np.arange(n)
    if mode == 5:  # strip: odd triangles swap winding to keep faces consistent
        a, b = np.where(k % 2 == 0, k, k + 1), np.where(k % 2 == 0, k + 1, k)
        return np.stack([flat[a], flat[b], flat[k + 2]], 1)
    return np.stack([np.full(n, flat[0]), flat[k + 1], flat[k + 2]], 1)  # fan


def _node(i: int, n: dict) -> Node:
    node = Node(name=item_name(n, f"node{i}"), children=list(n.get("children", [])),
                mesh=n.get("mesh"), skin=n.get("skin"))
    if n.get("matrix") is not None and list(n["matrix"]) != _IDENTITY:
        node.matrix = np.asarray(n["matrix"], float).reshape(4, 4).T  # column-major
    if n.get("translation") is not None:
        node.translation = cast(tuple[float, float, float], tuple(map(float, n["translation"])))
    if n.get("rotation") is not None:
        node.rotation = cast(tuple[float, float, float, float], tuple(map(float, n["rotation"])))
    if n.get("scale") is not None:
        node.scale = cast(tuple[float, float, float], tuple(map(float, n["scale"])))
    return node


def _check_joints(scene: Scene) -> None:
    """JOINTS_0 of a skinned mesh index its skin's joints."""
    for i, node in enumerate(scene.nodes):
        if node.skin is None or node.mesh is None:
            continue
        joints = len(scene.skins[node.skin].joints)
        for prim in scene.meshes[node.mesh].primitives:
            a = prim.attributes.get("JOINTS_0")
            if a is not None and len(a) and int(a.max()) >= joints:
                raise expected(f"JOINTS_0 values below {joints} (the joints of skins[{node.skin}]) "
                               f"in meshes[{node.mesh}] on nodes[{i}]", str(int(a.max())))


def _clip(data: Decoder, k: int, a: dict) -> Clip:
    channels = []
    for j, ch in enumerate(a.get("channels", [])):
        smp = a["samplers"][ch["sampler"]]
        interp = smp.get("interpolation", "LINEAR")
        node, path = ch["target"].get("node"), ch["target"]["path"]
        if node is None or path not in PATHS:
            continue
        times = data.accessor(smp["input"]).astype(float).ravel()
        if len(times) > 1 and (np.diff(times) < 0).any():
            at = int(np.argmax(np.diff(times) < 0)) + 1
            raise expected(f"keyframe times that never decrease at animations[{k}].channels[{j}]",
                           f"{times[at]:g} after {times[at - 1]:g}")
        values = data.accessor(smp["output"]).astype(float)
        if path == "weights":
            values = values.reshape(len(times) * (3 if interp == "CUBICSPLINE" else 1), -1)
        channels.append(Channel(node, path, Sampler(times, values, interp)))
    return Clip(item_name(a, f"clip{k}"), channels)


def _target_names(mesh: dict) -> list[str]:
    """A mesh's ``extras.targetNames`` (three.js and Blender read them), kept only when they are
    one string per morph target; anything else is application data and ignored."""
    extras = mesh.get("extras")
    names = extras.get("targetNames") if isinstance(extras, dict) else None
    prims = mesh.get("primitives") or [{}]
    count = len(prims[0].get("targets", []) or [])
    if isinstance(names, list) and len(names) == count and all(isinstance(n, str) for n in names):
        return list(names)
    return []
