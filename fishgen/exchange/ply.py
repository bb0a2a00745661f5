"""Stanford PLY writer (binary little-endian): a rest-pose mesh, or a particle set.

A scene of triangles becomes one mesh with normals and UVs (``s t``) and a
``comment TextureFile`` for its first image. A scene of points becomes one
vertex element of x y z, then ``radius`` and ``density`` where the points have
them and ``red green blue`` as sRGB bytes (what Blender, Open3D and plyfile
expect), streamed a chunk at a time so a 10^7-particle cloud needs no copy.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from fishgen.atomic import atomic_open, write_files
from fishgen.errors import FishgenError
from fishgen.exchange.particles import only_points, particle_chunks, particle_columns
from fishgen.exchange.rest import rest_meshes
from fishgen.exchange.sidefiles import check_shared, image_side_stems
from fishgen.file_names import name_text
from fishgen.scene.model import Scene

VERTEX = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("nx", "<f4"), ("ny", "<f4"),
                   ("nz", "<f4"), ("s", "<f4"), ("t", "<f4")])
FACE = np.dtype([("n", "u1"), ("v", "<i4", (3,))])
_TYPES = {"<f4": "float", "|u1": "uchar", "<i4": "int"}


def _ascii(text: str) -> str:
    # A PLY header is ASCII: non-ASCII names are escaped rather than refused.
    return text.encode("ascii", "backslashreplace").decode("ascii")


def write_ply(scene: Scene, path: Path) -> list[Path]:
    kinds = {prim.mode for _, prim in scene.drawn()}
    if kinds == {"POINTS"}:
        return _write_points(scene, path)
    if "POINTS" in kinds:
        raise FishgenError("expected either triangles or points for one PLY file, found both", path)
    return _write_mesh(scene, path)


def _write_mesh(scene: Scene, path: Path) -> list[Path]:
    meshes = rest_meshes(scene)
    if not meshes:
        raise FishgenError("expected triangles or points to write, found an empty scene", path)
    counts = np.cumsum([0] + [len(m.positions) for m in meshes])
    vertices = np.empty(counts[-1], dtype=VERTEX)
    pos = np.concatenate([m.positions for m in meshes])
    nrm = np.concatenate([m.normals for m in meshes])
    uv = np.concatenate([m.uvs if m.uvs is not None else np.zeros((len(m.positions), 2)) for m in meshes])
    for k, axis in enumerate("xyz"):
        vertices[axis] = pos[:, k]
        vertices["n" + axis] = nrm[:, k]
    vertices["s"] = uv[:, 0]
    vertices["t"] = 1.0 - uv[:, 1]          # PLY readers take t up from the bottom
    # counts holds one offset more than there are meshes (the total)
    faces_idx = np.concatenate([m.faces + c for m, c in zip(meshes, counts, strict=False)])
    faces = np.empty(len(faces_idx), dtype=FACE)
    faces["n"] = 3
    faces["v"] = faces_idx
    image = next((scene.images[m.texture] for m in scene.materials if m.texture is not None), None)
    texture = f"{image_side_stems(path.stem, [image.name])[0]}.png" if image is not None else None
    header = ["ply", "format binary_little_endian 1.0",
              f"comment fishgen {_ascii(scene.name)} rest pose, metres, +Y up"]
    if texture:
        header.append(f"comment TextureFile {name_text(texture)}")
    header += [f"element vertex {len(vertices)}"] + [f"property float {n}" for n in VERTEX.names or ()]
    header += [f"element face {len(faces)}", "property list uchar int vertex_indices", "end_header", ""]
    # The header is ASCII but for a texture's file name, which must be the file's own bytes: UTF-8
    # where the file system's names are, as trimesh (and so fishgen's reader) reads it; "pòisson.ply"
    # was a traceback.
    files = {path: "\n".join(header).encode("utf-8", "surrogateescape") + vertices.tobytes()
             + faces.tobytes()}
    if texture and image is not None:
        files[path.with_name(texture)] = image.encoded()
    check_shared(path, files)
    write_files(files)
    return list(files)


def _write_points(scene: Scene, path: Path) -> list[Path]:
    prim = only_points(scene, path)
    columns = [c for c in particle_columns(prim) if c[0] != "cube"]
    header = ["ply", "format binary_little_endian 1.0",
              f"comment fishgen {_ascii(scene.name)}: particle centre, radius, Gaussian density, colour",
              f"element vertex {prim.vertex_count}"]
    header += [f"property {_TYPES[np.dtype(kind).str]} {name}" for name, _, kind in columns]
    header.append("end_header")
    with atomic_open(path) as handle:
        handle.write(("\n".join(header) + "\n").encode("ascii"))
        for rec in particle_chunks(prim, columns):
            handle.write(rec.data.cast("B"))
    return [path]
