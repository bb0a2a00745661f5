"""Writers and readers, one module per format, behind one entry point chosen by extension.

Which formats exist and what each can hold is declared in :mod:`fishgen.exchange.registry`.
"""
from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from fishgen.scene.model import Scene


def export(scene: Scene, path: str | os.PathLike, *, require: Iterable[str] = (), **options) -> list[Path]:
    """Write ``scene`` to ``path`` in the format its extension names; returns the files written.

    ``require`` names what the format must hold (``"node animation"`` for a
    school); a format that cannot is refused before anything is written. ``options`` (of
    ``registry.WRITER_OPTIONS``: ``voxel_size``) go to the writers that take them.
    """
    from fishgen.exchange.registry import output_format

    path = Path(path)
    return output_format(path, require).write(scene, path, **options)
