"""Atomic output: write to a temporary file beside the target, then rename.

A failed or interrupted run never leaves a partial file and never clobbers a
good one. Multi-file outputs (OBJ + MTL + textures, glTF + bin + images) are
staged together and renamed only once every part was written.
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Mapping


def _stage(path: Path, data: bytes) -> str:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, 0o644)
    except BaseException:
        _discard(tmp)
        raise
    return tmp


def _discard(tmp: str) -> None:
    try:
        os.unlink(tmp)
    except FileNotFoundError:
        pass


def write_files(files: Mapping[str | os.PathLike, bytes]) -> None:
    """Write every ``path -> bytes`` entry atomically, all or (as far as possible) nothing."""
    staged: list[tuple[str, Path]] = []
    try:
        for path, data in files.items():
            target = Path(path)
            staged.append((_stage(target, data), target))
    except BaseException:
        for tmp, _ in staged:
            _discard(tmp)
        raise
    for tmp, target in staged:
        os.replace(tmp, target)


def write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write one file atomically."""
    write_files({path: data})


class atomic_open:
    """Context manager yielding a binary file handle for streaming writes.

    The data goes to a temporary file beside ``path``; it replaces ``path`` only
    when the ``with`` block finishes without an exception.
    """

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)
        self._tmp: str | None = None
        self._handle = None

    def __enter__(self):
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd, self._tmp = tempfile.mkstemp(prefix=f".{self.path.name}.", suffix=".tmp",
                                         dir=self.path.parent)
        self._handle = os.fdopen(fd, "wb")
        return self._handle

    def __exit__(self, exc_type, exc, tb) -> bool:
        assert self._handle is not None and self._tmp is not None
        try:
            if exc_type is None:
                self._handle.flush()
                os.fsync(self._handle.fileno())
            self._handle.close()
            if exc_type is None:
                os.chmod(self._tmp, 0o644)
                os.replace(self._tmp, self.path)
                return False
        except BaseException:
            _discard(self._tmp)
            raise
        _discard(self._tmp)
        return False
