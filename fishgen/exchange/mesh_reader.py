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
from trimesh.resolvers import Resolver

from fishgen.errors import FishgenError, describe, expected
from fishgen.preview.gltf_reader import POINT_SIZE_FRACTION, one_line
from fishgen.preview.scene import Material, MeshPart, PointPart, Scene, srgb_to_linear
from fishgen.preview.sidefiles import side_file


def read_mesh_file(path: str | Path) -> Scene:
    """Load an .obj or .ply file as a Scene; unreadable files raise FishgenError.

    The whole read is guarded, not only trimesh's parse: a face index past the
    vertices or a broken MTL statement is bad input like any other.
    """
    path = Path(path)
    try:
        return _read(path)
    except FishgenError:
        raise
    except Exception as err:  # trimesh and numpy raise anything from KeyError to IndexError
        raise FishgenError(f"not a readable {path.suffix[1:].upper()} file "
                           f"({type(err).__name__}: {one_line(err)})", path) from None


def _read(path: Path) -> Scene:
    import trimesh

    obj = path.suffix.lower() == ".obj"
    alpha = _mtl_alpha(path) if obj else {}  # also refuses side files outside the asset's folder
    loaded = trimesh.load(str(path), process=False, resolver=_FolderResolver(path))
    geoms = loaded.dump(concatenate=False) if isinstance(loaded, trimesh.Scene) else [loaded]
    scene = Scene(label=path.stem)
    for geom in geoms:
        if isinstance(geom, trimesh.PointCloud):
            scene.points.append(_points(geom))
        elif isinstance(geom, trimesh.Trimesh) and len(geom.faces):
            scene.meshes.append(_mesh(geom, alpha, path))
    if not scene.meshes and not scene.points:
        raise FishgenError("expected triangles or points, found an empty asset", path)
    return scene


class _FolderResolver(Resolver):
    """Hands trimesh the side files it asks for, from the asset's folder only."""

    def __init__(self, asset: Path):
        self.asset = asset

    def get(self, name: str) -> bytes:
        words = name.split()
        # MTL map statements may reach us with options first ("-imfchan m skin.png").
        for candidate in dict.fromkeys([name, words[-1] if words else name]):
            target = side_file(self.asset, candidate)
            if target.is_file():
                return target.read_bytes()
        raise FileNotFoundError(name)

    def keys(self):
        return iter(())

    def write(self, name, data):
        raise OSError("a preview writes no side files")

    def namespaced(self, namespace):
        return self


def _mtl_alpha(obj: Path) -> dict[str, tuple[str, float]]:
    """material name -> (alpha mode, opacity) from the OBJ's MTL libraries.

    Every MTL and texture reference is checked to stay in the OBJ's folder; a
    missing MTL only loses its materials, as in an engine.
    """
    out: dict[str, tuple[str, float]] = {}
    libs = re.findall(r"^\s*mtllib\s+(.+?)\s*$", obj.read_text(errors="replace"), re.M)
    for lib in libs:
        mtl = side_file(obj, lib)
        if not mtl.is_file():
            continue
        name = None
        for number, line in enumerate(mtl.read_text(errors="replace").splitlines(), 1):
            words = line.split()
            if not words:
                continue
            key = words[0].lower()
            if key in _MAP_KEYS and len(words) > 1:
                side_file(obj, words[-1])  # options such as "-imfchan m" come before the file name
            if key == "newmtl":
                name = " ".join(words[1:])
                out[name] = ("OPAQUE", 1.0)
            elif name is not None and key == "d" and len(words) > 1:
                try:
                    d = float(words[-1])
                except ValueError:
                    raise expected("an opacity number after d", describe(words[-1]), mtl, number) from None
                if d != d:  # nan
                    raise expected("an opacity number after d", describe(words[-1]), mtl, number)
                d = min(max(d, 0.0), 1.0)
                out[name] = ("BLEND" if d < 1 else out[name][0], d)
            elif name is not None and key == "map_d":
                out[name] = ("MASK", out[name][1])
    return out


_MAP_KEYS = {"map_ka", "map_kd", "map_ks", "map_ke", "map_ns", "map_d", "map_bump", "bump", "disp",
             "decal", "refl", "norm", "map_pr", "map_pm", "map_ps"}


def _mesh(geom, alpha: dict[str, tuple[str, float]], path: Path) -> MeshPart:
    positions = np.asarray(geom.vertices, np.float32)
    faces = np.asarray(geom.faces)
    if faces.min() < 0 or faces.max() >= len(positions):  # checked before anything indexes with them
        bad = int(faces.max()) if faces.max() >= len(positions) else int(faces.min())
        raise expected(f"face vertex indices from 0 to {len(positions) - 1}", str(bad), path)
    indices = faces.astype(np.uint32)
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
    columns = _ply_columns(cloud.metadata.get("_ply_raw", {}).get("vertex", {}).get("data"))
    if "radius" in columns:
        radii = columns["radius"].astype(np.float32)
    else:
        span = positions.max(0) - positions.min(0) if len(positions) else np.ones(3)
        radii = np.full(len(positions), POINT_SIZE_FRACTION * float(np.linalg.norm(span)), np.float32)
    rgba = np.ones((len(positions), 4), np.float32)
    if all(k in columns for k in ("red", "green", "blue")):
        rgb = np.stack([columns[k] for k in ("red", "green", "blue")], 1).astype(np.float32)
        rgba[:, :3] = srgb_to_linear(rgb / (255.0 if rgb.max() > 1 else 1.0))
    if "density" in columns:
        rgba[:, 3] = np.clip(columns["density"].astype(np.float32), 0, 1)
    return PointPart(positions, radii, rgba)


def _ply_columns(raw) -> dict[str, np.ndarray]:
    """PLY vertex properties by name, one value per vertex.

    trimesh keeps binary PLY data as a structured array and ASCII PLY data as a
    dict of column arrays; both come out the same here.
    """
    if raw is None:
        return {}
    if isinstance(raw, dict):
        return {str(k): np.asarray(v).ravel() for k, v in raw.items()}
    names = getattr(getattr(raw, "dtype", None), "names", None) or ()
    return {k: np.asarray(raw[k]).ravel() for k in names}
