"""What a written glTF asks of the clients that will read it, said as notes: files past what
fishgen's own viewers read, and animations past what Godot 3 plays. The file is written either way
(an engine loads it); the note saves a user from finding out there."""
from __future__ import annotations

import json
import os
import struct
from pathlib import Path

MAX_EMBED_BYTES = 256 << 20
"""`fishgen view` embeds at most this much in its page: beyond it a browser struggles with a base64
page, and such assets need a desktop tool."""

GODOT3_TRACKS = 1024
"""Godot 3 updates at most this many animated nodes, and as many animated properties (a mesh's
blend-shape weights, one a morph target), each frame (``NODE_CACHE_UPDATE_MAX``); the rest stand
still, with an error line a frame. A swimming BonyBream animates 5 nodes and 36 weights, so a
school of more than 28 passes it; with ``--swim fins``, 6 nodes and no weights: 170 (QA pass 14:
29 of 200 such fish frozen, and 203,808 error lines for the swimming school of 200).
``--merge`` animates fewer, but Godot 3 puts a merged school's fish on one fish's bones."""


def notes(written: tuple[os.PathLike | str, ...]) -> list[str]:
    """One note a limit each written glTF (``.glb``, ``.gltf``, and its ``.bin``) passes."""
    from fishgen.atomic import where_now

    out: list[str] = []
    for path in map(Path, written):
        suffix = path.suffix.lower()
        if suffix not in (".glb", ".gltf", ".bin"):
            continue
        now = where_now(path)      # a school's files are staged until its summary is out
        try:
            size = now.stat().st_size
        except OSError:
            continue
        out += _too_big(path, size)
        if suffix != ".bin":
            out += _godot3(path, now)
    return out


def _too_big(path: Path, size: int) -> list[str]:
    """`sky --billboards --particles 1200000` wrote 528 MiB that `preview` and `fly` then refused."""
    from fishgen.exchange.gltf_container import MAX_FILE_BYTES

    mib, read, embed = f"{size / 2**20:,.0f} MiB", MAX_FILE_BYTES >> 20, MAX_EMBED_BYTES >> 20
    if size > MAX_FILE_BYTES:
        return [f"{path}: {mib}, more than `fishgen preview` and `fishgen fly` read ({read} MiB) "
                f"or `fishgen view` embeds ({embed} MiB); engines load it"]
    if size > MAX_EMBED_BYTES:
        return [f"{path}: {mib}, more than `fishgen view` embeds in a page ({embed} MiB); "
                "`fishgen preview`, `fishgen fly` and engines load it"]
    return []


def _godot3(path: Path, now: Path) -> list[str]:
    doc = _json_of(now)
    if doc is None:
        return []
    nodes, meshes = doc.get("nodes", []), doc.get("meshes", [])
    moved: set[int] = set()
    weights = 0
    for animation in doc.get("animations", []):
        for channel in animation.get("channels", []):
            target = channel.get("target", {})
            node = target.get("node")
            if not isinstance(node, int) or not 0 <= node < len(nodes):
                continue
            if target.get("path") == "weights":
                mesh = nodes[node].get("mesh")
                primitives = meshes[mesh].get("primitives", []) if isinstance(mesh, int) else []
                weights += len(primitives[0].get("targets", [])) if primitives else 0
            else:
                moved.add(node)
    over = [f"{n:,} {what}" for n, what in ((weights, "blend-shape weights"), (len(moved), "nodes"))
            if n > GODOT3_TRACKS]
    if not over:
        return []
    return [f"{path}: animates {' and '.join(over)}; Godot 3 plays at most {GODOT3_TRACKS:,} of each "
            "and leaves the rest still (schools in Godot 3: docs/clients.md)"]


def _json_of(path: Path) -> dict | None:
    """The glTF JSON of a .gltf, or of a .glb's first chunk, read without its binary chunk."""
    try:
        with path.open("rb") as handle:
            head = handle.read(20)
            if head[:4] != b"glTF":
                handle.seek(0)
                raw = handle.read()
            elif len(head) == 20 and struct.unpack_from("<I", head, 16)[0] == 0x4E4F534A:
                raw = handle.read(struct.unpack_from("<I", head, 12)[0])
            else:
                return None
        doc = json.loads(raw)
    except (OSError, ValueError):
        return None
    return doc if isinstance(doc, dict) else None
