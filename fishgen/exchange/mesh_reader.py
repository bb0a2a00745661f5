"""Read OBJ (+MTL, textures) and PLY (meshes or particle clouds) into the scene model.

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
from fishgen.exchange.gltf_reader import one_line
from fishgen.exchange.sidefiles import side_file
from fishgen.numeric import srgb_to_linear
from fishgen.scene.model import Image, Material, Mesh, Node, Primitive, Scene


def read_mesh_file(path: str | Path, **_) -> Scene:
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
    scene = Scene(name=path.stem, info={"source": str(path)})
    for k, geom in enumerate(geoms):
        if isinstance(geom, trimesh.PointCloud):
            prim = _points(geom)
        elif isinstance(geom, trimesh.Trimesh) and len(geom.faces):
            prim = _mesh(geom, alpha, path, scene)
        else:
            continue
        name = str(geom.metadata.get("name") or f"{path.stem}{k}")
        scene.add_node(Node(name=name, mesh=scene.add_mesh(Mesh(name, [prim]))))
    if not scene.meshes:
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


def _mesh(geom, alpha: dict[str, tuple[str, float]], path: Path, scene: Scene) -> Primitive:
    positions = np.asarray(geom.vertices, np.float32)
    faces = np.asarray(geom.faces)
    if faces.min() < 0 or faces.max() >= len(positions):  # checked before anything indexes with them
        bad = int(faces.max()) if faces.max() >= len(positions) else int(faces.min())
        raise expected(f"face vertex indices from 0 to {len(positions) - 1}", str(bad), path)
    # trimesh keeps the file's normals, or computes smooth ones when it has none
    attributes = {"POSITION": positions, "NORMAL": np.asarray(geom.vertex_normals, np.float32)}
    material = None
    visual = geom.visual
    if visual.kind == "texture":
        mat = visual.material
        uv = getattr(visual, "uv", None)
        if uv is not None and len(uv) == len(positions):
            uvs = np.asarray(uv, np.float32).copy()
            uvs[:, 1] = 1.0 - uvs[:, 1]  # OBJ's v points up; the image's first row is the top
            attributes["TEXCOORD_0"] = uvs
        image = getattr(mat, "image", None) or getattr(mat, "baseColorTexture", None)
        diffuse = getattr(mat, "diffuse", None)
        if diffuse is None:
            diffuse = getattr(mat, "baseColorFactor", None)
        rgba = np.asarray(diffuse if diffuse is not None else [255] * 4, np.float32).ravel()
        rgba = rgba / 255.0 if rgba.max() > 1.0 else rgba
        rgb = srgb_to_linear(rgba[:3])  # MTL Kd is authored as a display (sRGB) colour
        name = getattr(mat, "name", None) or ""
        mode, opacity = alpha.get(name, ("OPAQUE", 1.0))
        texture = None
        if image is not None and "TEXCOORD_0" in attributes:
            texture = scene.add_image(Image(name or "texture", b"",
                                            pixels=np.asarray(image.convert("RGBA"))))
        material = scene.add_material(Material(name or f"material{len(scene.materials)}",
                                               (*map(float, rgb), float(opacity)), texture, mode,  # type: ignore[arg-type]
                                               double_sided=mode != "OPAQUE"))
    elif visual.kind == "vertex":
        c = np.asarray(visual.vertex_colors, np.float32) / 255.0
        attributes["COLOR_0"] = np.hstack([srgb_to_linear(c[:, :3]), c[:, 3:4]])
    return Primitive(attributes, faces.astype(np.uint32), material)


def _points(cloud) -> Primitive:
    positions = np.asarray(cloud.vertices, np.float32)
    columns = _ply_columns(cloud.metadata.get("_ply_raw", {}).get("vertex", {}).get("data"))
    attributes = {"POSITION": positions}
    if "radius" in columns:
        attributes["_RADIUS"] = columns["radius"].astype(np.float32)
    if all(k in columns for k in ("red", "green", "blue")):
        rgb = np.stack([columns[k] for k in ("red", "green", "blue")], 1).astype(np.float32)
        rgba = np.ones((len(positions), 4), np.float32)
        rgba[:, :3] = srgb_to_linear(rgb / (255.0 if rgb.max() > 1 else 1.0))
        attributes["COLOR_0"] = rgba
    if "density" in columns:
        attributes["_DENSITY"] = np.clip(columns["density"].astype(np.float32), 0, 1)
    return Primitive(attributes, mode="POINTS")


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
