"""Input generators: token-level mutators for the text formats, structure-aware glTF mutation,
PLY/OBJ/PNG mutators, and random option values for the CLI.

Every generator takes a ``random.Random`` and returns a new input; nothing here touches the
disk, so one ``(seed, target, index)`` always regenerates the same case (see
:func:`fishgen.fuzz.cases.make_case`).
"""
from __future__ import annotations

import base64
import json
import math
import random
import struct
import zlib
from typing import Any

# -- interesting values ----------------------------------------------------------------------
NUMBERS = [
    "0", "-0", "0.0", "1", "-1", "2", "3", "4", "7", "16", "1024", "1025", "65535", "65536",
    "0.5", "1.0001", "0.9999", "1e-300", "-1e-300", "5e-324", "1e-45", "1e-38", "1.2e-38",
    "1e-9", "1e-6", "0.0001", "0.001", "1e300", "-1e300", "1e308", "1.8e308", "3.4e38",
    "3.5e38", "1e39", "1e6", "1000001", "1e7", "9999", "10000", "10001", "1e4", "100", "101",
    "360", "720", "-360", "90", "180", "-90", "1e18", "999999999999999999", "9" * 19, "9" * 400,
    "2147483647", "2147483648", "4294967296", "-2147483649", "nan", "NaN", "-nan", "inf", "-inf",
    "Infinity", "+1", "+0", ".5", "5.", ".", "-", "+", "e5", "1e", "1e+", "0x10", "1_000", "１２",
    "٣", "1,5", "1.5.5", "true", "false", "T", "F", "", "\t", "\u00a0", "\u2028", "\x00", "\x0c",
]
WORDS = ["true", "false", "T", "F", "True", "FishShapeSin", "FishShapeCircle", "none", "null",
         "bonybream.png", "../secret.png", "/etc/passwd", "missing.png", "a" * 300, "//", "#",
         "\ufeff", "é", "\U0001f41f", "con", "nul.png", "dir/", "."]
FLOAT_SPECIALS = [0.0, -0.0, 1.0, -1.0, 1e-45, 1e-38, 3.4e38, -3.4e38, 1e39, 1e300,
                  float("nan"), float("inf"), float("-inf"), 65504.0, 0.5, 2.0, 1e6, -1e6]
INT_SPECIALS = [0, 1, -1, 2, 3, 4, 5, 6, 255, 256, 65535, 65536, 2**31 - 1, 2**31, 2**32,
                2**53, 10**12, -(2**31), 10**30]


def f32(value: float) -> bytes:
    """``value`` as 4 little-endian float32 bytes; beyond float32 range it becomes infinity."""
    try:
        return struct.pack("<f", value)
    except OverflowError:
        return struct.pack("<f", math.copysign(math.inf, value))


def _number_like(token: str) -> bool:
    try:
        float(token)
        return True
    except ValueError:
        return False


def interesting_token(rng: random.Random, old: str | None = None) -> str:
    roll = rng.random()
    if old is not None and _number_like(old) and roll < 0.3:
        value = float(old)
        factor = rng.choice([0, -1, 10, 0.1, 1e3, 1e-3, 1e6, 1e-6, 1e30, 1e-30, 2, 0.5])
        out = value * factor
        if rng.random() < 0.5 and abs(out) < 1e15:
            return str(int(out))
        return repr(out)
    if roll < 0.85:
        return rng.choice(NUMBERS)
    return rng.choice(WORDS)


def mutate_text(text: str, rng: random.Random, sep: str = " ", ops: int | None = None) -> str:
    """Token- and line-level mutation of a whitespace (or comma) separated text file."""
    lines = text.split("\n")
    for _ in range(ops if ops is not None else rng.choice([1, 1, 1, 2, 2, 3, 5, 8])):
        if not lines:
            lines = [""]
        k = rng.randrange(len(lines))
        op = rng.random()
        if op < 0.5:  # replace a token
            toks = lines[k].replace(",", " , ").split() if sep == "," else lines[k].split()
            if toks:
                i = rng.randrange(len(toks))
                toks[i] = interesting_token(rng, toks[i])
                lines[k] = " ".join(toks).replace(" , ", ", ") if sep == "," else " ".join(toks)
        elif op < 0.58:  # delete a token
            toks = lines[k].split()
            if toks:
                del toks[rng.randrange(len(toks))]
                lines[k] = " ".join(toks)
        elif op < 0.66:  # insert a token
            toks = lines[k].split()
            toks.insert(rng.randrange(len(toks) + 1), interesting_token(rng))
            lines[k] = " ".join(toks)
        elif op < 0.72:
            del lines[k]
        elif op < 0.78:
            lines.insert(k, lines[rng.randrange(len(lines))])
        elif op < 0.82:
            j = rng.randrange(len(lines))
            lines[k], lines[j] = lines[j], lines[k]
        elif op < 0.86:  # truncate
            cut = rng.randrange(len(text) + 1) if text else 0
            return "\n".join(lines)[:cut]
        elif op < 0.90:  # line endings / comments / odd characters
            lines[k] = rng.choice(["//" + lines[k], lines[k] + "\r", "\ufeff" + lines[k],
                                   lines[k] + " //x", "\x0c" + lines[k], lines[k].upper(),
                                   lines[k] + "\u2028", " " * 50 + lines[k]])
        elif op < 0.95:  # character flip
            s = lines[k]
            if s:
                i = rng.randrange(len(s))
                char = chr(rng.choice([0, 9, 11, 32, 44, 45, 46, 48, 57, 101, 127, 0xa0, 0xff, 0x2028,
                                       0xfeff, 0x1f41f, rng.randrange(1, 0x3000)]))
                lines[k] = s[:i] + char + s[i + 1:]
        else:  # a huge repeat of one line
            lines[k:k + 1] = [lines[k]] * rng.choice([2, 10, 1000])
    return "\n".join(lines)


# -- species and cube files --------------------------------------------------------------------
def species_text(seeds: list[str], rng: random.Random) -> str:
    return mutate_text(rng.choice(seeds), rng)


def cubes_bytes(seeds: list[bytes], rng: random.Random) -> bytes:
    if rng.random() < 0.25:  # from the grammar: header, count, cube lines of interesting values
        n = rng.choice([0, 1, 1, 2, 3, 5, 40])
        rows = [str(rng.choice([0, 1, 10, 100, 1000, 10**9, 10**20, -1])), str(n)]
        for _ in range(n):
            fields = [rng.choice(["1", "10", "100", "0", "-1", "2000"])]
            for _field in range(7):
                fields.append(interesting_token(rng) if rng.random() < 0.3 else
                              rng.choice(["1", "0.5", "10", "-5", "3.0"]))
            rows.append(rng.choice([", ", ",", " ", "\t", " , "]).join(fields))
        text = rng.choice(["\n", "\r\n", "\r"]).join(rows) + rng.choice(["", "\n", "\n\n"])
        data = text.encode("utf-8", "surrogatepass")
    else:
        seed = rng.choice(seeds).decode("utf-8")
        data = mutate_text(seed, rng, sep=",").encode("utf-8", "surrogatepass")
    if rng.random() < 0.05:
        data = mutate_bytes(data, rng)
    return data


def mutate_bytes(data: bytes, rng: random.Random, ops: int | None = None) -> bytes:
    buf = bytearray(data)
    for _ in range(ops if ops is not None else rng.choice([1, 2, 4, 8])):
        op = rng.random()
        if not buf:
            buf += bytes([rng.randrange(256)])
            continue
        i = rng.randrange(len(buf))
        if op < 0.4:
            buf[i] = rng.randrange(256)
        elif op < 0.5:
            buf[i] ^= 1 << rng.randrange(8)
        elif op < 0.6:
            del buf[i:i + rng.choice([1, 4, 16, 256])]
        elif op < 0.7:
            buf[i:i] = bytes(rng.randrange(256) for _ in range(rng.choice([1, 4, 16])))
        elif op < 0.8 and len(buf) >= 4:
            i = rng.randrange(len(buf) - 3)
            buf[i:i + 4] = struct.pack("<I", rng.choice([0, 1, 0xFFFFFFFF, 0x7FFFFFFF, 0x80000000,
                                                        len(buf), len(buf) + 1, 10**9]))
        elif op < 0.9 and len(buf) >= 4:
            i = rng.randrange(len(buf) - 3)
            buf[i:i + 4] = f32(rng.choice(FLOAT_SPECIALS))
        else:
            del buf[i:]
    return bytes(buf)


# -- PNG -------------------------------------------------------------------------------------------
def png_bytes(width: int, height: int, *, color_type: int = 6, depth: int = 8, body: bool = True) -> bytes:
    """A PNG with the given header; with ``body``, a real (tiny-row) zlib stream of the pixels."""
    def chunk(kind: bytes, payload: bytes) -> bytes:
        crc = struct.pack(">I", zlib.crc32(kind + payload))
        return struct.pack(">I", len(payload)) + kind + payload + crc
    ihdr = struct.pack(">IIBBBBB", width, height, depth, color_type, 0, 0, 0)
    data = b""
    if body and width <= 4096 and height <= 4096 and width * height <= 4096:
        channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}.get(color_type, 4)
        row = b"\0" + b"\x80" * (width * channels * max(depth, 8) // 8)
        data = zlib.compress(row * height)
    elif body:  # a huge declared image with a small (truncated) stream: the decoder must refuse
        data = zlib.compress(b"\0" * 1024)
    plte = chunk(b"PLTE", b"\0\0\0" * 4) if color_type == 3 else b""
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + plte + chunk(b"IDAT", data) + chunk(b"IEND", b"")


def mutate_png(data: bytes, rng: random.Random) -> bytes:
    roll = rng.random()
    if roll < 0.45:
        w = rng.choice([0, 1, 2, 8, 8193, 30000, 65535, 100000, 2**31 - 1, 2**32 - 1])
        h = rng.choice([0, 1, 2, 8, 8193, 30000, 65535, 100000, 2**31 - 1, 2**32 - 1])
        return png_bytes(w, h, color_type=rng.choice([6, 6, 2, 0, 3, 4, 7]),
                         depth=rng.choice([8, 8, 16, 1, 3]), body=rng.random() < 0.8)
    if roll < 0.6:
        return data[: rng.randrange(len(data) + 1)]
    if roll < 0.7:
        return rng.choice([b"", b"GIF89a", b"\xff\xd8\xff", b"not an image", b"\x89PNG\r\n\x1a\n"])
    return mutate_bytes(data, rng)


# -- glTF ------------------------------------------------------------------------------------------
GLB_MAGIC = 0x46546C67


def unpack_glb(data: bytes) -> tuple[dict, bytes]:
    total = struct.unpack_from("<I", data, 8)[0]
    pos, doc, blob = 12, None, b""
    while pos + 8 <= min(total, len(data)):
        length, kind = struct.unpack_from("<II", data, pos)
        payload = data[pos + 8: pos + 8 + length]
        if kind == 0x4E4F534A:
            doc = json.loads(payload.decode("utf-8"))
        elif kind == 0x004E4942:
            blob = payload
        pos += 8 + length
    if doc is None:
        raise ValueError("no JSON chunk")
    return doc, blob


def pack_glb(doc: Any, blob: bytes | None, *, allow_nan: bool = True) -> bytes:
    text = json.dumps(doc, allow_nan=allow_nan).encode("utf-8")
    text += b" " * (-len(text) % 4)
    out = struct.pack("<II", len(text), 0x4E4F534A) + text
    if blob is not None:
        blob = blob + b"\0" * (-len(blob) % 4)
        out += struct.pack("<II", len(blob), 0x004E4942) + blob
    return struct.pack("<III", GLB_MAGIC, 2, 12 + len(out)) + out


def _pick(rng: random.Random, doc: dict, key: str) -> tuple[list, int] | None:
    items = doc.get(key)
    if not isinstance(items, list) or not items:
        return None
    return items, rng.randrange(len(items))


def _bad_index(rng: random.Random, n: int) -> Any:
    return rng.choice([n, n + 1, -1, 2**31, 2**53, 10**20, 0.5, "0", None, [0], True])


def _bad_vector(rng: random.Random, want: int) -> Any:
    roll = rng.random()
    if roll < 0.35:
        return [rng.choice([0.0, 1.0, 0.5])] * rng.choice([0, 1, 2, 3, 4, 5, 6, 16, 17])
    if roll < 0.8:
        return [rng.choice(FLOAT_SPECIALS) for _ in range(want)]
    return rng.choice([None, "1,0,0", {}, [None] * want, [[1]] * want, 1.0, [True] * want])


def _accessor_counts(doc: dict) -> list[int]:
    return [i for i, a in enumerate(doc.get("accessors") or []) if isinstance(a, dict)]


def mutate_gltf_doc(doc: dict, blob: bytearray | None, rng: random.Random,
                    side: dict[str, bytes | int]) -> None:
    """One structure-aware mutation of a glTF JSON document (in place), its GLB blob or side files."""
    n_nodes = len(doc.get("nodes") or [])
    op = rng.randrange(24)
    if op == 0 and (p := _pick(rng, doc, "nodes")):  # TRS of the wrong length or odd values
        items, i = p
        key = rng.choice(["rotation", "scale", "translation", "matrix", "weights"])
        want = {"rotation": 4, "scale": 3, "translation": 3, "matrix": 16, "weights": 2}[key]
        items[i][key] = _bad_vector(rng, want)
    elif op == 1 and (p := _pick(rng, doc, "nodes")):  # scale 0 / degenerate matrices
        items, i = p
        items[i][rng.choice(["scale", "matrix"])] = rng.choice([
            [0.0, 0.0, 0.0], [0.0, 1.0, 1.0], [1e-45, 1e-45, 1e-45], [1e38, 1e38, 1e38],
            [0.0] * 16, [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0]])
        if rng.random() < 0.5:
            items[i]["rotation"] = rng.choice([[0, 0, 0, 0], [0, 0, 0, 2], [1e30, 0, 0, 1]])
    elif op == 2 and (p := _pick(rng, doc, "nodes")):  # self-child, cycles, bad children
        items, i = p
        kind = rng.random()
        if kind < 0.4:
            items[i]["children"] = list(items[i].get("children") or []) + [i]
        elif kind < 0.7 and n_nodes > 1:
            j = rng.randrange(n_nodes)
            items[i]["children"] = [j]
            items[j]["children"] = list(items[j].get("children") or []) + [i]
        else:
            items[i]["children"] = rng.choice([[_bad_index(rng, n_nodes)], [0, 0], "1", [None]])
    elif op == 3 and (p := _pick(rng, doc, "nodes")):
        items, i = p
        key = rng.choice(["mesh", "skin", "camera"])
        items[i][key] = _bad_index(rng, len(doc.get(key + "es" if key == "mesh" else key + "s") or []))
    elif op == 4 and (p := _pick(rng, doc, "accessors")):  # huge / zero / negative counts
        items, i = p
        items[i]["count"] = rng.choice([0, 1, 2, 3, 1000, 2**24, 2**28, 2**31, 2**32, 10**12, -1, 0.5])
    elif op == 5 and (p := _pick(rng, doc, "accessors")):
        items, i = p
        key = rng.choice(["componentType", "type", "byteOffset", "bufferView", "normalized", "sparse"])
        items[i][key] = {
            "componentType": rng.choice([5120, 5121, 5122, 5123, 5124, 5125, 5126, 5127, 0, "5126"]),
            "type": rng.choice(["SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4", "VEC5", ""]),
            "byteOffset": rng.choice([1, 2, 3, 4, 1000, 2**31, -4]),
            "bufferView": _bad_index(rng, len(doc.get("bufferViews") or [])),
            "normalized": True,
            "sparse": {"count": rng.choice([1, 5, 2**30]),
                       "indices": {"bufferView": 0, "componentType": rng.choice([5121, 5123, 5125, 5126])},
                       "values": {"bufferView": rng.choice([0, 1, 999])}},
        }[key]
    elif op == 6 and (p := _pick(rng, doc, "bufferViews")):
        items, i = p
        key = rng.choice(["byteLength", "byteOffset", "byteStride", "buffer"])
        items[i][key] = rng.choice([0, 1, 3, 4, 255, 256, 2**31, 2**40, -1]) if key != "buffer" \
            else _bad_index(rng, len(doc.get("buffers") or []))
    elif op == 7 and (p := _pick(rng, doc, "buffers")):  # buffer URIs
        items, i = p
        kind = rng.randrange(8)
        if kind == 0:
            items[i]["uri"] = rng.choice(["missing.bin", "../outside.bin", "/etc/hostname", "file:///etc/hostname",
                                          "http://example.invalid/x.bin", "", " ", "%00.bin",
                                          "a%2F..%2F..%2Fx",
                                          "dir/", ".", "C:\\x.bin", "\\\\server\\x"])
        elif kind == 1:
            payload = bytes(blob) if blob is not None else b"\0" * 64
            items[i]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(payload).decode()
        elif kind == 2:
            items[i]["uri"] = rng.choice(["data:", "data:,", "data:application/octet-stream;base64,!!!!",
                                          "data:;base64,AAA", "data:text/plain,hello", "data:" + "A" * 1000])
        elif kind == 3:  # a huge side file (sparse, so it costs no disk)
            items[i]["uri"] = "huge.bin"
            side["huge.bin"] = rng.choice([2**26, 2**31, 2**33])
        else:
            items[i]["byteLength"] = rng.choice([0, 1, 2**31, 2**40, -1])
    elif op == 8 and (p := _pick(rng, doc, "materials")):
        items, i = p
        pbr = items[i].setdefault("pbrMetallicRoughness", {})
        roll = rng.random()
        if roll < 0.5:
            pbr["baseColorFactor"] = _bad_vector(rng, 4)
        elif roll < 0.7:
            pbr["baseColorTexture"] = {"index": _bad_index(rng, len(doc.get("textures") or []))}
        elif roll < 0.85:
            items[i]["alphaCutoff"] = rng.choice(FLOAT_SPECIALS + [None, "0.5"])
        else:
            items[i]["alphaMode"] = rng.choice(["BLEND", "MASK", "OPAQUE", "blend", "", None, 3])
    elif op == 9 and (p := _pick(rng, doc, "textures")):
        items, i = p
        items[i]["source"] = _bad_index(rng, len(doc.get("images") or []))
    elif op == 10 and (p := _pick(rng, doc, "images")):  # huge declared size, truncated, not a PNG
        items, i = p
        img = items[i]
        if "uri" in img and not str(img["uri"]).startswith("data:") and rng.random() < 0.7:
            name = str(img["uri"])
            old = side.get(name)
            side[name] = mutate_png(old if isinstance(old, bytes) else png_bytes(2, 2), rng)
        elif rng.random() < 0.5:
            img.pop("bufferView", None)
            encoded = base64.b64encode(mutate_png(png_bytes(2, 2), rng)).decode()
            img["uri"] = "data:image/png;base64," + encoded
        else:
            img["uri"] = rng.choice(["missing.png", "../x.png", "data:image/png;base64,", ""])
            img.pop("bufferView", None)
    elif op == 11 and (p := _pick(rng, doc, "animations")):  # sampler input/output mismatch
        items, i = p
        samplers = items[i].get("samplers") or []
        if samplers:
            s = rng.choice(samplers)
            acc = doc.get("accessors") or []
            which = rng.choice(["input", "output"])
            j = s.get(which)
            if isinstance(j, int) and 0 <= j < len(acc) and rng.random() < 0.6:
                acc[j]["count"] = max(0, int(acc[j].get("count", 1)) + rng.choice([-1, 1, -2, 5, -1000]))
            else:
                s[which] = rng.choice(_accessor_counts(doc) or [0]) if rng.random() < 0.5 \
                    else _bad_index(rng, len(acc))
    elif op == 12 and (p := _pick(rng, doc, "animations")):
        items, i = p
        anim = items[i]
        channels = anim.get("channels") or []
        if channels:
            ch = rng.choice(channels)
            roll = rng.random()
            if roll < 0.3:
                ch["sampler"] = _bad_index(rng, len(anim.get("samplers") or []))
            elif roll < 0.6:
                ch.setdefault("target", {})["node"] = _bad_index(rng, n_nodes)
            else:
                ch.setdefault("target", {})["path"] = rng.choice(["translation", "rotation", "scale",
                                                                  "weights", "pointer", "", None])
        for s in anim.get("samplers") or []:
            if rng.random() < 0.3:
                s["interpolation"] = rng.choice(["CUBICSPLINE", "STEP", "LINEAR", "cubic", ""])
    elif op == 13 and (p := _pick(rng, doc, "meshes")):
        items, i = p
        prims = items[i].get("primitives") or []
        if prims:
            prim = rng.choice(prims)
            roll = rng.random()
            if roll < 0.3:
                prim["mode"] = rng.choice([0, 1, 2, 3, 4, 5, 6, 7, -1])
            elif roll < 0.55:
                prim["indices"] = rng.choice(_accessor_counts(doc) or [0]) if rng.random() < 0.5 \
                    else _bad_index(rng, len(doc.get("accessors") or []))
            elif roll < 0.8:
                attrs = prim.setdefault("attributes", {})
                name = rng.choice(["POSITION", "NORMAL", "TEXCOORD_0", "COLOR_0", "_RADIUS", "JOINTS_0",
                                   "WEIGHTS_0", "TANGENT"])
                attrs[name] = rng.choice(_accessor_counts(doc) or [0])
            elif roll < 0.9:
                prim["material"] = _bad_index(rng, len(doc.get("materials") or []))
            else:
                prim["targets"] = [{"POSITION": rng.choice(_accessor_counts(doc) or [0])}]
                items[i]["weights"] = _bad_vector(rng, 1)
    elif op == 14:  # skins
        acc = _accessor_counts(doc)
        skin: dict[str, Any] = {"joints": rng.choice([[0], [0, n_nodes], [], [-1], list(range(n_nodes))])}
        if acc and rng.random() < 0.7:
            skin["inverseBindMatrices"] = rng.choice(acc)
        if rng.random() < 0.3:
            skin["skeleton"] = _bad_index(rng, n_nodes)
        doc.setdefault("skins", []).append(skin)
        if n_nodes:
            doc["nodes"][rng.randrange(n_nodes)]["skin"] = len(doc["skins"]) - 1
    elif op == 15:  # scenes
        roll = rng.random()
        if roll < 0.5:
            doc["scene"] = _bad_index(rng, len(doc.get("scenes") or []))
        elif doc.get("scenes"):
            doc["scenes"][0]["nodes"] = rng.choice([[_bad_index(rng, n_nodes)], [0, 0], [], None])
        else:
            doc["scenes"] = []
    elif op == 16 and blob is not None and len(blob) >= 4:  # NaN/inf/huge floats in the binary data
        for _ in range(rng.choice([1, 4, 32])):
            k = rng.randrange(len(blob) // 4) * 4
            blob[k:k + 4] = f32(rng.choice(FLOAT_SPECIALS))
    elif op == 17 and blob is not None:  # truncated binary chunk
        del blob[rng.randrange(len(blob) + 1):]
    elif op == 18:  # delete a random key somewhere
        _delete_random(doc, rng)
    elif op == 19:  # replace a random value somewhere with something of another type
        _replace_random(doc, rng)
    elif op == 20:  # drop a whole top-level array
        key = rng.choice(["accessors", "bufferViews", "buffers", "nodes", "meshes", "materials",
                          "textures", "images", "animations", "scenes", "asset"])
        doc.pop(key, None)
    elif op == 21 and (p := _pick(rng, doc, "accessors")):  # min/max, NaN in JSON
        items, i = p
        items[i]["max"] = _bad_vector(rng, 3)
        items[i]["min"] = _bad_vector(rng, 3)
    elif op == 22:  # a huge array of nodes / a deep chain of children
        depth = rng.choice([100, 1000, 5000])
        base = len(doc.setdefault("nodes", []))
        doc["nodes"].extend({"children": [base + k + 1]} for k in range(depth - 1))
        doc["nodes"].append({})
        if doc.get("scenes"):
            doc["scenes"][0].setdefault("nodes", []).append(base)
    else:  # extensions / asset version
        doc["asset"] = rng.choice([{"version": "2.0"}, {"version": "1.0"}, {"version": 2}, {}, None])
        if rng.random() < 0.3:
            doc["extensionsRequired"] = ["KHR_draco_mesh_compression"]


def _containers(node: Any, out: list) -> list:
    if isinstance(node, dict):
        out.append(node)
        for v in node.values():
            _containers(v, out)
    elif isinstance(node, list):
        out.append(node)
        for v in node:
            _containers(v, out)
    return out


def _delete_random(doc: dict, rng: random.Random) -> None:
    holders = [c for c in _containers(doc, []) if c]
    if holders:
        c = rng.choice(holders)
        if isinstance(c, dict):
            del c[rng.choice(list(c))]
        else:
            del c[rng.randrange(len(c))]


def _replace_random(doc: dict, rng: random.Random) -> None:
    holders = [c for c in _containers(doc, []) if c]
    if holders:
        c = rng.choice(holders)
        key = rng.choice(list(c)) if isinstance(c, dict) else rng.randrange(len(c))
        c[key] = rng.choice([None, True, 0, -1, 2**31, 1e300, float("nan"), "", "x", [], {}, [0] * 3,
                             {"a": 1}])


def mutate_gltf(files: dict[str, bytes | int], main: str, rng: random.Random) -> dict[str, bytes | int]:
    """Structure-aware mutation of a .glb or .gltf (with its side files); sometimes bytes too."""
    files = dict(files)
    raw = files[main]
    assert isinstance(raw, bytes)
    glb = main.endswith(".glb")
    try:
        if glb:
            doc, blob_bytes = unpack_glb(raw)
            blob: bytearray | None = bytearray(blob_bytes)
        else:
            doc, blob = json.loads(raw.decode("utf-8")), None
            if isinstance(doc, dict) and doc.get("buffers") and rng.random() < 0.3:
                uri = doc["buffers"][0].get("uri")
                if isinstance(files.get(uri), bytes):  # mutate the .bin side file's floats
                    side = bytearray(files[uri])
                    for _ in range(rng.choice([1, 8])):
                        if len(side) >= 4:
                            k = rng.randrange(len(side) // 4) * 4
                            side[k:k + 4] = f32(rng.choice(FLOAT_SPECIALS))
                    files[uri] = bytes(side)
    except Exception:
        files[main] = mutate_bytes(raw, rng)
        return files
    for _ in range(rng.choice([1, 1, 1, 2, 2, 3, 5])):
        try:
            mutate_gltf_doc(doc, blob, rng, files)
        except (AttributeError, TypeError, KeyError, IndexError, ValueError):
            pass  # an earlier mutation left no room for this one (e.g. "nodes" is no longer a list)
    if glb:
        packed = pack_glb(doc, bytes(blob) if blob is not None else None)
        if rng.random() < 0.08:
            packed = mutate_bytes(packed, rng, 1)  # container-level damage: lengths, magic, chunk types
        files[main] = packed
    else:
        files[main] = json.dumps(doc).encode("utf-8")
        if rng.random() < 0.05:
            files[main] = mutate_bytes(json.dumps(doc).encode("utf-8"), rng, 1)
    return files


# -- OBJ / PLY -------------------------------------------------------------------------------------
OBJ_LINES = ["f 1 2 3", "f 1 2 999999", "f 0 1 2", "f -1 -2 -3", "f -99999 1 2", "f 1/1/1 2/2/2 3/3/3",
             "f 1//1 2//999 3//1", "f 1/999 2/1 3/1", "f 1", "f", "v nan nan nan", "v inf 0 0", "v 1e39 0 0",
             "v 1 2", "v", "vt 0.5", "vt nan 1", "vn 0 0 0", "vn nan 0 0", "usemtl missing", "usemtl",
             "mtllib missing.mtl", "mtllib ../outside.mtl", "mtllib /etc/hostname", "mtllib", "o", "g",
             "s off", "l 1 2", "p 1", "v 1 2 3 4 5 6 7", "v 1 2 3 2 2 2"]
MTL_LINES = ["d nan", "d inf", "d -1", "d 2", "d", "d x", "Tr 0.5", "Kd 1", "Kd nan 0 0", "Kd 2 2 2",
             "Kd 1e39 0 0", "map_Kd missing.png", "map_Kd ../x.png", "map_Kd /etc/hostname",
             "map_Kd -imfchan m skin.png", "map_Kd -s 1 1 1", "map_d skin.png", "map_Kd", "newmtl",
             "newmtl body", "illum 99", "Ns nan", "map_Kd -o nan nan nan skin.png", "map_Kd file:///x.png"]


def _mutate_lines(text: str, rng: random.Random, pool: list[str]) -> str:
    lines = text.split("\n")
    for _ in range(rng.choice([1, 1, 2, 3])):
        k = rng.randrange(len(lines) + 1)
        if rng.random() < 0.5:
            lines.insert(k, rng.choice(pool))
        elif k < len(lines):
            lines[k] = rng.choice(pool)
    return "\n".join(lines)


def mutate_obj(files: dict[str, bytes | int], main: str, rng: random.Random) -> dict[str, bytes | int]:
    files = dict(files)
    mtl = next((n for n in files if n.endswith(".mtl")), None)
    png = [n for n in files if n.endswith(".png")]
    roll = rng.random()
    if roll < 0.45:
        text = files[main].decode("utf-8", "replace")  # type: ignore[union-attr]
        text = _mutate_lines(text, rng, OBJ_LINES) if rng.random() < 0.6 else mutate_text(text, rng)
        files[main] = text.encode("utf-8", "surrogatepass")
    elif roll < 0.7 and mtl:
        text = files[mtl].decode("utf-8", "replace")  # type: ignore[union-attr]
        text = _mutate_lines(text, rng, MTL_LINES) if rng.random() < 0.7 else mutate_text(text, rng)
        files[mtl] = text.encode("utf-8", "surrogatepass")
    elif roll < 0.85 and png:
        name = rng.choice(png)
        files[name] = mutate_png(files[name], rng)  # type: ignore[arg-type]
    elif roll < 0.92 and mtl:
        del files[mtl]
    else:
        files[main] = mutate_bytes(files[main], rng)  # type: ignore[arg-type]
    return files


PLY_HEADER_LINES = ["element vertex 0", "element vertex 4294967295", "element vertex 1000000000",
                    "element vertex -1", "element face 4294967295", "element face 1000000",
                    "property float radius", "property uchar red", "property double density",
                    "property list uchar int vertex_indices", "property list uint int vertex_indices",
                    "property list uchar float vertex_indices", "property int128 x", "property float",
                    "format ascii 1.0", "format binary_big_endian 1.0", "format binary_little_endian 1.0",
                    "format binary 2.0", "comment TextureFile missing.png", "comment TextureFile ../x.png",
                    "comment TextureFile /etc/hostname", "obj_info x", "element", "end_header"]


def mutate_ply(files: dict[str, bytes | int], main: str, rng: random.Random) -> dict[str, bytes | int]:
    files = dict(files)
    raw = files[main]
    assert isinstance(raw, bytes)
    end = raw.find(b"end_header")
    png = [n for n in files if n.endswith(".png")]
    roll = rng.random()
    if roll < 0.5 and end >= 0:
        cut = raw.index(b"\n", end) + 1 if b"\n" in raw[end:] else len(raw)
        header, body = raw[:cut].decode("ascii", "replace"), raw[cut:]
        lines = header.rstrip("\n").split("\n")
        for _ in range(rng.choice([1, 1, 2, 3])):
            k = rng.randrange(1, max(2, len(lines) - 1))
            if rng.random() < 0.3:
                lines.insert(k, rng.choice(PLY_HEADER_LINES))
            elif rng.random() < 0.5:
                lines[k] = rng.choice(PLY_HEADER_LINES)
            else:
                toks = lines[k].split()
                if toks:
                    toks[rng.randrange(len(toks))] = interesting_token(rng)
                    lines[k] = " ".join(toks)
        if b"format ascii" in raw[:cut] and rng.random() < 0.5:
            body = mutate_text(body.decode("ascii", "replace"), rng).encode("utf-8", "surrogatepass")
        elif rng.random() < 0.3:
            body = body[: rng.randrange(len(body) + 1)]
        files[main] = ("\n".join(lines) + "\n").encode("utf-8", "surrogatepass") + body
    elif roll < 0.65 and png:
        name = rng.choice(png)
        files[name] = mutate_png(files[name], rng)  # type: ignore[arg-type]
    elif roll < 0.85 and end >= 0:  # NaN/inf/huge floats and face indices in the body
        buf = bytearray(raw)
        start = end + 11
        for _ in range(rng.choice([1, 4, 16])):
            if len(buf) - start >= 4:
                k = rng.randrange(start, len(buf) - 3)
                buf[k:k + 4] = f32(rng.choice(FLOAT_SPECIALS)) if rng.random() < 0.6 \
                    else struct.pack("<i", rng.choice(INT_SPECIALS[:12] + [-1, -(2**31)]))
        files[main] = bytes(buf)
    else:
        files[main] = mutate_bytes(raw, rng)
    return files
