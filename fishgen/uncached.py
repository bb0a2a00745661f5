"""A file writer that sends big outputs past the page cache (``O_DIRECT`` where the system has it).

Why: on the virtual machines CI and users run on, the first touch of a page the host has not
backed costs about 3 ns a byte, and a buffered write of a fresh file fills the page cache with
such pages. Writing 230 MB (a 10^7-particle PLY) took 0.6-0.9 s buffered plus its fsync, and
0.1 s straight from one reused, page-aligned buffer (docs/decisions.md, "Writing past the page
cache"). The bytes written are the same either way.

Everything written is staged in one page-aligned buffer of :data:`BLOCK` bytes. A file that never
fills it (almost every output) is written in one ordinary write at :meth:`UncachedWriter.flush`. Each
full buffer is written with ``O_DIRECT``; the tail, which is not a whole number of blocks, goes
through the page cache, as does everything where ``O_DIRECT`` is missing or refused (another
system, a file system without it, an odd block size).
"""
from __future__ import annotations

import errno
import mmap
import os
from typing import Any, BinaryIO, cast

BLOCK = 8 << 20
"""Bytes staged before a direct write: a whole number of blocks on any device (4096 divides it)."""

_O_DIRECT: int = getattr(os, "O_DIRECT", 0)


def _set_direct(fd: int, on: bool) -> bool:
    """Turn O_DIRECT on or off for ``fd``; False where the system or the file system refuses."""
    if not _O_DIRECT:
        return False
    try:
        import fcntl

        flags = fcntl.fcntl(fd, fcntl.F_GETFL)
        fcntl.fcntl(fd, fcntl.F_SETFL, flags | _O_DIRECT if on else flags & ~_O_DIRECT)
    except (ImportError, OSError):
        return False
    return True


class UncachedWriter:
    """A binary handle over ``raw`` (an unbuffered file) for :mod:`fishgen.atomic`'s writers."""

    def __init__(self, raw: Any):
        self._raw = raw
        self._buffer: mmap.mmap | None = None   # made at the first write: an unused handle needs none
        self._used = 0
        self._direct: bool | None = None       # None: untried; False once the offset is unaligned

    def write(self, data: Any) -> int:
        piece = memoryview(data).cast("B")
        if self._buffer is None:
            self._buffer = mmap.mmap(-1, BLOCK)   # page-aligned, as O_DIRECT needs
        view = memoryview(self._buffer)
        done = 0
        while done < len(piece):
            take = min(len(piece) - done, BLOCK - self._used)
            view[self._used:self._used + take] = piece[done:done + take]
            self._used += take
            done += take
            if self._used == BLOCK:
                self._write_block()
        return done

    def _write_block(self) -> None:
        assert self._buffer is not None
        fd = self._raw.fileno()
        if self._direct is None:
            self._direct = _set_direct(fd, True)
        if self._direct:
            try:
                written = os.write(fd, memoryview(self._buffer))
            except OSError as err:
                if err.errno != errno.EINVAL:   # alignment the device refuses: go on through the cache
                    raise
                written = 0
            if written == BLOCK:
                self._used = 0
                return
            self._stop_direct()
            self._drain(memoryview(self._buffer)[written:BLOCK])
        else:
            self._drain(memoryview(self._buffer)[:self._used])
        self._used = 0

    def _stop_direct(self) -> None:
        if self._direct:
            _set_direct(self._raw.fileno(), False)
        self._direct = False

    def _drain(self, data: memoryview) -> None:
        while len(data):
            written = self._raw.write(data)
            data = data[written:]

    def flush(self) -> None:
        """Write what is staged: the file's tail, a partial block, through the page cache."""
        if self._used:
            assert self._buffer is not None
            self._stop_direct()
            self._drain(memoryview(self._buffer)[:self._used])
            self._used = 0

    def fileno(self) -> int:
        return int(self._raw.fileno())

    @property
    def closed(self) -> bool:
        return bool(self._raw.closed)

    def close(self) -> None:
        """Close without writing what is staged: :mod:`fishgen.atomic` flushes and syncs first, and a
        failed write is discarded anyway."""
        self._buffer = None   # unmapped once no view of it is left (a failed write's traceback may hold one)
        self._raw.close()

    def __enter__(self) -> BinaryIO:
        return cast(BinaryIO, self)

    def __exit__(self, *exc: object) -> None:
        self.close()
