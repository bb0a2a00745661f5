"""glTF 2.0 export: a POINTS primitive, or camera-facing-at-rest billboards.

Points carry POSITION, COLOR_0 and the application-specific ``_RADIUS`` and
``_DENSITY`` attributes (glTF requires custom attribute names to start with
``_``). Billboards are one quad per particle in the XY plane, facing +Z (the
glTF front), sized by the particle radius and textured with a radial Gaussian
alpha sprite, for engines that cannot size points. A ``.glb`` is streamed to
disk; a ``.gltf`` is written beside a ``.bin`` of the same stem, both atomically.
"""
from __future__ import annotations

import json
import os
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterator
from urllib.parse import quote

import numpy as np

from fishgen.atomic import atomic_open, write_files
from fishgen.clouds.export.sprite import gaussian_sprite_png
from fishgen.clouds.model import Cloud
from fishgen.errors import FishgenError

GENERATOR = "fishgen clouds"
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
FLOAT, UNSIGNED_BYTE, UNSIGNED_INT = 5126, 5121, 5125
GLB_LIMIT = 2**32 - 1
ROWS = 1 << 16  # particles per streamed block


@dataclass
class _View:
    """One bufferView: its size, how to produce its bytes block by block, its JSON."""

    length: int
    blocks: Callable[[], Iterator[bytes]]
    json: dict


def write_gltf(cloud: Cloud, path: str | os.PathLike, *, billboards: bool = False) -> None:
    """Write ``.glb`` or ``.gltf`` (+ ``.bin``) for the cloud."""
    path = Path(path)
    if len(cloud) == 0:
        raise FishgenError("expected at least 1 particle to export, found 0", path)
    views, accessors, primitive, extra = (_billboards if billboards else _points)(cloud)

    offset = 0
    for view in views:
        view.json.update(buffer=0, byteOffset=offset, byteLength=view.length)
        offset += _pad4(view.length)
    if offset > GLB_LIMIT:
        per = offset // len(cloud)
        raise FishgenError(f"expected at most {GLB_LIMIT // per:,} particles for "
                           f"{'--billboards ' if billboards else ''}glTF (4 GiB buffer limit), "
                           f"found {len(cloud):,}", path)

    doc = {
        "asset": {"version": "2.0", "generator": GENERATOR},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "cloud"}],
        "meshes": [{"name": "cloud", "primitives": [primitive]}],
        "accessors": accessors,
        "bufferViews": [view.json for view in views],
        "buffers": [{"byteLength": offset}],
        **extra,
    }

    def body() -> Iterator[bytes]:
        for view in views:
            for block in view.blocks():
                yield block
            yield b"\0" * (_pad4(view.length) - view.length)

    if path.suffix.lower() == ".gltf":
        bin_path = path.with_suffix(".bin")
        # A URI, not a file name: "a%20b.bin" would load "a b.bin", "x#y.bin" only "x".
        doc["buffers"][0]["uri"] = quote(bin_path.name)
        text = json.dumps(doc, indent=1).encode("utf-8")
        write_files({path: text, bin_path: b"".join(body())})
        return

    text = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    text += b" " * (_pad4(len(text)) - len(text))
    total = 12 + 8 + len(text) + 8 + offset
    with atomic_open(path) as handle:
        handle.write(struct.pack("<4sII", b"glTF", 2, total))
        handle.write(struct.pack("<I4s", len(text), b"JSON") + text)
        handle.write(struct.pack("<I4s", offset, b"BIN\0"))
        for block in body():
            handle.write(block)


def _srgb_to_linear_lut() -> np.ndarray:
    c = np.arange(256) / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return np.round(lin * 255.0).astype(np.uint8)


#: Cloud colours are sRGB bytes (as PLY/CSV carry them); glTF defines COLOR_0 as linear.
SRGB_TO_LINEAR = _srgb_to_linear_lut()


def _pad4(n: int) -> int:
    return (n + 3) & ~3


def _blocks(cloud: Cloud, make: Callable[[int, int], np.ndarray]) -> Callable[[], Iterator[bytes]]:
    def gen() -> Iterator[bytes]:
        for start in range(0, len(cloud), ROWS):
            block = np.ascontiguousarray(make(start, min(start + ROWS, len(cloud))))
            yield memoryview(block).cast("B")
    return gen


def _accessor(view: int, component: int, count: int, kind: str, **more) -> dict:
    return {"bufferView": view, "componentType": component, "count": count, "type": kind, **more}


def _bounds(points: np.ndarray) -> dict:
    # The validator checks these against the data, so they are the exact float32 values.
    return {"min": [float(v) for v in points.min(axis=0)],
            "max": [float(v) for v in points.max(axis=0)]}


def _points(cloud: Cloud):
    n = len(cloud)

    def colours(a: int, b: int) -> np.ndarray:
        # A VEC3 of bytes is padded to a 4-byte stride, as vertex attributes must be aligned.
        out = np.zeros((b - a, 4), np.uint8)
        out[:, :3] = SRGB_TO_LINEAR[cloud.colors[a:b]]
        return out

    views = [
        _View(n * 12, _blocks(cloud, lambda a, b: cloud.centers[a:b]), {"target": ARRAY_BUFFER}),
        _View(n * 4, _blocks(cloud, colours), {"target": ARRAY_BUFFER, "byteStride": 4}),
        _View(n * 4, _blocks(cloud, lambda a, b: cloud.radii[a:b]), {"target": ARRAY_BUFFER}),
        _View(n * 4, _blocks(cloud, lambda a, b: cloud.density[a:b]), {"target": ARRAY_BUFFER}),
    ]
    accessors = [
        _accessor(0, FLOAT, n, "VEC3", **_bounds(cloud.centers)),
        _accessor(1, UNSIGNED_BYTE, n, "VEC3", normalized=True),
        _accessor(2, FLOAT, n, "SCALAR"),
        _accessor(3, FLOAT, n, "SCALAR"),
    ]
    primitive = {"attributes": {"POSITION": 0, "COLOR_0": 1, "_RADIUS": 2, "_DENSITY": 3},
                 "mode": 0}
    return views, accessors, primitive, {}


_CORNERS = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], np.float32)
_UVS = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
_QUAD = np.array([0, 1, 2, 0, 2, 3], np.uint32)


def _billboards(cloud: Cloud):
    n = len(cloud)

    def corners(a: int, b: int) -> np.ndarray:
        out = np.repeat(cloud.centers[a:b, None, :], 4, axis=1)
        out[:, :, :2] += _CORNERS[None] * cloud.radii[a:b, None, None]
        return out

    def colours(a: int, b: int) -> np.ndarray:
        # Vertex alpha carries the density, so the sprite fades more where the cloud is thin.
        rgba = np.empty((b - a, 4), np.uint8)
        rgba[:, :3] = SRGB_TO_LINEAR[cloud.colors[a:b]]
        rgba[:, 3] = np.round(cloud.density[a:b] * 255)
        return np.repeat(rgba[:, None, :], 4, axis=1)

    # Bounds of every corner, block by block rather than building all corners at once.
    lo = np.full(3, np.inf, np.float32)
    hi = np.full(3, -np.inf, np.float32)
    for start in range(0, n, ROWS):
        quad = corners(start, min(start + ROWS, n)).reshape(-1, 3)
        lo = np.minimum(lo, quad.min(axis=0))
        hi = np.maximum(hi, quad.max(axis=0))
    sprite = gaussian_sprite_png()

    views = [
        _View(n * 48, _blocks(cloud, corners), {"target": ARRAY_BUFFER}),
        _View(n * 32, _blocks(cloud, lambda a, b: np.broadcast_to(_UVS, (b - a, 4, 2))),
              {"target": ARRAY_BUFFER}),
        _View(n * 16, _blocks(cloud, colours), {"target": ARRAY_BUFFER}),
        _View(n * 24, _blocks(cloud, lambda a, b: (np.arange(a, b, dtype=np.uint32)[:, None] * 4
                                                   + _QUAD[None])),
              {"target": ELEMENT_ARRAY_BUFFER}),
        _View(len(sprite), lambda: iter([sprite]), {}),
    ]
    accessors = [
        _accessor(0, FLOAT, 4 * n, "VEC3", min=[float(v) for v in lo], max=[float(v) for v in hi]),
        _accessor(1, FLOAT, 4 * n, "VEC2"),
        _accessor(2, UNSIGNED_BYTE, 4 * n, "VEC4", normalized=True),
        _accessor(3, UNSIGNED_INT, 6 * n, "SCALAR"),
    ]
    primitive = {"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "COLOR_0": 2}, "indices": 3,
                 "material": 0, "mode": 4}
    extra = {
        "extensionsUsed": ["KHR_materials_unlit"],
        "materials": [{
            "name": "cloud particle",
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                     "metallicFactor": 0.0, "roughnessFactor": 1.0},
            "alphaMode": "BLEND",
            "doubleSided": True,
            "extensions": {"KHR_materials_unlit": {}},
        }],
        "textures": [{"sampler": 0, "source": 0}],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 33071, "wrapT": 33071}],
        "images": [{"bufferView": 4, "mimeType": "image/png", "name": "gaussian sprite"}],
    }
    return views, accessors, primitive, extra
