"""Exporters, one module per format behind one entry point chosen by file extension."""
from __future__ import annotations

import importlib
import os
from pathlib import Path

from fishgen.errors import FishgenError

#: extension -> (module, function); each writer takes (asset, path) and writes atomically.
WRITERS = {
    ".glb": ("fishgen.exchange.gltf", "write_glb"),
    ".gltf": ("fishgen.exchange.gltf", "write_gltf"),
    ".obj": ("fishgen.exchange.obj", "write_obj"),
    ".ply": ("fishgen.exchange.ply", "write_ply"),
}


def export(asset, path: str | os.PathLike) -> list[Path]:
    """Write ``asset`` to ``path`` in the format its extension names; returns the files written."""
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in WRITERS:
        raise FishgenError(f"expected an output ending in {', '.join(WRITERS)}, found {path.name!r}")
    module, name = WRITERS[ext]
    return getattr(importlib.import_module(module), name)(asset, path)
