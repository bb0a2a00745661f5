"""Stanford PLY writer: the rest pose as one binary little-endian mesh with normals and UVs."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from fishgen.atomic import write_files

VERTEX = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("nx", "<f4"), ("ny", "<f4"),
                   ("nz", "<f4"), ("s", "<f4"), ("t", "<f4")])
FACE = np.dtype([("n", "u1"), ("v", "<i4", (3,))])


def write_ply(asset, path: Path) -> list[Path]:
    meshes = [m for _, m in asset.rest_meshes()]
    counts = np.cumsum([0] + [len(m.positions) for m in meshes])
    vertices = np.empty(counts[-1], dtype=VERTEX)
    pos = np.concatenate([m.positions for m in meshes])
    nrm = np.concatenate([m.normals for m in meshes])
    uv = np.concatenate([m.uvs for m in meshes])
    for k, axis in enumerate("xyz"):
        vertices[axis] = pos[:, k]
        vertices["n" + axis] = nrm[:, k]
    vertices["s"] = uv[:, 0]
    vertices["t"] = 1.0 - uv[:, 1]          # PLY readers take t up from the bottom
    faces_idx = np.concatenate([m.faces + c for m, c in zip(meshes, counts)])
    faces = np.empty(len(faces_idx), dtype=FACE)
    faces["n"] = 3
    faces["v"] = faces_idx
    texture = f"{path.stem}_skin.png" if "skin" in asset.images else None
    # A PLY header is ASCII: non-ASCII names are escaped rather than refused.
    name = asset.name.encode("ascii", "backslashreplace").decode("ascii")
    header = ["ply", "format binary_little_endian 1.0", f"comment fishgen {name} rest pose, metres, +Y up"]
    if texture:
        header.append(f"comment TextureFile {texture}")
    header += [f"element vertex {len(vertices)}"] + [f"property float {n}" for n in VERTEX.names]
    header += [f"element face {len(faces)}", "property list uchar int vertex_indices", "end_header", ""]
    files = {path: "\n".join(header).encode("ascii") + vertices.tobytes() + faces.tobytes()}
    if texture:
        files[path.with_name(texture)] = asset.images["skin"]
    write_files(files)
    return list(files)
