"""Signals that wait for a critical step: fishgen's SIGTERM and Ctrl-C handlers raise through
:func:`deliver`, and inside :func:`held` the exception waits until the block ends.

A handler's exception may otherwise come between any two instructions: between two renames that
land a set of outputs, it would leave them half old and half new. Only the main thread runs
signal handlers, so only its blocks hold them.
"""
from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager

_depth = 0
_pending: BaseException | None = None


def deliver(err: BaseException) -> None:
    """Raise a signal handler's ``err`` now, or when the main thread's :func:`held` block ends."""
    global _pending
    if _depth and threading.current_thread() is threading.main_thread():
        _pending = _pending or err
        return
    raise err


@contextmanager
def held() -> Iterator[None]:
    """Signals delivered inside raise once the block (the outermost one) is over."""
    global _depth, _pending
    main = threading.current_thread() is threading.main_thread()
    if main:
        _depth += 1
    try:
        yield
    finally:
        if main:
            _depth -= 1
            if not _depth and _pending is not None:
                err, _pending = _pending, None
                raise err
