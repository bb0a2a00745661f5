"""Signals that wait for a critical step: fishgen's SIGTERM and Ctrl-C handlers raise through
:func:`deliver`, and inside :func:`held` the exception waits until the block ends.

A handler's exception may otherwise come between any two instructions: between two renames that
land a set of outputs, it would leave them half old and half new. Only the main thread runs
signal handlers, so only its blocks hold them.

A handler's exception can also come as a cleanup begins (on entering an ``__exit__``), before a
line of it runs. So what must not outlive the process is also registered with :func:`at_stop`,
and whoever ends the process on a signal (the CLI, a batch worker) calls :func:`stopped`.
"""
from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

_depth = 0
_pending: BaseException | None = None
_cleanups: list[Callable[[], None]] = []


def at_stop(cleanup: Callable[[], None]) -> Callable[[], None]:
    """Register ``cleanup`` to run when the process stops on a signal (usable as a decorator)."""
    _cleanups.append(cleanup)
    return cleanup


def stopped() -> None:
    """The process stops on a signal: run every registered cleanup, the last registered first."""
    for cleanup in reversed(_cleanups):
        cleanup()


def deliver(err: BaseException) -> None:
    """Raise a signal handler's ``err`` now, or when the main thread's :func:`held` block ends."""
    global _pending
    if _depth and threading.current_thread() is threading.main_thread():
        _pending = _pending or err
        return
    try:
        raise err
    finally:  # this frame, in the traceback, would hold the exception: a cycle only the collector
        del err  # frees, and with it the generators of the context managers it stopped


@contextmanager
def held() -> Iterator[None]:
    """Signals delivered inside raise once the block (the outermost one) is over."""
    global _depth
    main = threading.current_thread() is threading.main_thread()
    if main:
        _depth += 1
    try:
        yield
    finally:
        if main:
            _depth -= 1
            if not _depth and _pending is not None:
                _raise_pending()


def _raise_pending() -> None:
    global _pending
    err, _pending = _pending, None
    assert err is not None
    try:
        raise err
    finally:
        del err  # as in deliver
