"""Read OBJ (+MTL, textures) and PLY (meshes or particle clouds) into a preview ``Scene``.

trimesh does the parsing; this module maps what it finds onto preview materials.
OBJ transparency comes from the MTL itself (``d`` below 1: blended; ``map_d``:
a cut-out mask), since trimesh's materials drop those statements. A PLY of
bare vertices is a particle cloud: a ``radius`` property gives each particle's
size, ``density`` its opacity, ``red green blue`` its sRGB colour.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from fishgen.errors import FishgenError
from fishgen.preview.gltf_reader import POINT_SIZE_FRACTION
from fishgen.preview.scene import Material, MeshPart, PointPart, Scene, srgb_to_linear


def read_mesh_file(path: str | Path) -> Scene:
    """Load an .obj or .ply file as a Scene; unreadable files raise FishgenError."""
    import trimesh

    path = Path(path)
    try:
        loaded = trimesh.load(str(path), process=False)
    except Exception as err:
        raise FishgenError(f"not a readable {path.suffix[1:].upper()} file ({type(err).__name__}: {err})",
                           path)
    geoms = loaded.dump(concatenate=False) if isinstance(loaded, trimesh.Scene) else [loaded]
    alpha = _mtl_alpha(path) if path.suffix.lower() == ".obj" else {}
    scene = Scene(label=path.stem)
    for geom in geoms:
        if isinstance(geom, trimesh.PointCloud):
            scene.points.append(_points(geom))
        elif isinstance(geom, trimesh.Trimesh) and len(geom.faces):
            scene.meshes.append(_mesh(geom, alpha))
    if not scene.meshes and not scene.points:
        raise FishgenError("expected triangles or points, found an empty asset", path)
    return scene


def _mtl_alpha(obj: Path) -> dict[str, tuple[str, float]]:
    """material name -> (alpha mode, opacity) from the OBJ's MTL libraries."""
    out: dict[str, tuple[str, float]] = {}
    libs = re.findall(r"^mtllib\s+(.+?)\s*$", obj.read_text(errors="replace"), re.M)
    for lib in libs:
        mtl = obj.parent / lib
        if not mtl.is_file():
            continue
        name = None
        for line in mtl.read_text(errors="replace").splitlines():
            words = line.split()
            if not words:
                continue
            if words[0] == "newmtl":
                name = " ".join(words[1:])
                out[name] = ("OPAQUE", 1.0)
            elif name is not None and words[0] == "d" and len(words) > 1:
                d = float(words[-1])
                out[name] = ("BLEND" if d < 1 else out[name][0], d)
            elif name is not None and words[0] == "map_d":
                out[name] = ("MASK", out[name][1])
    return out


def _mesh(geom, alpha: dict[str, tuple[str, float]]) -> MeshPart:
    positions = np.asarray(geom.vertices, np.float32)
    indices = np.asarray(geom.faces, np.uint32)
    # trimesh keeps the file's normals, or computes smooth ones when it has none
    normals = np.asarray(geom.vertex_normals, np.float32)
    material, uvs, colors = Material(), None, None
    visual = geom.visual
    if visual.kind == "texture":
        mat = visual.material
        uv = getattr(visual, "uv", None)
        if uv is not None and len(uv) == len(positions):
            uvs = np.asarray(uv, np.float32).copy()
            uvs[:, 1] = 1.0 - uvs[:, 1]  # OBJ's v points up; the image's first row is the top
        image = getattr(mat, "image", None) or getattr(mat, "baseColorTexture", None)
        diffuse = getattr(mat, "diffuse", None)
        if diffuse is None:
            diffuse = getattr(mat, "baseColorFactor", None)
        rgba = np.asarray(diffuse if diffuse is not None else [255] * 4, np.float32).ravel()
        rgba = rgba / 255.0 if rgba.max() > 1.0 else rgba
        rgb = srgb_to_linear(rgba[:3])  # MTL Kd is authored as a display (sRGB) colour
        mode, opacity = alpha.get(getattr(mat, "name", None) or "", ("OPAQUE", 1.0))
        material = Material(base_color=(*map(float, rgb), float(opacity)),
                            texture=np.asarray(image.convert("RGBA")) if image is not None and uvs is not None else None,
                            alpha_mode=mode, double_sided=mode != "OPAQUE")
    elif visual.kind == "vertex":
        c = np.asarray(visual.vertex_colors, np.float32) / 255.0
        colors = np.hstack([srgb_to_linear(c[:, :3]), c[:, 3:4]])
    return MeshPart(positions, indices, material, None, normals, uvs, colors)


def _points(cloud) -> PointPart:
    positions = np.asarray(cloud.vertices, np.float32)
    raw = cloud.metadata.get("_ply_raw", {}).get("vertex", {}).get("data")
    names = raw.dtype.names if raw is not None and raw.dtype.names else ()
    if "radius" in names:
        radii = np.asarray(raw["radius"], np.float32).ravel()
    else:
        span = positions.max(0) - positions.min(0) if len(positions) else np.ones(3)
        radii = np.full(len(positions), POINT_SIZE_FRACTION * float(np.linalg.norm(span)), np.float32)
    rgba = np.ones((len(positions), 4), np.float32)
    if all(k in names for k in ("red", "green", "blue")):
        rgb = np.stack([raw[k].ravel() for k in ("red", "green", "blue")], 1).astype(np.float32)
        rgba[:, :3] = srgb_to_linear(rgb / (255.0 if rgb.max() > 1 else 1.0))
    if "density" in names:
        rgba[:, 3] = np.clip(np.asarray(raw["density"], np.float32).ravel(), 0, 1)
    return PointPart(positions, radii, rgba)
