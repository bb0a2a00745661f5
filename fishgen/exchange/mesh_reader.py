"""Read OBJ (+MTL, textures) and PLY (meshes or particle clouds) into the scene model.

trimesh does the parsing; this module maps what it finds onto preview materials.
OBJ transparency comes from the MTL itself (``d`` below 1: blended; ``map_d``:
a cut-out mask), since trimesh's materials drop those statements. A PLY of
bare vertices is a particle cloud: a ``radius`` property gives each particle's
size, ``density`` its opacity, ``red green blue`` its sRGB colour.

Before trimesh reads anything, sizes are checked by stat against the caps
below (the asset and each side file), a PLY header's element counts against
the bytes really there, and an OBJ's vertex statements for three coordinates.
Every fault is one ``FishgenError`` reading ``expected ..., found ...``.
"""
from __future__ import annotations

import io
import logging
import math
import re
import warnings
from pathlib import Path
from typing import NamedTuple

import numpy as np
from trimesh.resolvers import Resolver

from fishgen.errors import FishgenError, describe, expected
from fishgen.exchange.guards import MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE, check_picture, size_text, what_was_found
from fishgen.exchange.sidefiles import map_file_name, mtl_libraries, side_file
from fishgen.numeric import srgb8_to_linear16, srgb_to_linear
from fishgen.scene.model import Image, Material, Mesh, Node, Primitive, Scene

logging.getLogger("trimesh").addHandler(logging.NullHandler())  # its log is not the user's stderr
logging.getLogger("trimesh").propagate = False

MAX_TEXT_BYTES = 256 * 2**20
"""Largest OBJ or ASCII PLY file (trimesh's text parse takes a few times the file in memory)."""
MAX_BINARY_BYTES = 512 * 2**20
"""Largest binary PLY file."""
MAX_SIDE_BYTES = 64 * 2**20
"""Largest MTL or texture file beside an OBJ or PLY."""
MAX_PLY_HEADER = 2**20
"""Longest PLY header: its ``end_header`` must come within this many bytes."""

_PLY_SIZES = {"char": 1, "uchar": 1, "int8": 1, "uint8": 1, "short": 2, "ushort": 2, "int16": 2,
              "uint16": 2, "int": 4, "uint": 4, "int32": 4, "uint32": 4, "float": 4, "float32": 4,
              "double": 8, "float64": 8}


def read_mesh_file(path: str | Path) -> Scene:
    """Load an .obj or .ply file as a Scene; unreadable files raise FishgenError.

    The whole read is guarded, not only trimesh's parse: a face index past the
    vertices or a broken MTL statement is bad input like any other.
    """
    path = Path(path)
    kind = path.suffix[1:].upper()
    try:
        # a library's own warnings (numpy's overflow, trimesh's log) never reach the user's stderr:
        # what matters about the file becomes this reader's one line
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            return _read(path)
    except FishgenError:
        raise
    except MemoryError:
        raise FishgenError(f"expected a {kind} file that fits in memory, found it does not", path) from None
    except Exception as err:  # trimesh and numpy raise anything from KeyError to IndexError
        raise FishgenError(f"expected a well-formed {kind} file, found {what_was_found(err, kind)}",
                           path) from None


def _stat(path: Path, cap: int, what: str, where: Path) -> int:
    size = path.stat().st_size
    if size > cap:
        raise expected(f"{what} of at most {size_text(cap)}", f"{path.name!r} of {size_text(size)}", where)
    return size


def _decode(data: bytes) -> str:
    """Text of an OBJ or MTL: UTF-8 (a BOM dropped), else Latin-1, which reads any byte."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def _read(path: Path) -> Scene:
    import trimesh

    obj = path.suffix.lower() == ".obj"
    resolver = _FolderResolver(path)
    if obj:
        _stat(path, MAX_TEXT_BYTES, "an OBJ file", path)
        text = _decode(path.read_bytes())
        _check_obj_vertices(text, path)
        alpha = _mtl_alpha(path, text)  # also refuses side files outside the asset's folder
        source = io.BytesIO(text.encode("utf-8"))  # trimesh gets UTF-8 whatever the file's encoding
        loaded = trimesh.load(file_obj=source, file_type="obj", process=False, resolver=resolver,
                              metadata={"file_name": path.name})
    else:
        alpha = {}
        header = _check_ply_header(path)
        try:
            if not header.faces:
                return _point_set(path, header)
            loaded = trimesh.load(str(path), process=False, resolver=resolver)
        except FishgenError:
            raise
        except Exception:  # numpy's "could not be read to its end": said at the line that stopped it
            _ascii_ply_fault(path, header)
            raise
    geoms = loaded.dump(concatenate=False) if isinstance(loaded, trimesh.Scene) else [loaded]
    scene = Scene(name=path.stem, source=str(path))
    for k, geom in enumerate(geoms):
        if isinstance(geom, trimesh.PointCloud):
            prim = _points(geom.vertices, geom.metadata, path, None if obj else header)
        elif isinstance(geom, trimesh.Trimesh) and len(geom.faces):
            prim = _mesh(geom, alpha, path, scene, None if obj else header)
        else:
            continue
        name = str(geom.metadata.get("name") or f"{path.stem}{k}")
        scene.add_node(Node(name=name, mesh=scene.add_mesh(Mesh(name, [prim]))))
    if not scene.meshes:
        if not obj:
            _ascii_ply_fault(path, header)    # a face list shorter than its count reads as no faces
        raise FishgenError("expected triangles or points, found an empty asset", path)
    return scene


class _FolderResolver(Resolver):
    """Hands trimesh the side files it asks for, from the asset's folder only."""

    def __init__(self, asset: Path):
        self.asset = asset

    def get(self, name: str) -> bytes:
        words = name.split()
        target = side_file(self.asset, name)
        if target.is_file():
            return self._read(target)
        if len(words) > 1 and all(w.lower().endswith(".mtl") for w in words):
            # "mtllib a.mtl b.mtl" names several libraries: trimesh gets them as one
            found = [side_file(self.asset, w) for w in words]
            return b"\n".join(self._read(t) for t in found if t.is_file())
        # MTL map statements may reach us with options first ("-imfchan m skin.png").
        if words:
            target = side_file(self.asset, words[-1])
            if target.is_file():
                return self._read(target)
        raise FileNotFoundError(name)

    def _read(self, target: Path) -> bytes:
        _stat(target, MAX_SIDE_BYTES, "a side file", self.asset)
        data = target.read_bytes()
        if target.suffix.lower() == ".mtl":
            data = _decode(data).encode("utf-8")
        return data

    def keys(self):
        return iter(())

    def write(self, name, data):
        raise OSError("a preview writes no side files")

    def namespaced(self, namespace):
        return self


def _check_obj_vertices(text: str, path: Path) -> None:
    """Every ``v`` statement has 3 finite coordinates (then optionally w, or r g b), and every ``f``
    statement 3 corners or more."""
    for m in re.finditer(r"^[ \t]*v[ \t]+([^\n]*)", text, re.M):
        words = m.group(1).split("#", 1)[0].split()
        ok = 3 <= len(words) <= 7
        if ok:
            try:
                ok = all(math.isfinite(float(w)) for w in words)
            except ValueError:
                ok = False
        if not ok:
            line = text.count("\n", 0, m.start()) + 1
            raise expected("a vertex of 3 finite coordinates (v x y z)",
                           describe(m.group(0).strip()), path, line)
    # a face of fewer corners is no face: trimesh drops it, and a file cut off mid-line showed half
    # a fish with no word
    for m in re.finditer(r"^[ \t]*f(?![^ \t\r\n])([^\n]*)", text, re.M):
        if len(m.group(1).split("#", 1)[0].split()) < 3:
            raise expected("a face of 3 or more corners (f a b c)", describe(m.group(0).strip()), path,
                           text.count("\n", 0, m.start()) + 1)


def _mtl_libraries(obj: Path, text: str) -> list[Path]:
    """The MTL files an OBJ's ``mtllib`` statements name (several may share one statement). Each
    must be there: a file an asset names and cannot find is incomplete input, for `preview` and
    `view` alike, as a glTF's missing buffer or image is."""
    out = []
    for match in re.finditer(r"^[ \t]*mtllib[ \t]+(.+?)[ \t]*\r?$", text, re.M):
        lib = match[1]
        for name in mtl_libraries(obj, lib):
            mtl = side_file(obj, name)
            if not mtl.is_file():
                raise FishgenError(f"expected the material library {name!r} the OBJ names, in its folder, "
                                   "found none", obj, text.count("\n", 0, match.start()) + 1)
            out.append(mtl)
    return out


def _mtl_alpha(obj: Path, text: str) -> dict[str, tuple[str, float]]:
    """material name -> (alpha mode, opacity) from the OBJ's MTL libraries.

    Every MTL and texture reference is checked to stay in the OBJ's folder, to be there, and
    their sizes against the caps.
    """
    out: dict[str, tuple[str, float]] = {}
    for mtl in _mtl_libraries(obj, text):
        _stat(mtl, MAX_SIDE_BYTES, "an MTL file", obj)
        name = None
        for number, line in enumerate(_decode(mtl.read_bytes()).splitlines(), 1):
            words = line.split()
            if not words:
                continue
            key = words[0].lower()
            if key in _MAP_KEYS and len(words) > 1:
                named = map_file_name(obj, line.strip()[len(words[0]):])
                image = side_file(obj, named)
                if not image.is_file():
                    raise FishgenError(f"expected the texture {named!r} the MTL names, in the OBJ's "
                                       "folder, found none", mtl, number)
                _stat(image, MAX_SIDE_BYTES, "a texture file", obj)
                if key == "map_kd":  # the one texture decoded: refuse a huge or damaged one now
                    _check_texture(image, mtl, number)
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


def _check_texture(image: Path, where: Path, line: int | None = None) -> None:
    try:
        check_picture(image.read_bytes(), repr(image.name))
    except FishgenError as err:
        raise FishgenError(err.message, where, line) from None


def _named_texture(path: Path, name: str, line: int) -> None:
    """A texture a PLY names (``comment TextureFile``) is read as an OBJ's or a glTF's is: from the
    asset's folder only, and it must be there (trimesh's loader would log a traceback and go on)."""
    target = side_file(path, name)
    if not target.is_file():
        raise FishgenError(f"expected the texture {name!r} the PLY names, in its folder, found none", path,
                           line)


class _PlyHeader(NamedTuple):
    """A checked PLY header: its format, its elements (name, count, and each property's name,
    least bytes and whether it is a list), and where its body starts."""

    fmt: str
    elements: list[tuple[str, int, list[tuple[str, int, bool]]]]
    body: int
    lines: int

    @property
    def faces(self) -> bool:
        return any(name == "face" and count for name, count, _ in self.elements)


def _check_ply_header(path: Path) -> _PlyHeader:
    """Element counts x property sizes must fit in the file, checked before trimesh allocates."""
    with path.open("rb") as f:
        head = f.read(MAX_PLY_HEADER)
    end = re.search(rb"(^|\n)end_header[ \t]*\r?\n", head)
    if not head.startswith(b"ply") or end is None:
        found = "no 'ply' first" if not head.startswith(b"ply") else \
            f"no end_header in its first {size_text(MAX_PLY_HEADER)}"
        raise expected("a PLY header (ply ... end_header)", found, path)
    size = _stat(path, MAX_BINARY_BYTES, "a PLY file", path)
    body = size - end.end()
    fmt = None
    elements: list[tuple[str, int, list[tuple[str, int, bool]]]] = []
    lines = head[: end.end()].decode("latin-1").splitlines()
    for number, line in enumerate(lines, 1):
        words = line.split()
        if len(words) >= 3 and words[:2] == ["comment", "TextureFile"]:
            # its bytes as trimesh reads them: UTF-8 (a name like pòisson_skin.png), else Latin-1
            _named_texture(path, _decode(line.encode("latin-1")).split(None, 2)[2].strip(), number)
        if not words or words[0] in ("ply", "comment", "obj_info", "end_header"):
            continue
        if words[0] == "format":
            if len(words) < 2 or words[1] not in ("ascii", "binary_little_endian", "binary_big_endian"):
                raise expected("format ascii, binary_little_endian or binary_big_endian",
                               describe(line), path, number)
            fmt = words[1]
        elif words[0] == "element":
            if len(words) != 3 or not words[2].isdigit():
                raise expected("element NAME COUNT", describe(line), path, number)
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property":
            if not elements:
                raise expected("an element before its properties", describe(line), path, number)
            if len(words) == 5 and words[1] == "list" and words[2] in _PLY_SIZES and words[3] in _PLY_SIZES:
                elements[-1][2].append((words[4], _PLY_SIZES[words[2]], True))  # at least the count
            elif len(words) == 3 and words[1] in _PLY_SIZES:
                elements[-1][2].append((words[2], _PLY_SIZES[words[1]], False))
            else:
                raise expected("property TYPE NAME or property list TYPE TYPE NAME", describe(line),
                               path, number)
        else:
            raise expected("a PLY header statement", describe(line), path, number)
    if fmt is None:
        raise expected("a format line in the PLY header", "none", path)
    if fmt == "ascii":
        _stat(path, MAX_TEXT_BYTES, "an ASCII PLY file", path)
    need = 0
    for name, count, props in elements:
        # ASCII: each value takes at least a digit and a separator
        need += count * (2 * len(props) if fmt == "ascii" else sum(b for _, b, _ in props))
        if name == "vertex" and count and not {"x", "y", "z"} <= {p for p, _, _ in props}:
            raise expected("vertex properties x, y and z", ", ".join(p for p, _, _ in props) or "none",
                           path)
    header = _PlyHeader(fmt, elements, end.end(), len(lines))
    if need > body:
        _ascii_ply_short(path, header)    # an ASCII file says so at the line it ends
        counts = ", ".join(f"{count:,} {name}" for name, count, _ in elements)
        raise expected(f"at least {need:,} bytes of {fmt} data for {counts}",
                       f"{body:,} bytes after the header", path)
    return header


def _ascii_ply_short(path: Path, header: _PlyHeader) -> None:
    """Raise at the line where an ASCII PLY's body ends short of its elements' rows (one a line),
    counting lines, not reading numbers; return if it holds them all, or the file is binary."""
    if header.fmt != "ascii":
        return
    lines, tail = 0, b""
    with path.open("rb") as f:
        f.seek(header.body)
        while block := f.read(1 << 20):
            lines += block.count(b"\n")
            tail = block[-1:]
    lines += tail not in (b"", b"\n")        # a last line without its newline
    before = 0
    for name, count, props in header.elements:
        if lines < before + count:
            what = f"{name} ({' '.join(p for p, _, _ in props)})"
            raise expected(f"{count:,} rows of {what}", f"the file ending after {lines - before:,}", path,
                           header.lines + lines + 1)
        before += count


def _ascii_ply_fault(path: Path, header: _PlyHeader) -> None:
    """Raise at the first line of an ASCII PLY's body that is not one element's numbers (a comma,
    a word, a list shorter than its count); return if there is none, or the file is binary."""
    if header.fmt != "ascii":
        return
    with path.open("rb") as f:
        f.seek(header.body)
        rows = iter(enumerate(f, header.lines + 1))
        for name, count, props in header.elements:
            what = f"{name} ({' '.join(p for p, _, _ in props)})"
            for _ in range(count):
                number, raw = next(rows, (None, b""))
                if number is None:
                    return  # too few lines: the size check or trimesh says it
                text = raw.decode("latin-1").strip()
                words = text.split()
                try:
                    values = [float(w) for w in words]
                except ValueError:
                    raise expected(f"numbers for a {what}", describe(text),
                                   path, number) from None
                want, at = 0, 0
                for _, _, is_list in props:
                    if is_list and at < len(values):
                        items = values[at]
                        if not math.isfinite(items) or items != int(items) or items < 0:
                            raise expected(f"a whole count before a {name}'s list", describe(text),
                                           path, number)
                        want, at = want + 1 + int(items), at + 1 + int(items)
                    else:
                        want, at = want + 1, at + 1
                if len(values) != want:
                    raise expected(f"{want} numbers for a {what}", f"{len(values)}: {describe(text)}",
                                   path, number)


def _finite(positions: np.ndarray, path: Path, header: _PlyHeader | None = None) -> None:
    """Vertices of three finite coordinates each: what the scene model and every pose assume."""
    if positions.ndim != 2 or positions.shape[1] != 3:
        found = positions.shape[1] if positions.ndim == 2 else positions.ndim
        raise expected("vertices of three coordinates each", f"{found} per vertex as the file was read",
                       path)
    if len(positions) and not np.isfinite(positions).all():
        bad = int(np.argmax(~np.isfinite(positions).all(axis=1)))
        raise expected("finite vertex coordinates", f"{positions[bad].tolist()} at vertex {bad + 1}", path,
                       _vertex_line(header, bad))


def _vertex_line(header: _PlyHeader | None, index: int) -> int | None:
    """The line of an ASCII PLY's vertex ``index`` (from 0), one element row a line; None for binary."""
    if header is None or header.fmt != "ascii":
        return None
    before = 0
    for name, count, _ in header.elements:
        if name == "vertex":
            return header.lines + 1 + before + index
        before += count
    return None


def _mesh(geom, alpha: dict[str, tuple[str, float]], path: Path, scene: Scene,
          header: _PlyHeader | None = None) -> Primitive:
    positions = np.asarray(geom.vertices, np.float32)
    _finite(positions, path, header)
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
        if path.suffix.lower() == ".ply":
            # PLY names a texture but no colour; trimesh's own default grey (102) darkened it 2.5x
            diffuse = None
        rgba = np.asarray(diffuse if diffuse is not None else [255] * 4, np.float32).ravel()
        rgba = rgba / 255.0 if rgba.max() > 1.0 else rgba
        rgb = srgb_to_linear(rgba[:3])  # MTL Kd is authored as a display (sRGB) colour
        name = getattr(mat, "name", None) or ""
        mode, opacity = alpha.get(name, ("OPAQUE", 1.0))
        texture = None
        if image is not None and "TEXCOORD_0" in attributes:
            _check_size(image, path)
            texture = scene.add_image(Image(name or "texture", b"",
                                            pixels=np.asarray(image.convert("RGBA"))))
        material = scene.add_material(Material(name or f"material{len(scene.materials)}",
                                               (*map(float, rgb), float(opacity)), texture, mode,  # type: ignore[arg-type]
                                               double_sided=mode != "OPAQUE"))
    elif visual.kind == "vertex":
        c = np.asarray(visual.vertex_colors, np.float32) / 255.0
        attributes["COLOR_0"] = np.hstack([srgb_to_linear(c[:, :3]), c[:, 3:4]])
    return Primitive(attributes, faces.astype(np.uint32), material)


def _check_size(image, path: Path) -> None:
    """A texture trimesh opened (lazily) is refused over the readers' image caps before decoding."""
    width, height = image.size
    if width > MAX_IMAGE_SIDE or height > MAX_IMAGE_SIDE or width * height > MAX_IMAGE_PIXELS:
        raise expected(f"a texture of at most {MAX_IMAGE_SIDE} px a side and {MAX_IMAGE_PIXELS:,} pixels",
                       f"{width}x{height}", path)


def _point_set(path: Path, header: _PlyHeader | None = None) -> Scene:
    """A PLY of vertices alone, parsed by trimesh's PLY reader without its point cloud: building
    one (its colour visuals) took 10 of a 10^7-particle cloud's 13.5 s."""
    from trimesh.exchange.ply import load_ply

    with path.open("rb") as handle:
        loaded = load_ply(handle)
    if not len(loaded.get("vertices", ())):
        raise FishgenError("expected triangles or points, found an empty asset", path)
    declared = None if header is None else {name: n for name, n, _ in header.elements}.get("vertex")
    if header is not None and declared is not None and declared != len(loaded["vertices"]):
        # an ASCII body of several rows a line read as fewer vertices, silently
        _ascii_ply_fault(path, header)
        raise expected(f"{declared:,} vertices, as the header says", f"{len(loaded['vertices']):,}", path)
    scene = Scene(name=path.stem, source=str(path))
    name = f"{path.stem}0"
    prim = _points(loaded["vertices"], loaded.get("metadata", {}), path, header)
    scene.add_node(Node(name=name, mesh=scene.add_mesh(Mesh(name, [prim]))))
    return scene


def _points(vertices, metadata: dict, path: Path, header: _PlyHeader | None = None) -> Primitive:
    positions = np.asarray(vertices, np.float32)
    _finite(positions, path, header)
    columns = _ply_columns(metadata.get("_ply_raw", {}).get("vertex", {}).get("data"))
    for name in ("radius", "red", "green", "blue", "density"):
        if name in columns and columns[name].dtype.kind == "f" and not np.isfinite(columns[name]).all():
            bad = int(np.argmax(~np.isfinite(columns[name])))
            raise expected(f"finite {name} values", f"{columns[name][bad]} at vertex {bad + 1}", path,
                           _vertex_line(header, bad))
    attributes = {"POSITION": positions}
    if "radius" in columns:
        attributes["_RADIUS"] = columns["radius"].astype(np.float32)
    rgb_names = ("red", "green", "blue")
    if all(k in columns and columns[k].dtype == np.uint8 for k in rgb_names):
        # sRGB bytes (what fishgen and most tools write): linear 16-bit through a table, as fishgen's
        # own clouds carry it. The float path took 7 s of a 10^7-particle PLY's 18 s load, and read
        # bytes of at most 1 (a dark cloud) as floats of 0 to 1.
        rgb8 = np.empty((len(positions), 3), np.uint8)
        for j, k in enumerate(rgb_names):
            rgb8[:, j] = columns[k]
        attributes["COLOR_0"] = srgb8_to_linear16()[rgb8]
    elif all(k in columns for k in rgb_names):
        kinds = {columns[k].dtype for k in rgb_names}
        rgb = np.stack([columns[k] for k in rgb_names], 1).astype(np.float32)
        if all(kind.kind in "ui" for kind in kinds):     # whole numbers: of their type's full range
            scale = float(max(np.iinfo(kind).max for kind in kinds))
        else:                                             # floats: 0 to 1, or 0 to 255 as some write
            scale = 255.0 if rgb.max() > 1 else 1.0
        rgba = np.ones((len(positions), 4), np.float32)
        rgba[:, :3] = srgb_to_linear(np.clip(rgb / scale, 0, 1))
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
