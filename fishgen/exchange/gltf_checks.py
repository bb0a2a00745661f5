"""The structural checks of a glTF document against the glTF 2.0 rules.

Everything the decoder and the scene builder will touch is checked here first, before any
accessor is decoded: indices in range, node trees without cycles or second parents, the sizes
of TRS, matrices and colour factors, accessor types and counts per semantic, animation sampler
counts, skins and morph targets, and declared sizes against the bytes really there (buffer
views within buffers, accessors within views, at most MAX_ELEMENTS components in all). Each
fault is one ``FishgenError`` reading ``expected ..., found ...``. What the checks learn on the
way comes out as a :class:`Document`.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, cast

import numpy as np

from fishgen.errors import describe, expected
from fishgen.exchange.gltf_container import sized_uri
from fishgen.scene.model import INTERPOLATIONS, PATHS

MAX_ELEMENTS = 2**26
"""Most accessor components (count x components, summed over every accessor) in one file."""

SUPPORTED_EXTENSIONS = frozenset({"KHR_materials_unlit"})
"""Extensions the reader understands; a file that requires any other one is refused."""

COMPONENT_DTYPES: dict[int, type[np.number]] = {5120: np.int8, 5121: np.uint8, 5122: np.int16,
                                                5123: np.uint16, 5125: np.uint32, 5126: np.float32}
"""The numpy type of each accessor componentType."""
TYPE_WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
"""The components of each accessor type."""
_FLOAT = 5126
_UNORM = (5121, 5123)   # unsigned byte / short, used normalized
_PATH_TYPES = {"translation": "VEC3", "rotation": "VEC4", "scale": "VEC3", "weights": "SCALAR"}
_PATH_COMPONENTS = {"translation": (_FLOAT,), "scale": (_FLOAT,),
                    "rotation": (_FLOAT, 5120, 5121, 5122, 5123), "weights": (_FLOAT, 5120, 5121, 5122, 5123)}


@dataclass(frozen=True)
class Document:
    """A glTF document that passed every structural check, with what the checks learned."""

    doc: dict
    """The whole JSON document."""
    lists: dict[str, list[dict]]
    """Each top-level array (``accessors``, ``nodes``, ...), checked to hold objects; [] if absent."""
    blob: memoryview | None
    """The GLB's BIN chunk, or None for a .gltf."""
    asset: Path | None
    """The asset's file, whose folder side files come from; None for GLB bytes from memory."""
    files: dict[int, Path]
    """Buffer index -> its side file, whose size matched byteLength when checked."""
    targets: list[int]
    """Morph target count of each mesh."""
    textured: frozenset[int]
    """Images the renderer decodes (base colour textures): their pictures are checked too."""
    parent: dict[int, int]
    """Node index -> its parent's index (roots have none)."""


def check_document(doc: dict, blob: memoryview | None, asset: Path | None) -> Document:
    """Check ``doc`` (with its GLB ``blob``, beside ``asset``) against the glTF 2.0 rules.

    Raises FishgenError, without a file name, at the first fault; side files are sized by
    stat, never read.
    """
    return _Checker(doc, blob, asset).document()


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
        raise expected(f"an object at {where}", _show(value))
    return value


def _list(d: dict, key: str, where: str) -> list:
    value = d.get(key, [])
    if not isinstance(value, list):
        raise expected(f"a list at {where}.{key}", _show(value))
    return value


def _int(d: dict, key: str, where: str, default: int | None = None, lo: int = 0,
         hi: int | None = None) -> int:
    value: Any = d.get(key, default)
    if not _is_int(value) or value < lo or (hi is not None and value > hi):
        span = f"from {lo} to {hi}" if hi is not None else f"of at least {lo}"
        raise expected(f"an integer {span} at {where}.{key}", "none" if value is None else _show(value))
    return cast(int, value)


def _index(d: dict, key: str, where: str, kind: str, count: int, required: bool = False) -> int | None:
    value = d.get(key)
    if value is None and not required:
        return None
    return _ref(value, f"{where}.{key}", kind, count)


def _ref(value: Any, where: str, kind: str, count: int) -> int:
    if not _is_int(value) or not 0 <= value < count:
        span = f"from 0 to {count - 1}" if count else f"(the file has no {kind}s)"
        article = "an" if kind[0] in "aeiou" else "a"
        raise expected(f"{article} {kind} index {span} at {where}", "none" if value is None else _show(value))
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
        raise expected(f"{what} at {where}.{key}", found)
    return [float(v) for v in value]


def _enum(d: dict, key: str, where: str, choices: tuple[str, ...], default: str) -> str:
    value = d.get(key, default)
    if value not in choices:
        raise expected(f"one of {', '.join(choices)} at {where}.{key}", _show(value))
    return cast(str, value)


def _bool(d: dict, key: str, where: str) -> bool:
    value = d.get(key, False)
    if not isinstance(value, bool):
        raise expected(f"true or false at {where}.{key}", _show(value))
    return value


def item_name(d: dict, fallback: str) -> str:
    """An item's own non-empty name, else ``fallback``."""
    name = d.get("name")
    return name if isinstance(name, str) and name else fallback


class _Checker:
    """Walks the document once, in the order each kind refers to the ones before it."""

    def __init__(self, doc: dict, blob: memoryview | None, asset: Path | None):
        self.doc, self.blob, self.asset = doc, blob, asset
        self.files: dict[int, Path] = {}
        self.lists: dict[str, list[dict]] = {}
        self.elements = 0
        self.targets: list[int] = []   # morph target count of each mesh
        self.textured: set[int] = set()  # images the renderer decodes (base colour textures)
        self.parent: dict[int, int] = {}

    def count(self, kind: str) -> int:
        return len(self.lists[kind])

    def document(self) -> Document:
        self._check()
        return Document(self.doc, self.lists, self.blob, self.asset, self.files, self.targets,
                        frozenset(self.textured), self.parent)

    def _check(self) -> None:
        doc = self.doc
        asset = _obj(doc.get("asset"), "asset")
        version = asset.get("version")
        if not isinstance(version, str) or version.split(".")[0] != "2":
            raise expected('asset.version "2.0"', "none" if version is None else _show(version))
        for key in ("extensionsUsed", "extensionsRequired"):  # names, or a list in a set test is a TypeError
            for k, name in enumerate(_list(doc, key, "document")):
                if not isinstance(name, str):
                    raise expected(f"an extension name at {key}[{k}]", _show(name))
        required = _list(doc, "extensionsRequired", "document")
        unknown = [e for e in required if e not in SUPPORTED_EXTENSIONS]
        if unknown:
            raise expected("no required extension but " + ", ".join(sorted(SUPPORTED_EXTENSIONS)),
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
                raise expected(f"each node once at {where}.nodes", "a node listed twice")
            for n in nodes:
                if n in self.parent:
                    raise expected(f"only root nodes at {where}.nodes",
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
                raise expected(f"a uri at {where} (only a GLB's first buffer may omit it)", "none")
            if not length <= len(self.blob) <= length + 3:
                raise expected(f"a GLB BIN chunk of {length:,} bytes for {where}",
                               f"{len(self.blob):,} bytes")
            return
        found = self._sized_uri(uri, where, "a buffer")
        if found is None:
            return
        target, size = found
        if size != length:
            raise expected(f"{length:,} bytes in {describe(uri)} ({where}.byteLength)", f"{size:,} bytes")
        self.files[k] = target

    def _sized_uri(self, uri: Any, where: str, what: str) -> tuple[Path, int] | None:
        if not isinstance(uri, str):
            raise expected(f"a URI string at {where}.uri", _show(uri))
        return sized_uri(self.asset, uri, where, what)

    def _check_view(self, k: int, v: dict) -> None:
        where = f"bufferViews[{k}]"
        buf = _index(v, "buffer", where, "buffer", self.count("buffers"), required=True)
        offset = _int(v, "byteOffset", where, 0)
        length = _int(v, "byteLength", where, lo=1)
        stride = v.get("byteStride")
        if stride is not None and (not _is_int(stride) or not 4 <= stride <= 252 or stride % 4):
            raise expected(f"a byteStride from 4 to 252, a multiple of 4, at {where}", _show(stride))
        size = self.lists["buffers"][cast(int, buf)]["byteLength"]
        if offset + length > size:
            raise expected(f"{where} (bytes {offset:,} to {offset + length:,}) within buffer {buf} "
                           f"of {size:,} bytes", f"{offset + length - size:,} bytes past its end")

    def _check_accessor(self, k: int, a: dict) -> None:
        where = f"accessors[{k}]"
        ctype = a.get("componentType")
        if ctype not in COMPONENT_DTYPES:
            raise expected(f"a componentType of {', '.join(map(str, COMPONENT_DTYPES))} at {where}",
                           _show(ctype))
        kind = _enum(a, "type", where, tuple(TYPE_WIDTHS), "")
        count = _int(a, "count", where, lo=1)
        _bool(a, "normalized", where)
        width = TYPE_WIDTHS[kind]
        view = _index(a, "bufferView", where, "bufferView", self.count("bufferViews"))
        if view is not None:
            item = np.dtype(COMPONENT_DTYPES[ctype]).itemsize * width
            self._fits(where, view, _int(a, "byteOffset", where, 0), count, item, strided=True)
        self.elements += count * width
        if self.elements > MAX_ELEMENTS:
            raise expected(f"at most {MAX_ELEMENTS:,} accessor components in the file",
                           f"more by {where} (count {count:,} of {kind})")
        sparse = a.get("sparse")
        if sparse is not None:
            sw = f"{where}.sparse"
            _obj(sparse, sw)
            n = _int(sparse, "count", sw, lo=1, hi=count)
            self.elements += n * (1 + width)
            if self.elements > MAX_ELEMENTS:
                raise expected(f"at most {MAX_ELEMENTS:,} accessor components in the file", f"more by {sw}")
            idx = _obj(sparse.get("indices"), f"{sw}.indices")
            if idx.get("componentType") not in (5121, 5123, 5125):
                raise expected(f"a componentType of 5121, 5123 or 5125 at {sw}.indices",
                               _show(idx.get("componentType")))
            for part, item in ((idx, np.dtype(COMPONENT_DTYPES[idx["componentType"]]).itemsize),
                               (_obj(sparse.get("values"), f"{sw}.values"),
                                np.dtype(COMPONENT_DTYPES[ctype]).itemsize * width)):
                pw = f"{sw}.{'indices' if part is idx else 'values'}"
                pv = _index(part, "bufferView", pw, "bufferView", self.count("bufferViews"), required=True)
                self._fits(pw, cast(int, pv), _int(part, "byteOffset", pw, 0), n, item, strided=False)

    def _fits(self, where: str, view: int, offset: int, count: int, item: int, strided: bool) -> None:
        v = self.lists["bufferViews"][view]
        stride = (v.get("byteStride") if strided else None) or item
        if stride < item:
            raise expected(f"a byteStride of at least {item} (one element) for {where}",
                           f"{stride} in bufferView {view}")
        end = offset + stride * (count - 1) + item
        if end > v["byteLength"]:
            raise expected(f"{where} ({count:,} elements of {item} bytes from byte {offset:,}) "
                           f"within bufferView {view} of {v['byteLength']:,} bytes",
                           f"{end:,} bytes needed")

    def _check_image_ref(self, k: int, img: dict) -> None:
        where = f"images[{k}]"
        uri, view = img.get("uri"), _index(img, "bufferView", where, "bufferView", self.count("bufferViews"))
        if (uri is None) == (view is None):
            raise expected(f"either a uri or a bufferView at {where}",
                           "both" if view is not None else "neither")
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
                    raise expected(f"a finite number at {pw}.{key}", _show(pbr[key]))
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
            raise expected(f"a finite alphaCutoff of at least 0 at {where}", _show(cutoff))
        _bool(m, "doubleSided", where)
        if not isinstance(m.get("extensions", {}), dict):
            raise expected(f"an object at {where}.extensions", _show(m["extensions"]))

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
        elif name in ("_RADIUS", "_DENSITY", "_LIGHT"):
            ok, want = kind == "SCALAR", "SCALAR"
        if not ok:
            raise expected(f"{name} as {want} at {where}",
                           f"accessor {i}: {kind} of componentType {ctype}{' normalized' if norm else ''}")
        if n is not None and a["count"] != n:
            raise expected(f"{n:,} {name} values (one per POSITION) at {where}",
                           f"{a['count']:,} (accessor {i})")

    def _check_mesh(self, k: int, m: dict) -> None:
        where = f"meshes[{k}]"
        prims = _list(m, "primitives", where)
        if not prims:
            raise expected(f"at least one primitive at {where}", "none")
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
                    raise expected(f"indices as SCALAR unsigned bytes, shorts or ints at {pw}",
                                   f"accessor {indices}: {a['type']} of componentType {a['componentType']}")
            targets = _list(p, "targets", pw)
            for t, target in enumerate(targets):
                tw = f"{pw}.targets[{t}]"
                for name, i in _obj(target, tw).items():
                    i = _ref(i, f"{tw}.{name}", "accessor", self.count("accessors"))
                    a = self._acc(i)
                    if name in ("POSITION", "NORMAL", "TANGENT") and (a["type"] != "VEC3"
                                                                     or a["componentType"] != _FLOAT):
                        raise expected(f"{name} displacements as VEC3 of floats at {tw}",
                                       f"accessor {i}: {a['type']} of componentType {a['componentType']}")
                    if n is not None and a["count"] != n:
                        raise expected(f"{n:,} {name} displacements (one per POSITION) at {tw}",
                                       f"{a['count']:,} (accessor {i})")
            counts.append(len(targets))
        if len(set(counts)) > 1:
            raise expected(f"the same number of morph targets in every primitive of {where}",
                           ", ".join(map(str, counts)))
        self.targets.append(counts[0])
        weights = _numbers(m, "weights", where, None)
        if weights is not None and len(weights) != counts[0]:
            raise expected(f"{counts[0]} default weights (one per morph target) at {where}.weights",
                           f"{len(weights)}")

    def _check_nodes(self) -> None:
        nodes = self.lists["nodes"]
        for i, n in enumerate(nodes):
            where = f"nodes[{i}]"
            children = [_ref(c, f"{where}.children[{j}]", "node", len(nodes))
                        for j, c in enumerate(_list(n, "children", where))]
            for c in children:
                if c == i:
                    raise expected(f"children other than the node itself at {where}",
                                   f"node {i} as its own child")
                if c in self.parent:
                    raise expected(f"one parent for node {c}",
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
                raise expected(f"{0 if mesh is None else self.targets[mesh]} weights (one per morph target "
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
            raise expected("a node hierarchy without cycles", f"node {first} among its own ancestors")

    def _check_skin(self, k: int, s: dict) -> None:
        where = f"skins[{k}]"
        joints = [_ref(j, f"{where}.joints[{n}]", "node", self.count("nodes"))
                  for n, j in enumerate(_list(s, "joints", where))]
        if not joints:
            raise expected(f"at least one joint at {where}.joints", "none")
        _index(s, "skeleton", where, "node", self.count("nodes"))
        ibm = _index(s, "inverseBindMatrices", where, "accessor", self.count("accessors"))
        if ibm is not None:
            a = self._acc(ibm)
            if a["type"] != "MAT4" or a["componentType"] != _FLOAT:
                raise expected(f"inverseBindMatrices as MAT4 of floats at {where}",
                               f"accessor {ibm}: {a['type']} of componentType {a['componentType']}")
            if a["count"] != len(joints):
                raise expected(f"{len(joints)} inverseBindMatrices (one per joint) at {where}",
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
                raise expected(f"keyframe times as SCALAR floats at {sw}.input",
                               f"accessor {i}: {a['type']} of componentType {a['componentType']}")
        for j, ch in enumerate(_list(anim, "channels", where)):
            cw = f"{where}.channels[{j}]"
            _obj(ch, cw)
            smp = samplers[cast(int, _index(ch, "sampler", cw, "sampler", len(samplers), required=True))]
            target = _obj(ch.get("target"), f"{cw}.target")
            node = _index(target, "node", f"{cw}.target", "node", self.count("nodes"))
            path = target.get("path")
            if not isinstance(path, str):
                raise expected(f"a path at {cw}.target", _show(path))
            if node is None or path not in PATHS:
                continue  # another extension's target (KHR_animation_pointer): not previewed
            out = self._acc(smp["output"])
            if out["type"] != _PATH_TYPES[path] or out["componentType"] not in _PATH_COMPONENTS[path]:
                raise expected(f"{path} keyframes as {_PATH_TYPES[path]} at {cw}",
                               f"accessor {smp['output']}: {out['type']} of componentType "
                               f"{out['componentType']}")
            per_key = 3 if smp.get("interpolation") == "CUBICSPLINE" else 1
            if path == "weights":
                mesh = self.lists["nodes"][node].get("mesh")
                targets = 0 if mesh is None else self.targets[mesh]
                if not targets:
                    raise expected(f"a node with morph targets for the weights channel {cw}",
                                   f"node {node} without any")
                per_key *= targets
            times = self._acc(smp["input"])["count"]
            if out["count"] != times * per_key:
                factor = f" x {per_key}" if per_key > 1 else ""
                raise expected(f"{times * per_key:,} output values ({times:,} keyframes{factor}) for {cw}",
                               f"{out['count']:,} (accessor {smp['output']})")
