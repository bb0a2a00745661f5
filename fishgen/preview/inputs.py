"""Turn any preview input (species file, cube file, or asset) into a scene, through the format registry."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from fishgen.errors import FishgenError
from fishgen.exchange.registry import formats, input_format
from fishgen.scene.model import Scene


def input_formats():
    """Everything a preview reads: every registered format with a reader."""
    return formats(readable=True)


def load_input(path: str | os.PathLike, *, textures_dir: str | os.PathLike | None = None,
               seed: int = 0, lighting: Any = None) -> Scene:
    """Load a species file, a cube file or an asset; species and cube files are built in memory."""
    path = Path(path)
    fmt = input_format(path, kinds=input_formats(), command="preview")
    if path.is_dir():
        raise FishgenError("expected a file, found a directory", path)
    if not path.is_file():
        raise FishgenError("expected an existing file, found none", path)
    return fmt.read(path, textures_dir=textures_dir, seed=seed, lighting=lighting)
