"""A file writer that sends big outputs past the page cache (``O_DIRECT`` where the system has it).

Why: on the virtual machine fishgen is developed and tested on, the first touch of a page the
host has not backed costs about 3 ns a byte, and a buffered write of a fresh file fills the page
cache with such pages. Writing 230 MB (a 10^7-particle PLY) took 0.6-0.9 s buffered plus its fsync
when its pages were fresh, and 0.1 s straight from one page-aligned buffer (docs/decisions.md,
"Third round: writing past the page cache"). The bytes written are the same either way.

What is written is staged in a page-aligned buffer of :data:`BLOCK` bytes, reused from file to
file. A file that never fills it (almost every output) is written in one ordinary write when
flushed. Each full buffer is written with ``O_DIRECT``; what is left at the end (under a buffer's
worth, so not a whole number of blocks) goes through the page cache, as does everything where
``O_DIRECT`` is missing or refused (another system, a file system without it, an odd block size, a
short write).
"""
from __future__ import annotations

import errno
import io
import mmap
import os
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from concurrent.futures import Future, ThreadPoolExecutor

BLOCK = 8 << 20
"""Bytes staged before a direct write: a whole number of blocks on any device (4096 divides it)."""

_O_DIRECT: int = getattr(os, "O_DIRECT", 0)
_spare: list[mmap.mmap] = []
"""Buffers no writer holds: the next file reuses one, so a small file's bytes land in warm pages."""


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


def _take_buffer() -> mmap.mmap:
    try:
        return _spare.pop()            # atomic under the GIL: two threads never get the same one
    except IndexError:
        pass
    private = {"flags": mmap.MAP_PRIVATE} if hasattr(mmap, "MAP_PRIVATE") else {}
    try:
        return mmap.mmap(-1, BLOCK, **private)   # page-aligned, as O_DIRECT needs; never shared with a child
    except OSError as err:
        if err.errno == errno.ENOMEM:  # an address-space limit: out of memory, not a write that failed
            raise MemoryError(f"cannot map a {BLOCK >> 20} MiB write buffer") from None
        raise


SPARES = 2
"""Most buffers kept for the next writers: a big file's two (one filled while one is written)."""


def _give_back(buffer: mmap.mmap) -> None:
    if len(_spare) < SPARES:
        _spare.append(buffer)


class UncachedWriter(io.RawIOBase):
    """A binary handle over ``raw`` (an unbuffered file) for :mod:`fishgen.atomic`'s writers.

    A full buffer is written on a thread of its own while the caller fills the next one, so the
    disk's time and the caller's packing overlap, as the page cache's writeback let them before.
    One block at a time is in flight, so the file's bytes stay in order; its error is raised at
    the next write, flush or close."""

    def __init__(self, raw: Any):
        super().__init__()
        self._raw = raw
        self._buffer: mmap.mmap | None = None   # taken at the first write: an unused handle needs none
        self._used = 0
        self._accepted = int(raw.tell())
        self._direct: bool | None = None       # None: untried; False once the offset is unaligned
        self._worker: ThreadPoolExecutor | None = None
        self._writing: Future[None] | None = None
        self._failed: BaseException | None = None   # a block's write that failed: the file is short

    def _check_failed(self) -> None:
        if self._failed is not None:
            raise OSError(getattr(self._failed, "errno", None) or errno.EIO,
                          f"an earlier block was not written ({self._failed})")

    def writable(self) -> bool:
        return True

    def write(self, data: Any) -> int:
        self._checkClosed()
        self._check_failed()
        with memoryview(data) as given, given.cast("B") as piece:
            done = 0
            while done < len(piece):
                if self._buffer is None:
                    self._buffer = _take_buffer()
                take = min(len(piece) - done, BLOCK - self._used)
                with memoryview(self._buffer) as view:
                    view[self._used:self._used + take] = piece[done:done + take]
                self._used += take
                done += take
                if self._used == BLOCK:
                    self._send()
        self._accepted += done
        return done

    def _send(self) -> None:
        """Hand the full buffer to the writing thread, once the block before it is written."""
        self._wait()
        full, self._buffer, self._used = self._buffer, None, 0
        assert full is not None
        if self._worker is None:
            from concurrent.futures import ThreadPoolExecutor

            self._worker = ThreadPoolExecutor(1, thread_name_prefix="fishgen-write")
        self._writing = self._worker.submit(self._write_block, full)

    def _wait(self) -> None:
        writing, self._writing = self._writing, None
        if writing is None:
            return
        try:
            writing.result()
        except BaseException as err:
            self._failed = err           # every later write, flush or close says so too
            raise
        finally:
            writing = None               # else frame -> future -> error -> frame keeps the file open

    def _write_block(self, full: mmap.mmap) -> None:
        try:
            fd = self._raw.fileno()
            if self._direct is None:
                self._direct = _set_direct(fd, True)
            with memoryview(full) as view:
                written = 0
                if self._direct:
                    try:
                        written = os.write(fd, view)
                    except OSError as err:
                        if err.errno != errno.EINVAL:   # alignment the device refuses: on through the cache
                            raise
                    if written != BLOCK:
                        self._stop_direct()
                if written < BLOCK:
                    self._drain(view[written:])
        finally:
            _give_back(full)

    def _stop_direct(self) -> None:
        if self._direct:
            _set_direct(self._raw.fileno(), False)
        self._direct = False

    def _drain(self, data: memoryview) -> None:
        """Write ``data`` through the page cache."""
        while len(data):
            data = data[self._raw.write(data):]

    def flush(self) -> None:
        """Write everything given: the block in flight, then what is staged (a file's end, under a
        buffer's worth) through the page cache."""
        self._wait()
        self._check_failed()
        if self._used and self._buffer is not None:
            self._stop_direct()
            with memoryview(self._buffer) as view:
                self._drain(view[:self._used])
            self._used = 0

    def tell(self) -> int:
        return self._accepted

    def fileno(self) -> int:
        return int(self._raw.fileno())

    def abort(self) -> None:
        """Close without writing what is staged, once the block in flight is done, and without
        raising its error: the file is being discarded, and the error that discards it is the one
        to report (an interrupt stays an interrupt)."""
        if self.closed:
            return
        self._used = 0
        writing, self._writing = self._writing, None
        try:
            if writing is not None:
                writing.exception()      # waits for it, raising nothing
        finally:
            writing = None
            self._failed = None
            self.close()

    def close(self) -> None:
        """Flush, close the file and hand the buffer to the next writer."""
        if self.closed:
            return
        try:
            super().close()        # flushes
        finally:
            if self._worker is not None:     # never close the file under a write in flight
                self._worker.shutdown(wait=True)
                self._writing = None
            if self._buffer is not None:
                _give_back(self._buffer)
                self._buffer = None
            self._used = 0
            self._raw.close()
