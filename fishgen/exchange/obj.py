"""Wavefront OBJ writer: the scene's rest pose, one ``o`` group per drawn mesh, with .mtl and images."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from fishgen.atomic import write_files
from fishgen.exchange.rest import rest_meshes
from fishgen.exchange.sidefiles import check_shared, image_side_stems
from fishgen.file_names import name_text
from fishgen.scene.model import Scene


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


def _alpha_png(rgba: np.ndarray) -> bytes:
    """The alpha channel of an RGBA picture as a greyscale PNG (white = opaque)."""
    import io

    from PIL import Image

    out = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgba[..., 3]), "L").save(out, format="PNG")
    return out.getvalue()


def write_obj(scene: Scene, path: Path) -> list[Path]:
    stem = path.stem
    mtl_name = f"{stem}.mtl"
    stems = image_side_stems(stem, [image.name for image in scene.images])
    textures = {k: f"{side}.png" for k, side in enumerate(stems)}
    lines = [f"# fishgen: {scene.name} (rest pose, metres, +Y up, head towards +Z)",
             f"mtllib {name_text(mtl_name)}"]
    offset = 0
    for part in rest_meshes(scene):
        uv = part.uvs if part.uvs is not None else np.zeros((len(part.positions), 2))
        uv = uv.astype(np.float64)
        uv[:, 1] = 1.0 - uv[:, 1]          # OBJ's texture origin is bottom-left
        material = scene.materials[part.material].name if part.material is not None else "default"
        lines += [f"o {part.name}", _rows("v", part.positions), _rows("vt", uv), _rows("vn", part.normals),
                  f"usemtl {material}", "s 1", _face_rows(part.faces + offset + 1)]
        offset += len(part.positions)
    masks = {mat.texture: f"{stems[mat.texture]}_mask.png" for mat in scene.materials
             if mat.texture is not None and mat.alpha_mode == "MASK"}
    mtl = []
    for mat in scene.materials:
        r, g, b, a = mat.base_color
        mtl += [f"newmtl {mat.name}", f"Kd {r:.6f} {g:.6f} {b:.6f}", "Ka 0 0 0", "Ks 0.04 0.04 0.04",
                f"d {a:.6f}", "illum 2"]
        if mat.texture is not None:
            mtl.append(f"map_Kd {name_text(textures[mat.texture])}")
            if mat.alpha_mode == "MASK":
                # A separate greyscale picture: three.js's MTLLoader reads no `-imfchan` option (it
                # asked for a file named "-imfchan m ...") and every reader takes map_d's grey as alpha.
                mtl.append(f"map_d {name_text(masks[mat.texture])}")
        mtl.append("")
    # the names' bytes are the file system's (name_text), the rest UTF-8
    files = {path: ("\n".join(lines) + "\n").encode("utf-8", "surrogateescape"),
             path.with_name(mtl_name): "\n".join(mtl).encode("utf-8", "surrogateescape")}
    for k, name in textures.items():
        files[path.with_name(name)] = scene.images[k].encoded()
    for k, name in masks.items():
        files[path.with_name(name)] = _alpha_png(scene.images[k].rgba())
    check_shared(path, files)
    write_files(files)
    return list(files)
