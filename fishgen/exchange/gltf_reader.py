"""Read a glTF 2.0 asset (.glb / .gltf, or GLB bytes) into the scene model.

The reader parses the GLB container and the JSON itself and decodes the
accessors itself, so that alpha modes, double-sidedness, POINTS primitives
with ``_RADIUS``, skins, morph targets and every animation channel survive
(general mesh loaders drop some of them). Side files are read only from the
asset's own folder.

Everything read is checked against the glTF 2.0 rules before the scene is
built (the renderer and the posing code only ever see a well-formed scene):
indices in range, node trees without cycles or second parents, the sizes of
TRS, matrices and colour factors, accessor types and counts per semantic,
animation sampler counts, skins, morph targets and finite numbers. Declared
sizes are checked against the bytes really there, and against the caps below,
before anything is read or allocated. Every fault is one ``FishgenError``
reading ``expected ..., found ...``.
"""
from __future__ import annotations

import base64
import binascii
import io
import json
import math
import struct
import warnings
from pathlib import Path
from typing import Any, cast

import numpy as np

from fishgen.errors import FishgenError, describe
from fishgen.exchange.sidefiles import side_file
from fishgen.scene.model import (
    INTERPOLATIONS,
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

MAX_FILE_BYTES = 512 * 2**20
"""Largest .glb/.gltf file, and largest buffer or image side file, checked by stat before reading."""
MAX_JSON_BYTES = 128 * 2**20
"""Largest JSON part (a .gltf file, or a GLB's JSON chunk)."""
MAX_JSON_ITEMS = 2_000_000
"""Most JSON arrays, objects and commas: a few hundred MB of Python objects at worst."""
MAX_DATA_URI_CHARS = 64 * 2**20
"""Longest ``data:`` URI (buffer or image), checked before decoding."""
MAX_ELEMENTS = 2**26
"""Most accessor components (count x components, summed over every accessor) in one file."""
MAX_IMAGE_SIDE = 8192
"""Widest or tallest texture image, read from its header before any decoding."""
MAX_IMAGE_PIXELS = 2**26
"""Most pixels of one texture image (256 MiB as RGBA)."""

SUPPORTED_EXTENSIONS = frozenset({"KHR_materials_unlit"})
"""Extensions the reader understands; a file that requires any other one is refused."""

_DTYPES: dict[int, type[np.number]] = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16,
           5125: np.uint32, 5126: np.float32}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
_MODES: dict[int, PrimitiveMode] = {0: "POINTS", 4: "TRIANGLES", 5: "TRIANGLES", 6: "TRIANGLES"}
_FLOAT = 5126
_UNORM = (5121, 5123)   # unsigned byte / short, used normalized
_PATH_TYPES = {"translation": "VEC3", "rotation": "VEC4", "scale": "VEC3", "weights": "SCALAR"}
_PATH_COMPONENTS = {"translation": (_FLOAT,), "scale": (_FLOAT,),
                    "rotation": (_FLOAT, 5120, 5121, 5122, 5123), "weights": (_FLOAT, 5120, 5121, 5122, 5123)}
_GLB_MAGIC, _CHUNK_JSON, _CHUNK_BIN = b"glTF", 0x4E4F534A, 0x004E4942
_NOT_GLTF = "a glTF 2.0 file (JSON, or GLB with a 12-byte header)"
_IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]


def read_gltf(path: str | Path | None = None, *, data: bytes | None = None,
              label: str | None = None, **_) -> Scene:
    """Load a .glb/.gltf file (or GLB ``data``) as a Scene; bad files raise FishgenError."""
    where = str(path) if path is not None else "<glb>"
    try:
        if data is None:
            if path is None:
                raise FishgenError("expected a file or GLB bytes to read, found neither")
            data = _read_capped(Path(path), where)
        doc, blob = _split(data, where)
        del data  # the BIN chunk is a view; a .gltf's text is no longer needed
        reader = _Reader(doc, blob, Path(path) if path is not None else None, where)
        return reader.scene(label if label is not None else (Path(path).stem if path else ""))
    except FishgenError as err:
        if err.file is None:
            err.file = where
            err.args = (str(err),)
        raise
    except MemoryError:
        raise FishgenError("expected an asset that fits in memory, found it does not", where) from None
    except Exception as err:  # a fault the checks above missed: still one line, never a traceback
        raise FishgenError(f"expected a well-formed glTF 2.0 asset, found {type(err).__name__}: "
                           f"{one_line(err)}", where) from None


def one_line(err: BaseException, limit: int = 200) -> str:
    """A library's error message squeezed onto one short line for ours."""
    text = " ".join(str(err).split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


def size_text(n: int) -> str:
    """A byte count for a message: ``564 bytes``, ``2.0 GiB``."""
    if n < 2**20:
        return f"{n:,} bytes"
    return f"{n / 2**30:.1f} GiB" if n >= 2**30 else f"{n / 2**20:.1f} MiB"


def _fail(what: str, found: str) -> FishgenError:
    return FishgenError(f"expected {what}, found {found}")


def _read_capped(path: Path, where: str) -> bytes:
    try:
        size = path.stat().st_size
    except OSError as err:
        raise FishgenError(f"expected a readable file, found {type(err).__name__}", where) from None
    if size > MAX_FILE_BYTES:
        raise _fail(f"a glTF file of at most {size_text(MAX_FILE_BYTES)}", size_text(size))
    if size > MAX_JSON_BYTES:  # only a GLB may be this big: its bulk is binary
        with path.open("rb") as f:
            if f.read(4) != _GLB_MAGIC:
                raise _fail(f"a glTF JSON file of at most {size_text(MAX_JSON_BYTES)} "
                            "(keep big data in .bin files or a .glb)", size_text(size))
    return path.read_bytes()


def _split(data: bytes, where: str) -> tuple[dict, memoryview | None]:
    """The JSON document and the GLB BIN chunk (None for a .gltf)."""
    if bytes(data[:4]) != _GLB_MAGIC:
        return _parse_json(data), None
    if len(data) < 12:
        raise _fail(_NOT_GLTF, f"{len(data)} bytes")
    _, version, length = struct.unpack_from("<4sII", data)
    if version != 2:
        raise _fail("a GLB of version 2", f"version {version}")
    if length != len(data):
        raise _fail(f"a GLB of {length:,} bytes, as its header says", f"{len(data):,} bytes")
    view = memoryview(data)
    chunks: list[tuple[int, memoryview]] = []
    offset = 12
    while offset < length:
        if offset + 8 > length:
            raise _fail("an 8-byte GLB chunk header", f"{length - offset} bytes at byte {offset}")
        clen, ctype = struct.unpack_from("<II", data, offset)
        if offset + 8 + clen > length:
            raise _fail(f"a GLB chunk of {clen:,} bytes within the file",
                        f"{length - offset - 8:,} bytes left at byte {offset}")
        chunks.append((ctype, view[offset + 8: offset + 8 + clen]))
        offset += 8 + clen
    if not chunks or chunks[0][0] != _CHUNK_JSON:
        raise _fail("a JSON chunk first in the GLB",
                    "none" if not chunks else f"chunk type {chunks[0][0]:#x}")
    if len(chunks[0][1]) > MAX_JSON_BYTES:
        raise _fail(f"a JSON chunk of at most {size_text(MAX_JSON_BYTES)}", size_text(len(chunks[0][1])))
    blob = chunks[1][1] if len(chunks) > 1 and chunks[1][0] == _CHUNK_BIN else None
    return _parse_json(bytes(chunks[0][1])), blob


def _no_constant(name: str) -> Any:
    raise _fail("finite JSON numbers", name)


def _parse_json(raw: bytes) -> dict:
    if len(raw) > MAX_JSON_BYTES:
        raise _fail(f"a glTF JSON document of at most {size_text(MAX_JSON_BYTES)}", size_text(len(raw)))
    items = raw.count(b",") + raw.count(b"[") + raw.count(b"{")
    if items > MAX_JSON_ITEMS:
        raise _fail(f"a JSON document of at most {MAX_JSON_ITEMS:,} items", f"{items:,}")
    try:
        text = bytes(raw).decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise _fail(_NOT_GLTF, f"bytes that are not UTF-8 at byte {err.start}") from None
    try:
        doc = json.loads(text, parse_constant=_no_constant)
    except json.JSONDecodeError as err:
        raise _fail(_NOT_GLTF, f"invalid JSON at line {err.lineno} column {err.colno} ({err.msg})") from None
    except RecursionError:
        raise _fail(_NOT_GLTF, "JSON nested too deeply") from None
    if not isinstance(doc, dict):
        raise _fail(f"{_NOT_GLTF} holding a JSON object", f"a JSON {type(doc).__name__}")
    return doc


# -- JSON shape checks ---------------------------------------------------------------
def _show(value: Any) -> str:
    """A JSON value for a message, short."""
    if isinstance(value, bool) or value is None:
        return json.dumps(value)
    if isinstance(value, str):
        return describe(value)
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, list):
        if len(value) <= 6 and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            return json.dumps(value)
        return f"a list of {len(value)} items"
    return "an object" if isinstance(value, dict) else type(value).__name__


def _is_int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_num(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _obj(value: Any, where: str) -> dict:
    if not isinstance(value, dict):
        raise _fail(f"an object at {where}", _show(value))
    return value


def _list(d: dict, key: str, where: str) -> list:
    value = d.get(key, [])
    if not isinstance(value, list):
        raise _fail(f"a list at {where}.{key}", _show(value))
    return value


def _int(d: dict, key: str, where: str, default: int | None = None, lo: int = 0,
         hi: int | None = None) -> int:
    value: Any = d.get(key, default)
    if not _is_int(value) or value < lo or (hi is not None and value > hi):
        span = f"from {lo} to {hi}" if hi is not None else f"of at least {lo}"
        raise _fail(f"an integer {span} at {where}.{key}", "none" if value is None else _show(value))
    return cast(int, value)


def _index(d: dict, key: str, where: str, kind: str, count: int, required: bool = False) -> int | None:
    value = d.get(key)
    if value is None and not required:
        return None
    return _ref(value, f"{where}.{key}", kind, count)


def _ref(value: Any, where: str, kind: str, count: int) -> int:
    if not _is_int(value) or not 0 <= value < count:
        span = f"from 0 to {count - 1}" if count else f"(the file has no {kind}s)"
        raise _fail(f"a {kind} index {span} at {where}", "none" if value is None else _show(value))
    return cast(int, value)


def _numbers(d: dict, key: str, where: str, n: int | None) -> list[float] | None:
    value = d.get(key)
    if value is None:
        return None
    if not isinstance(value, list) or (n is not None and len(value) != n) or not all(map(_is_num, value)):
        what = f"{n} finite numbers" if n is not None else "a list of finite numbers"
        if isinstance(value, list) and n is not None and len(value) != n:
            found = f"{len(value)} numbers"
        else:
            found = _show(value)
        raise _fail(f"{what} at {where}.{key}", found)
    return [float(v) for v in value]


def _enum(d: dict, key: str, where: str, choices: tuple[str, ...], default: str) -> str:
    value = d.get(key, default)
    if value not in choices:
        raise _fail(f"one of {', '.join(choices)} at {where}.{key}", _show(value))
    return cast(str, value)


def _bool(d: dict, key: str, where: str) -> bool:
    value = d.get(key, False)
    if not isinstance(value, bool):
        raise _fail(f"true or false at {where}.{key}", _show(value))
    return value


def _mime(img: dict) -> str:
    mime = img.get("mimeType")
    return mime if isinstance(mime, str) else "image/png"


def _name(d: dict, fallback: str) -> str:
    name = d.get("name")
    return name if isinstance(name, str) and name else fallback


class _Reader:
    """Checks the document, then builds the scene from it."""

    def __init__(self, doc: dict, blob: memoryview | None, asset: Path | None, where: str):
        self.doc, self.blob, self.asset, self.where = doc, blob, asset, where
        self._buffers: dict[int, bytes | memoryview] = {}
        self._files: dict[int, Path] = {}
        self.lists: dict[str, list[dict]] = {}
        self.elements = 0
        self.targets: list[int] = []   # morph target count of each mesh
        self.textured: set[int] = set()  # images the renderer decodes (base colour textures)
        self._check()

    def count(self, kind: str) -> int:
        return len(self.lists[kind])

    # -- checks of the document --------------------------------------------------
    def _check(self) -> None:
        doc = self.doc
        asset = _obj(doc.get("asset"), "asset")
        version = asset.get("version")
        if not isinstance(version, str) or version.split(".")[0] != "2":
            raise _fail('asset.version "2.0"', "none" if version is None else _show(version))
        required = _list(doc, "extensionsRequired", "document")
        unknown = [e for e in required if e not in SUPPORTED_EXTENSIONS]
        if unknown:
            raise _fail("no required extension but " + ", ".join(sorted(SUPPORTED_EXTENSIONS)),
                        _show(unknown[0]) if len(unknown) == 1 else ", ".join(map(_show, unknown)))
        for kind in ("accessors", "animations", "buffers", "bufferViews", "images", "materials", "meshes",
                     "nodes", "samplers", "scenes", "skins", "textures", "cameras"):
            items = _list(doc, kind, "document")
            for k, item in enumerate(items):
                _obj(item, f"{kind}[{k}]")
            self.lists[kind] = items
        for k, b in enumerate(self.lists["buffers"]):
            self._check_buffer(k, b)
        for k, v in enumerate(self.lists["bufferViews"]):
            self._check_view(k, v)
        for k, a in enumerate(self.lists["accessors"]):
            self._check_accessor(k, a)
        for k, img in enumerate(self.lists["images"]):
            self._check_image_ref(k, img)
        for k, t in enumerate(self.lists["textures"]):
            _index(t, "source", f"textures[{k}]", "image", self.count("images"))
            _index(t, "sampler", f"textures[{k}]", "sampler", self.count("samplers"))
        for k, m in enumerate(self.lists["materials"]):
            self._check_material(k, m)
        for k, m in enumerate(self.lists["meshes"]):
            self._check_mesh(k, m)
        self._check_nodes()
        for k, s in enumerate(self.lists["skins"]):
            self._check_skin(k, s)
        for k, s in enumerate(self.lists["scenes"]):
            where = f"scenes[{k}]"
            nodes = [_ref(n, f"{where}.nodes[{j}]", "node", self.count("nodes"))
                     for j, n in enumerate(_list(s, "nodes", where))]
            if len(set(nodes)) != len(nodes):
                raise _fail(f"each node once at {where}.nodes", "a node listed twice")
            for n in nodes:
                if n in self.parent:
                    raise _fail(f"only root nodes at {where}.nodes",
                                f"node {n}, a child of node {self.parent[n]}")
        if self.lists["scenes"]:
            _index(doc, "scene", "document", "scene", self.count("scenes"))
        for k, a in enumerate(self.lists["animations"]):
            self._check_animation(k, a)

    def _check_buffer(self, k: int, b: dict) -> None:
        where = f"buffers[{k}]"
        length = _int(b, "byteLength", where, lo=1)
        uri = b.get("uri")
        if uri is None:
            if k != 0 or self.blob is None:
                raise _fail(f"a uri at {where} (only a GLB's first buffer may omit it)", "none")
            if not length <= len(self.blob) <= length + 3:
                raise _fail(f"a GLB BIN chunk of {length:,} bytes for {where}", f"{len(self.blob):,} bytes")
            return
        found = self._sized_uri(uri, where, "a buffer")
        if found is None:
            return
        target, size = found
        if size != length:
            raise _fail(f"{length:,} bytes in {describe(uri)} ({where}.byteLength)", f"{size:,} bytes")
        self._files[k] = target

    def _sized_uri(self, uri: Any, where: str, what: str) -> tuple[Path, int] | None:
        """Check a buffer's or image's URI against the caps by its length or its file's stat size,
        before anything is read: (side file, size), or None for an inline data: URI."""
        if not isinstance(uri, str):
            raise _fail(f"a URI string at {where}.uri", _show(uri))
        if uri.strip().startswith("data:"):
            if len(uri) > MAX_DATA_URI_CHARS:
                raise _fail(f"a data URI of at most {size_text(MAX_DATA_URI_CHARS)} at {where}",
                            size_text(len(uri)))
            return None
        target = self._side(uri)
        size = target.stat().st_size
        if size > MAX_FILE_BYTES:
            raise _fail(f"{what} file of at most {size_text(MAX_FILE_BYTES)} at {where}",
                        f"{describe(uri)} of {size_text(size)}")
        return target, size

    def _side(self, uri: str) -> Path:
        if self.asset is None:  # GLB bytes from memory have no folder to take side files from
            raise _fail("only embedded data", f"a reference to {describe(uri)}")
        # Only files in the asset's folder (glTF URIs are percent-encoded: "my%20skin.png").
        target = side_file(self.asset, uri, uri=True)
        if not target.is_file():
            raise _fail("a file beside the asset", f"no {uri!r}")
        return target

    def _check_view(self, k: int, v: dict) -> None:
        where = f"bufferViews[{k}]"
        buf = _index(v, "buffer", where, "buffer", self.count("buffers"), required=True)
        offset = _int(v, "byteOffset", where, 0)
        length = _int(v, "byteLength", where, lo=1)
        stride = v.get("byteStride")
        if stride is not None and (not _is_int(stride) or not 4 <= stride <= 252 or stride % 4):
            raise _fail(f"a byteStride from 4 to 252, a multiple of 4, at {where}", _show(stride))
        size = self.lists["buffers"][cast(int, buf)]["byteLength"]
        if offset + length > size:
            raise _fail(f"{where} (bytes {offset:,} to {offset + length:,}) within buffer {buf} "
                        f"of {size:,} bytes", f"{offset + length - size:,} bytes past its end")

    def _check_accessor(self, k: int, a: dict) -> None:
        where = f"accessors[{k}]"
        ctype = a.get("componentType")
        if ctype not in _DTYPES:
            raise _fail(f"a componentType of {', '.join(map(str, _DTYPES))} at {where}", _show(ctype))
        kind = _enum(a, "type", where, tuple(_WIDTH), "")
        count = _int(a, "count", where, lo=1)
        _bool(a, "normalized", where)
        width = _WIDTH[kind]
        view = _index(a, "bufferView", where, "bufferView", self.count("bufferViews"))
        if view is not None:
            item = np.dtype(_DTYPES[ctype]).itemsize * width
            self._fits(where, view, _int(a, "byteOffset", where, 0), count, item, strided=True)
        self.elements += count * width
        if self.elements > MAX_ELEMENTS:
            raise _fail(f"at most {MAX_ELEMENTS:,} accessor components in the file",
                        f"more by {where} (count {count:,} of {kind})")
        sparse = a.get("sparse")
        if sparse is not None:
            sw = f"{where}.sparse"
            _obj(sparse, sw)
            n = _int(sparse, "count", sw, lo=1, hi=count)
            self.elements += n * (1 + width)
            if self.elements > MAX_ELEMENTS:
                raise _fail(f"at most {MAX_ELEMENTS:,} accessor components in the file", f"more by {sw}")
            idx = _obj(sparse.get("indices"), f"{sw}.indices")
            if idx.get("componentType") not in (5121, 5123, 5125):
                raise _fail(f"a componentType of 5121, 5123 or 5125 at {sw}.indices",
                            _show(idx.get("componentType")))
            for part, item in ((idx, np.dtype(_DTYPES[idx["componentType"]]).itemsize),
                               (_obj(sparse.get("values"), f"{sw}.values"),
                                np.dtype(_DTYPES[ctype]).itemsize * width)):
                pw = f"{sw}.{'indices' if part is idx else 'values'}"
                pv = _index(part, "bufferView", pw, "bufferView", self.count("bufferViews"), required=True)
                self._fits(pw, cast(int, pv), _int(part, "byteOffset", pw, 0), n, item, strided=False)

    def _fits(self, where: str, view: int, offset: int, count: int, item: int, strided: bool) -> None:
        v = self.lists["bufferViews"][view]
        stride = (v.get("byteStride") if strided else None) or item
        if stride < item:
            raise _fail(f"a byteStride of at least {item} (one element) for {where}",
                        f"{stride} in bufferView {view}")
        end = offset + stride * (count - 1) + item
        if end > v["byteLength"]:
            raise _fail(f"{where} ({count:,} elements of {item} bytes from byte {offset:,}) "
                        f"within bufferView {view} of {v['byteLength']:,} bytes",
                        f"{end:,} bytes needed")

    def _check_image_ref(self, k: int, img: dict) -> None:
        where = f"images[{k}]"
        uri, view = img.get("uri"), _index(img, "bufferView", where, "bufferView", self.count("bufferViews"))
        if (uri is None) == (view is None):
            raise _fail(f"either a uri or a bufferView at {where}", "both" if view is not None else "neither")
        if uri is not None:
            self._sized_uri(uri, where, "an image")

    def _texture_ref(self, info: Any, where: str) -> int | None:
        if info is None:
            return None
        _obj(info, where)
        t = cast(int, _index(info, "index", where, "texture", self.count("textures"), required=True))
        _int(info, "texCoord", where, 0)
        return t

    def _check_material(self, k: int, m: dict) -> None:
        where = f"materials[{k}]"
        pbr = m.get("pbrMetallicRoughness")
        if pbr is not None:
            pw = f"{where}.pbrMetallicRoughness"
            _obj(pbr, pw)
            _numbers(pbr, "baseColorFactor", pw, 4)
            for key in ("metallicFactor", "roughnessFactor"):
                if key in pbr and not _is_num(pbr[key]):
                    raise _fail(f"a finite number at {pw}.{key}", _show(pbr[key]))
            t = self._texture_ref(pbr.get("baseColorTexture"), f"{pw}.baseColorTexture")
            if t is not None:
                source = self.lists["textures"][t].get("source")
                if source is not None:
                    self.textured.add(source)
            self._texture_ref(pbr.get("metallicRoughnessTexture"), f"{pw}.metallicRoughnessTexture")
        for key in ("normalTexture", "occlusionTexture", "emissiveTexture"):
            self._texture_ref(m.get(key), f"{where}.{key}")
        _numbers(m, "emissiveFactor", where, 3)
        _enum(m, "alphaMode", where, ("OPAQUE", "MASK", "BLEND"), "OPAQUE")
        cutoff = m.get("alphaCutoff")
        if cutoff is not None and (not _is_num(cutoff) or cutoff < 0):
            raise _fail(f"a finite alphaCutoff of at least 0 at {where}", _show(cutoff))
        _bool(m, "doubleSided", where)
        if not isinstance(m.get("extensions", {}), dict):
            raise _fail(f"an object at {where}.extensions", _show(m["extensions"]))

    def _acc(self, i: int) -> dict:
        return self.lists["accessors"][i]

    def _check_semantic(self, name: str, i: int, where: str, n: int | None) -> None:
        a = self._acc(i)
        kind, ctype, norm = a["type"], a["componentType"], a.get("normalized", False)
        ok = True
        want = ""
        if name in ("POSITION", "NORMAL"):
            ok, want = kind == "VEC3" and ctype == _FLOAT, "VEC3 of floats (5126)"
        elif name == "TANGENT":
            ok, want = kind == "VEC4" and ctype == _FLOAT, "VEC4 of floats (5126)"
        elif name.startswith("TEXCOORD_"):
            ok = kind == "VEC2" and (ctype == _FLOAT or (ctype in _UNORM and norm))
            want = "VEC2 of floats, or of normalized unsigned bytes or shorts"
        elif name.startswith("COLOR_"):
            ok = kind in ("VEC3", "VEC4") and (ctype == _FLOAT or (ctype in _UNORM and norm))
            want = "VEC3 or VEC4 of floats, or of normalized unsigned bytes or shorts"
        elif name.startswith("JOINTS_"):
            ok, want = kind == "VEC4" and ctype in _UNORM and not norm, "VEC4 of unsigned bytes or shorts"
        elif name.startswith("WEIGHTS_"):
            ok = kind == "VEC4" and (ctype == _FLOAT or (ctype in _UNORM and norm))
            want = "VEC4 of floats, or of normalized unsigned bytes or shorts"
        elif name in ("_RADIUS", "_DENSITY"):
            ok, want = kind == "SCALAR", "SCALAR"
        if not ok:
            raise _fail(f"{name} as {want} at {where}",
                        f"accessor {i}: {kind} of componentType {ctype}{' normalized' if norm else ''}")
        if n is not None and a["count"] != n:
            raise _fail(f"{n:,} {name} values (one per POSITION) at {where}",
                        f"{a['count']:,} (accessor {i})")

    def _check_mesh(self, k: int, m: dict) -> None:
        where = f"meshes[{k}]"
        prims = _list(m, "primitives", where)
        if not prims:
            raise _fail(f"at least one primitive at {where}", "none")
        counts = []
        for j, p in enumerate(prims):
            pw = f"{where}.primitives[{j}]"
            _obj(p, pw)
            attrs = _obj(p.get("attributes"), f"{pw}.attributes")
            for name, i in attrs.items():
                _ref(i, f"{pw}.attributes.{name}", "accessor", self.count("accessors"))
            _int(p, "mode", pw, 4, 0, 6)
            _index(p, "material", pw, "material", self.count("materials"))
            indices = _index(p, "indices", pw, "accessor", self.count("accessors"))
            n = self._acc(attrs["POSITION"])["count"] if "POSITION" in attrs else None
            for name, i in attrs.items():
                self._check_semantic(name, i, f"{pw}.attributes", n)
            if indices is not None:
                a = self._acc(indices)
                if a["type"] != "SCALAR" or a["componentType"] not in (5121, 5123, 5125):
                    raise _fail(f"indices as SCALAR unsigned bytes, shorts or ints at {pw}",
                                f"accessor {indices}: {a['type']} of componentType {a['componentType']}")
            targets = _list(p, "targets", pw)
            for t, target in enumerate(targets):
                tw = f"{pw}.targets[{t}]"
                for name, i in _obj(target, tw).items():
                    i = _ref(i, f"{tw}.{name}", "accessor", self.count("accessors"))
                    a = self._acc(i)
                    if name in ("POSITION", "NORMAL", "TANGENT") and (a["type"] != "VEC3"
                                                                     or a["componentType"] != _FLOAT):
                        raise _fail(f"{name} displacements as VEC3 of floats at {tw}",
                                    f"accessor {i}: {a['type']} of componentType {a['componentType']}")
                    if n is not None and a["count"] != n:
                        raise _fail(f"{n:,} {name} displacements (one per POSITION) at {tw}",
                                    f"{a['count']:,} (accessor {i})")
            counts.append(len(targets))
        if len(set(counts)) > 1:
            raise _fail(f"the same number of morph targets in every primitive of {where}",
                        ", ".join(map(str, counts)))
        self.targets.append(counts[0])
        weights = _numbers(m, "weights", where, None)
        if weights is not None and len(weights) != counts[0]:
            raise _fail(f"{counts[0]} default weights (one per morph target) at {where}.weights",
                        f"{len(weights)}")

    def _check_nodes(self) -> None:
        nodes = self.lists["nodes"]
        self.parent: dict[int, int] = {}
        for i, n in enumerate(nodes):
            where = f"nodes[{i}]"
            children = [_ref(c, f"{where}.children[{j}]", "node", len(nodes))
                        for j, c in enumerate(_list(n, "children", where))]
            for c in children:
                if c == i:
                    raise _fail(f"children other than the node itself at {where}",
                                f"node {i} as its own child")
                if c in self.parent:
                    raise _fail(f"one parent for node {c}",
                                f"nodes {self.parent[c]} and {i}" if self.parent[c] != i
                                else f"it listed twice at {where}.children")
                self.parent[c] = i
            mesh = _index(n, "mesh", where, "mesh", self.count("meshes"))
            _index(n, "skin", where, "skin", self.count("skins"))
            _index(n, "camera", where, "camera", self.count("cameras"))
            _numbers(n, "matrix", where, 16)
            _numbers(n, "translation", where, 3)
            _numbers(n, "rotation", where, 4)
            _numbers(n, "scale", where, 3)
            weights = _numbers(n, "weights", where, None)
            if weights is not None and (mesh is None or len(weights) != self.targets[mesh]):
                raise _fail(f"{0 if mesh is None else self.targets[mesh]} weights (one per morph target "
                            f"of its mesh) at {where}.weights", str(len(weights)))
        # With one parent each, a node that no walk from the roots reaches sits on a cycle.
        seen: set[int] = set()
        stack = [i for i in range(len(nodes)) if i not in self.parent]
        while stack:
            i = stack.pop()
            seen.add(i)
            stack.extend(nodes[i].get("children", []))
        if len(seen) != len(nodes):
            first = min(set(range(len(nodes))) - seen)
            raise _fail("a node hierarchy without cycles", f"node {first} among its own ancestors")

    def _check_skin(self, k: int, s: dict) -> None:
        where = f"skins[{k}]"
        joints = [_ref(j, f"{where}.joints[{n}]", "node", self.count("nodes"))
                  for n, j in enumerate(_list(s, "joints", where))]
        if not joints:
            raise _fail(f"at least one joint at {where}.joints", "none")
        _index(s, "skeleton", where, "node", self.count("nodes"))
        ibm = _index(s, "inverseBindMatrices", where, "accessor", self.count("accessors"))
        if ibm is not None:
            a = self._acc(ibm)
            if a["type"] != "MAT4" or a["componentType"] != _FLOAT:
                raise _fail(f"inverseBindMatrices as MAT4 of floats at {where}",
                            f"accessor {ibm}: {a['type']} of componentType {a['componentType']}")
            if a["count"] != len(joints):
                raise _fail(f"{len(joints)} inverseBindMatrices (one per joint) at {where}",
                            f"{a['count']:,} (accessor {ibm})")

    def _check_animation(self, k: int, anim: dict) -> None:
        where = f"animations[{k}]"
        samplers = _list(anim, "samplers", where)
        for j, smp in enumerate(samplers):
            sw = f"{where}.samplers[{j}]"
            _obj(smp, sw)
            i = cast(int, _index(smp, "input", sw, "accessor", self.count("accessors"), required=True))
            _index(smp, "output", sw, "accessor", self.count("accessors"), required=True)
            _enum(smp, "interpolation", sw, INTERPOLATIONS, "LINEAR")
            a = self._acc(i)
            if a["type"] != "SCALAR" or a["componentType"] != _FLOAT:
                raise _fail(f"keyframe times as SCALAR floats at {sw}.input",
                            f"accessor {i}: {a['type']} of componentType {a['componentType']}")
        for j, ch in enumerate(_list(anim, "channels", where)):
            cw = f"{where}.channels[{j}]"
            _obj(ch, cw)
            smp = samplers[cast(int, _index(ch, "sampler", cw, "sampler", len(samplers), required=True))]
            target = _obj(ch.get("target"), f"{cw}.target")
            node = _index(target, "node", f"{cw}.target", "node", self.count("nodes"))
            path = target.get("path")
            if not isinstance(path, str):
                raise _fail(f"a path at {cw}.target", _show(path))
            if node is None or path not in PATHS:
                continue  # another extension's target (KHR_animation_pointer): not previewed
            out = self._acc(smp["output"])
            if out["type"] != _PATH_TYPES[path] or out["componentType"] not in _PATH_COMPONENTS[path]:
                raise _fail(f"{path} keyframes as {_PATH_TYPES[path]} at {cw}", f"accessor {smp['output']}: "
                            f"{out['type']} of componentType {out['componentType']}")
            per_key = 3 if smp.get("interpolation") == "CUBICSPLINE" else 1
            if path == "weights":
                mesh = self.lists["nodes"][node].get("mesh")
                targets = 0 if mesh is None else self.targets[mesh]
                if not targets:
                    raise _fail(f"a node with morph targets for the weights channel {cw}",
                                f"node {node} without any")
                per_key *= targets
            times = self._acc(smp["input"])["count"]
            if out["count"] != times * per_key:
                factor = f" x {per_key}" if per_key > 1 else ""
                raise _fail(f"{times * per_key:,} output values ({times:,} keyframes{factor}) for {cw}",
                            f"{out['count']:,} (accessor {smp['output']})")

    # -- raw data -------------------------------------------------------------
    def _data_uri(self, uri: str, where: str) -> bytes:
        head, _, payload = uri.strip().partition(",")
        try:
            return base64.b64decode(payload, validate=True) if head.endswith(";base64") else \
                payload.encode("latin-1")
        except (binascii.Error, ValueError, UnicodeEncodeError):
            raise _fail(f"base64 data in the data URI at {where}", "other characters") from None

    def buffer(self, i: int) -> bytes | memoryview:
        if i not in self._buffers:
            buf = self.lists["buffers"][i]
            where = f"buffers[{i}]"
            if buf.get("uri") is None:
                data: bytes | memoryview = cast(memoryview, self.blob)
            elif i in self._files:
                data = self._files[i].read_bytes()
                if len(data) != buf["byteLength"]:  # changed since the check
                    raise _fail(f"{buf['byteLength']:,} bytes in {describe(buf['uri'])}", f"{len(data):,}")
            else:
                data = self._data_uri(buf["uri"], where)
                if len(data) != buf["byteLength"]:
                    raise _fail(f"{buf['byteLength']:,} bytes in the data URI of {where}", f"{len(data):,}")
            self._buffers[i] = data
        return self._buffers[i]

    def _view(self, i: int) -> tuple[bytes | memoryview, int]:
        view = self.lists["bufferViews"][i]
        return self.buffer(view["buffer"]), view.get("byteOffset", 0)

    def accessor(self, i: int) -> np.ndarray:
        """The accessor's values, (count, components); normalized integers as float32."""
        acc = self._acc(i)
        dtype, width, count = np.dtype(_DTYPES[acc["componentType"]]), _WIDTH[acc["type"]], acc["count"]
        if acc.get("bufferView") is None:
            out = np.zeros((count, width), dtype)
        else:
            raw, offset = self._view(acc["bufferView"])
            offset += acc.get("byteOffset", 0)
            item = dtype.itemsize * width
            stride = self.lists["bufferViews"][acc["bufferView"]].get("byteStride") or item
            if stride == item:
                out = np.frombuffer(raw, dtype, count * width, offset).reshape(count, width)
            else:  # interleaved: view the rows through a strided window
                rows = np.frombuffer(raw, np.uint8, stride * (count - 1) + item, offset)
                out = np.lib.stride_tricks.as_strided(rows, (count, item), (stride, 1))
                out = np.ascontiguousarray(out).view(dtype).reshape(count, width)
        sparse = acc.get("sparse")
        if sparse is not None:
            out = out.copy()
            n, idx_part, val_part = sparse["count"], sparse["indices"], sparse["values"]
            raw, offset = self._view(idx_part["bufferView"])
            idx = np.frombuffer(raw, _DTYPES[idx_part["componentType"]], n,
                                offset + idx_part.get("byteOffset", 0))
            if int(idx.max()) >= count:
                raise _fail(f"sparse indices below {count:,} at accessors[{i}]", str(int(idx.max())))
            raw, offset = self._view(val_part["bufferView"])
            out[idx] = np.frombuffer(raw, dtype, n * width,
                                     offset + val_part.get("byteOffset", 0)).reshape(n, width)
        if dtype.kind == "f" and not np.isfinite(out).all():
            bad = out[~np.isfinite(out)].ravel()[0]
            raise _fail(f"finite numbers in accessors[{i}]", str(bad))
        if acc.get("normalized") and dtype.kind in "iu":
            out = np.maximum(out.astype(np.float32) / np.iinfo(dtype).max, -1.0)
        return out

    def image_bytes(self, i: int) -> bytes:
        img = self.lists["images"][i]
        if img.get("bufferView") is not None:
            raw, offset = self._view(img["bufferView"])
            data = bytes(raw[offset: offset + self.lists["bufferViews"][img["bufferView"]]["byteLength"]])
        elif img["uri"].strip().startswith("data:"):
            data = self._data_uri(img["uri"], f"images[{i}]")
        else:
            data = self._side(img["uri"]).read_bytes()
        if i in self.textured:
            _check_picture(data, f"images[{i}] ({_name(img, 'unnamed')!r})")
        return data

    # -- scene ------------------------------------------------------------------
    def material(self, k: int) -> Material:
        m = self.lists["materials"][k]
        pbr = m.get("pbrMetallicRoughness") or {}
        texture = None
        if pbr.get("baseColorTexture") is not None:
            texture = self.lists["textures"][pbr["baseColorTexture"]["index"]].get("source")
        factor = pbr.get("baseColorFactor") or [1, 1, 1, 1]
        base_color = cast(tuple[float, float, float, float], tuple(float(v) for v in factor))
        cutoff = m.get("alphaCutoff")
        return Material(name=_name(m, f"material{k}"), base_color=base_color,
                        texture=texture, alpha_mode=m.get("alphaMode", "OPAQUE"),
                        alpha_cutoff=None if cutoff is None else float(cutoff),
                        double_sided=bool(m.get("doubleSided", False)),
                        unlit="KHR_materials_unlit" in (m.get("extensions") or {}))

    def primitive(self, prim: dict, where: str) -> Primitive | None:
        mode = prim.get("mode", 4)
        attrs = prim["attributes"]
        if "POSITION" not in attrs or mode not in _MODES:
            return None  # lines have no surface to preview
        attributes = {name: self.accessor(index) for name, index in attrs.items()}
        attributes = {name: (a.ravel() if a.shape[1] == 1 else a) for name, a in attributes.items()}
        attributes["POSITION"] = attributes["POSITION"].astype(np.float32)
        n = len(attributes["POSITION"])
        weights = attributes.get("WEIGHTS_0")
        if weights is not None and "JOINTS_0" in attributes:
            sums = np.asarray(weights, np.float64).sum(axis=1)
            if (weights < 0).any() or not np.allclose(sums, 1.0, atol=0.02):
                bad = int(np.argmax(np.abs(sums - 1.0) + (weights < 0).any(axis=1)))
                raise _fail(f"WEIGHTS_0 of each vertex non-negative and summing to 1 at {where}",
                            f"{np.round(weights[bad], 4).tolist()} at vertex {bad}")
        indices = None
        if _MODES[mode] == "TRIANGLES":
            flat = (self.accessor(prim["indices"]).ravel().astype(np.uint32) if "indices" in prim
                    else np.arange(n, dtype=np.uint32))
            if len(flat) and int(flat.max()) >= n:  # the GPU would read past the vertices
                raise _fail(f"vertex indices below {n} at {where}", str(int(flat.max())))
            indices = _triangles(flat, mode)
        targets = [{name: self.accessor(index).astype(np.float32) for name, index in target.items()}
                   for target in prim.get("targets", [])]
        return Primitive(attributes, indices, prim.get("material"), _MODES[mode], targets)

    def scene(self, label: str) -> Scene:
        lists = self.lists
        scene = Scene(name=label, info={"source": self.where})
        for k, m in enumerate(lists["meshes"]):
            prims = [self.primitive(p, f"meshes[{k}].primitives[{j}]") for j, p in enumerate(m["primitives"])]
            scene.meshes.append(Mesh(_name(m, f"mesh{k}"), [p for p in prims if p is not None],
                                     [float(w) for w in m.get("weights", [])]))
        scene.images = [Image(_name(img, f"image{k}"), self.image_bytes(k), _mime(img))
                        for k, img in enumerate(lists["images"])]
        scene.materials = [self.material(k) for k in range(len(lists["materials"]))]
        for i, n in enumerate(lists["nodes"]):
            node = Node(name=_name(n, f"node{i}"), children=list(n.get("children", [])),
                        mesh=n.get("mesh"), skin=n.get("skin"))
            if n.get("matrix") is not None and list(n["matrix"]) != _IDENTITY:
                node.matrix = np.asarray(n["matrix"], float).reshape(4, 4).T  # column-major
            if n.get("translation") is not None:
                node.translation = cast(tuple[float, float, float], tuple(map(float, n["translation"])))
            if n.get("rotation") is not None:
                node.rotation = cast(tuple[float, float, float, float], tuple(map(float, n["rotation"])))
            if n.get("scale") is not None:
                node.scale = cast(tuple[float, float, float], tuple(map(float, n["scale"])))
            scene.nodes.append(node)
        for k, skin in enumerate(lists["skins"]):
            joints = list(skin["joints"])
            if skin.get("inverseBindMatrices") is not None:
                ibm = (self.accessor(skin["inverseBindMatrices"]).astype(float)
                       .reshape(-1, 4, 4).transpose(0, 2, 1))
            else:
                ibm = np.repeat(np.eye(4)[None], len(joints), axis=0)
            scene.skins.append(Skin(_name(skin, f"skin{k}"), joints, ibm, skin.get("skeleton")))
        self._check_joints(scene)
        # Only nodes reachable from the default scene are drawn, as an engine would.
        scenes = lists["scenes"]
        scene.roots = (list(scenes[self.doc.get("scene", 0)].get("nodes", [])) if scenes
                       else [i for i in range(len(lists["nodes"])) if i not in self.parent])
        extras = scenes[self.doc.get("scene", 0)].get("extras") if scenes else None
        if isinstance(extras, dict):  # kept as read; whoever uses a member checks it
            scene.extras = extras
        for k, a in enumerate(lists["animations"]):
            channels = []
            for j, ch in enumerate(a.get("channels", [])):
                smp = a["samplers"][ch["sampler"]]
                interp = smp.get("interpolation", "LINEAR")
                node, path = ch["target"].get("node"), ch["target"]["path"]
                if node is None or path not in PATHS:
                    continue
                times = self.accessor(smp["input"]).astype(float).ravel()
                if len(times) > 1 and (np.diff(times) < 0).any():
                    at = int(np.argmax(np.diff(times) < 0)) + 1
                    raise _fail(f"keyframe times that never decrease at animations[{k}].channels[{j}]",
                                f"{times[at]:g} after {times[at - 1]:g}")
                values = self.accessor(smp["output"]).astype(float)
                if path == "weights":
                    values = values.reshape(len(times) * (3 if interp == "CUBICSPLINE" else 1), -1)
                channels.append(Channel(node, path, Sampler(times, values, interp)))
            scene.clips.append(Clip(_name(a, f"clip{k}"), channels))
        return scene

    def _check_joints(self, scene: Scene) -> None:
        """JOINTS_0 of a skinned mesh index its skin's joints."""
        for i, node in enumerate(scene.nodes):
            if node.skin is None or node.mesh is None:
                continue
            joints = len(scene.skins[node.skin].joints)
            for prim in scene.meshes[node.mesh].primitives:
                a = prim.attributes.get("JOINTS_0")
                if a is not None and len(a) and int(a.max()) >= joints:
                    raise _fail(f"JOINTS_0 values below {joints} (the joints of skins[{node.skin}]) "
                                f"in meshes[{node.mesh}] on nodes[{i}]", str(int(a.max())))


def _check_picture(data: bytes, name: str) -> None:
    """Refuse a texture too big to decode, or damaged, from its header and a cheap verify."""
    from PIL import Image as PILImage

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PILImage.DecompressionBombWarning)
            with PILImage.open(io.BytesIO(data)) as img:
                width, height = img.size
    except PILImage.DecompressionBombError:
        raise _fail(f"an image of at most {MAX_IMAGE_PIXELS:,} pixels at {name}",
                    f"more than {2 * (PILImage.MAX_IMAGE_PIXELS or 0):,}") from None
    except Exception as err:  # Pillow raises anything from OSError to SyntaxError
        raise _fail(f"a PNG or JPEG image at {name}", f"unreadable data ({type(err).__name__})") from None
    if width > MAX_IMAGE_SIDE or height > MAX_IMAGE_SIDE or width * height > MAX_IMAGE_PIXELS:
        raise _fail(f"an image of at most {MAX_IMAGE_SIDE} px a side and {MAX_IMAGE_PIXELS:,} pixels "
                    f"at {name}", f"{width}x{height}")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with PILImage.open(io.BytesIO(data)) as img:
                img.verify()
    except Exception as err:
        raise _fail(f"an undamaged image at {name}", f"{type(err).__name__}: {one_line(err, 80)}") from None


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
