"""The glTF container: where a glTF asset's bytes come from, and how many may come.

A .glb/.gltf file is read under the size caps below, a GLB is split into its JSON and BIN
chunks, and the JSON is parsed under caps of its own. The bytes that buffers and images point
to come from here too: ``data:`` URIs, and side files, read only from the asset's own folder.
Every size is checked, by length or by stat, before anything is read or decoded. Nothing here
knows the document's structure (:mod:`fishgen.exchange.gltf_checks` does).
"""
from __future__ import annotations

import base64
import binascii
import json
import struct
from pathlib import Path
from typing import Any

from fishgen.errors import FishgenError, describe, expected
from fishgen.exchange.guards import size_text
from fishgen.exchange.sidefiles import side_file

MAX_FILE_BYTES = 512 * 2**20
"""Largest .glb/.gltf file, and largest buffer or image side file, checked by stat before reading."""
MAX_JSON_BYTES = 128 * 2**20
"""Largest JSON part (a .gltf file, or a GLB's JSON chunk)."""
MAX_JSON_ITEMS = 2_000_000
"""Most JSON arrays, objects and commas: a few hundred MB of Python objects at worst."""
MAX_DATA_URI_CHARS = 64 * 2**20
"""Longest ``data:`` URI (buffer or image), checked before decoding."""

_GLB_MAGIC, _CHUNK_JSON, _CHUNK_BIN = b"glTF", 0x4E4F534A, 0x004E4942
_NOT_GLTF = "a glTF 2.0 file (JSON, or GLB with a 12-byte header)"


def read_capped(path: Path, where: str) -> bytes:
    """The file's bytes, once its size (by stat) is within the caps."""
    try:
        size = path.stat().st_size
    except OSError as err:
        raise FishgenError(f"expected a readable file, found {type(err).__name__}", where) from None
    if size > MAX_FILE_BYTES:
        raise expected(f"a glTF file of at most {size_text(MAX_FILE_BYTES)}", size_text(size))
    if size > MAX_JSON_BYTES:  # only a GLB may be this big: its bulk is binary
        with path.open("rb") as f:
            if f.read(4) != _GLB_MAGIC:
                raise expected(f"a glTF JSON file of at most {size_text(MAX_JSON_BYTES)} "
                               "(keep big data in .bin files or a .glb)", size_text(size))
    return path.read_bytes()


def unpack(data: bytes) -> tuple[dict, memoryview | None]:
    """The JSON document and the GLB BIN chunk (None for a .gltf)."""
    if bytes(data[:4]) != _GLB_MAGIC:
        return _parse_json(data), None
    if len(data) < 12:
        raise expected(_NOT_GLTF, f"{len(data)} bytes")
    _, version, length = struct.unpack_from("<4sII", data)
    if version != 2:
        raise expected("a GLB of version 2", f"version {version}")
    if length != len(data):
        raise expected(f"a GLB of {length:,} bytes, as its header says", f"{len(data):,} bytes")
    view = memoryview(data)
    chunks: list[tuple[int, memoryview]] = []
    offset = 12
    while offset < length:
        if offset + 8 > length:
            raise expected("an 8-byte GLB chunk header", f"{length - offset} bytes at byte {offset}")
        clen, ctype = struct.unpack_from("<II", data, offset)
        if offset + 8 + clen > length:
            raise expected(f"a GLB chunk of {clen:,} bytes within the file",
                           f"{length - offset - 8:,} bytes left at byte {offset}")
        chunks.append((ctype, view[offset + 8: offset + 8 + clen]))
        offset += 8 + clen
    if not chunks or chunks[0][0] != _CHUNK_JSON:
        raise expected("a JSON chunk first in the GLB",
                       "none" if not chunks else f"chunk type {chunks[0][0]:#x}")
    if len(chunks[0][1]) > MAX_JSON_BYTES:
        raise expected(f"a JSON chunk of at most {size_text(MAX_JSON_BYTES)}", size_text(len(chunks[0][1])))
    blob = chunks[1][1] if len(chunks) > 1 and chunks[1][0] == _CHUNK_BIN else None
    return _parse_json(bytes(chunks[0][1])), blob


def _no_constant(name: str) -> Any:
    raise expected("finite JSON numbers", name)


def _parse_json(raw: bytes) -> dict:
    if len(raw) > MAX_JSON_BYTES:
        raise expected(f"a glTF JSON document of at most {size_text(MAX_JSON_BYTES)}", size_text(len(raw)))
    items = raw.count(b",") + raw.count(b"[") + raw.count(b"{")
    if items > MAX_JSON_ITEMS:
        raise expected(f"a JSON document of at most {MAX_JSON_ITEMS:,} items", f"{items:,}")
    try:
        text = bytes(raw).decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise expected(_NOT_GLTF, f"bytes that are not UTF-8 at byte {err.start}") from None
    try:
        doc = json.loads(text, parse_constant=_no_constant)
    except json.JSONDecodeError as err:
        raise expected(_NOT_GLTF,
                       f"invalid JSON at line {err.lineno} column {err.colno} ({err.msg})") from None
    except RecursionError:
        raise expected(_NOT_GLTF, "JSON nested too deeply") from None
    if not isinstance(doc, dict):
        raise expected(f"{_NOT_GLTF} holding a JSON object", f"a JSON {type(doc).__name__}")
    return doc


# -- what buffers and images point to -------------------------------------------------
def sized_uri(asset: Path | None, uri: str, where: str, what: str) -> tuple[Path, int] | None:
    """Check a buffer's or image's URI against the caps by its length or its file's stat size,
    before anything is read: (side file, size), or None for an inline data: URI."""
    if uri.strip().startswith("data:"):
        if len(uri) > MAX_DATA_URI_CHARS:
            raise expected(f"a data URI of at most {size_text(MAX_DATA_URI_CHARS)} at {where}",
                           size_text(len(uri)))
        return None
    target = side_path(asset, uri)
    size = target.stat().st_size
    if size > MAX_FILE_BYTES:
        raise expected(f"{what} file of at most {size_text(MAX_FILE_BYTES)} at {where}",
                       f"{describe(uri)} of {size_text(size)}")
    return target, size


def side_path(asset: Path | None, uri: str) -> Path:
    """The existing file ``uri`` names beside ``asset`` (None: GLB bytes from memory)."""
    if asset is None:  # GLB bytes from memory have no folder to take side files from
        raise expected("only embedded data", f"a reference to {describe(uri)}")
    # Only files in the asset's folder (glTF URIs are percent-encoded: "my%20skin.png").
    target = side_file(asset, uri, uri=True)
    if not target.is_file():
        raise expected("a file beside the asset", f"no {uri!r}")
    return target


def data_uri(uri: str, where: str) -> bytes:
    """The bytes of a ``data:`` URI, base64 or plain."""
    head, _, payload = uri.strip().partition(",")
    try:
        return base64.b64decode(payload, validate=True) if head.endswith(";base64") else \
            payload.encode("latin-1")
    except (binascii.Error, ValueError, UnicodeEncodeError):
        raise expected(f"base64 data in the data URI at {where}", "other characters") from None
