"""Wavefront OBJ writer: rest pose, one ``o`` group per part, with .mtl and texture PNG."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from fishgen.atomic import write_files


def _rows(prefix: str, values: np.ndarray, fmt: str = "%.6f") -> str:
    """All rows in one C-level formatting pass (a per-row Python loop is 5x slower)."""
    if len(values) == 0:
        return ""
    row = prefix + (" " + fmt) * values.shape[1] + "\n"
    return (row * len(values) % tuple(values.ravel().tolist()))[:-1]


def _face_rows(faces: np.ndarray) -> str:
    """``f a/a/a b/b/b c/c/c`` rows: position, texture and normal share one index."""
    if len(faces) == 0:
        return ""
    row = "f %d/%d/%d %d/%d/%d %d/%d/%d\n"
    return (row * len(faces) % tuple(np.repeat(faces, 3, axis=1).ravel().tolist()))[:-1]


def write_obj(asset, path: Path) -> list[Path]:
    stem = path.stem
    mtl_name = f"{stem}.mtl"
    textures = {key: f"{stem}_{key}.png" for key in asset.images}
    lines = [f"# fishgen: {asset.name} (rest pose, metres, +Y up, head towards +Z)", f"mtllib {mtl_name}"]
    offset = 0
    for part, mesh in asset.rest_meshes():
        n = len(mesh.positions)
        uv = mesh.uvs.copy()
        uv[:, 1] = 1.0 - uv[:, 1]          # OBJ's texture origin is bottom-left
        face_rows = _face_rows(mesh.faces + offset + 1)
        lines += [f"o {part.name}", _rows("v", mesh.positions), _rows("vt", uv), _rows("vn", mesh.normals),
                  f"usemtl {part.material}", "s 1", face_rows]
        offset += n
    mtl = []
    for name, mat in asset.materials.items():
        r, g, b, a = mat.base_color
        mtl += [f"newmtl {name}", f"Kd {r:.6f} {g:.6f} {b:.6f}", "Ka 0 0 0", "Ks 0.04 0.04 0.04",
                f"d {a:.6f}", "illum 2"]
        if mat.texture is not None:
            mtl.append(f"map_Kd {textures[mat.texture]}")
            if mat.alpha_mode == "MASK":
                mtl.append(f"map_d -imfchan m {textures[mat.texture]}")
        mtl.append("")
    files = {path: ("\n".join(lines) + "\n").encode(), path.with_name(mtl_name): "\n".join(mtl).encode()}
    for key, name in textures.items():
        files[path.with_name(name)] = asset.images[key]
    write_files(files)
    return list(files)
