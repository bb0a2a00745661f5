"""Run one batch job through the work the batch command hands in (its command's library
function), in whatever process or Dask worker it lands on.

A job returns a :class:`Result` and never raises for bad input: a species file's ``FILE:LINE``
error fails its own job and the batch goes on. Every file the job read (the manifest's inputs, the
textures a species names, the species of a school's scene, a path CSV: what the command's
work says it read) and every file it wrote come back with their
SHA-256, so the record can tell later whether anything changed without parsing anything.
"""
from __future__ import annotations

import os
import time
import traceback
import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fishgen import interrupts
from fishgen.batch.manifest import Job
from fishgen.batch.record import file_sha256
from fishgen.errors import FishgenError, SystemFailure, cannot
from fishgen.reading import unheeded

Work = Callable[[Job, Callable[[str], None]], tuple[Iterable[Path], Iterable[Path]]]
"""Runs one job, telling each warning about its inputs to the callable it is given; returns the
files the job read and those it wrote. A module-level function: it is pickled by name into the
worker processes and onto Dask workers."""


class InternalError(FishgenError):
    """A bug in fishgen: one job fails (status 1), the batch goes on, ``--verbose`` shows where."""

    status = 1
    kind = "internal"

    def __init__(self, message: str, detail: str = ""):
        super().__init__(message)
        self.detail = detail

    def __reduce__(self):
        return (type(self), (self.message, self.detail))


class WorkerLost(FishgenError):
    """The process running a job died (killed, out of memory) or never answered (status 1)."""

    status = 1
    kind = "worker"


@dataclass
class Result:
    name: str
    status: str                                   # "built" or "failed"
    seconds: float = 0.0
    inputs: dict[str, str] = field(default_factory=dict)   # absolute path -> sha256, every file read
    outputs: dict[str, str] = field(default_factory=dict)  # absolute path -> sha256, every file written
    error: FishgenError | None = None
    notes: list[str] = field(default_factory=list)  # warnings about the inputs, one line each


def run_job(job: Job, work: Work) -> Result:
    """Run one job (its outputs written atomically); its errors become a failed :class:`Result`."""
    start = time.perf_counter()
    result = Result(job.name, "failed")
    notes: list[str] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            read, written = work(job, notes.append)
        notes += [str(w.message) for w in caught
                  if issubclass(w.category, UserWarning)
                  and not unheeded(w.category, w.filename)]
        result.notes = notes
        result.inputs = {os.fspath(p): file_sha256(p) for p in dict.fromkeys(read)}
        result.outputs = {os.fspath(p): file_sha256(p) for p in written}
        result.status = "built"
    except FishgenError as err:
        result.error = err
    except OSError as err:
        result.error = cannot("read or write", err.filename, err) if err.filename else \
            SystemFailure(str(err.strerror or err))
    except Exception as err:  # a bug in one job must not take the batch down; the trace says where
        result.error = InternalError(f"internal error: {type(err).__name__}: {err}", traceback.format_exc())
    result.seconds = time.perf_counter() - start
    return result


_busy = False    # a local pool worker is running a job (its SIGTERM must unwind the atomic writer)
_orphan = False  # the batch that started this worker is gone (killed with SIGKILL)
_failure_flag: Any = None  # the pool's shared byte: 1 once a job failed under --fail-fast, start no other


class Stopped(BaseException):
    """SIGTERM in a pool worker: unwinds the job (atomic writers remove their temp files)."""


def _stop(signum: int, _frame: object) -> None:
    if _busy:
        interrupts.deliver(Stopped(128 + signum))  # after the renames under way, if any
        return
    os._exit(128 + signum)  # idle: nothing to clean up, and no traceback from the pool's loop


def init_worker(batch_pid: int, failed: Any = None, pids: Any = None) -> None:
    """A local pool's worker: SIGTERM stops it cleanly; Ctrl-C is the parent's to handle (it stops
    the workers itself, so the terminal's SIGINT to the whole group is ignored here); and when
    the batch itself is killed, the worker finishes the file it is writing and exits. ``failed``
    is the pool's shared byte for --fail-fast (a RawValue: no lock a killed worker could hold);
    ``pids`` the queue on which each worker names itself, so that an interrupted batch can stop it."""
    import signal
    import threading

    global _failure_flag
    _failure_flag = failed
    if pids is not None:
        pids.put(os.getpid())

    signal.signal(signal.SIGTERM, _stop)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_watch, args=(batch_pid,), daemon=True).start()


def _watch(batch_pid: int) -> None:
    """A forkserver's worker is not the batch's child, so no pipe or signal tells it the batch died."""
    global _orphan
    while alive(batch_pid):
        time.sleep(0.2)
    _orphan = True
    if not _busy:
        os._exit(1)


def alive(pid: int) -> bool:
    """Whether the process runs. A killed batch stays a zombie until its own parent reaps it (and a
    parent reading its output first never does), so on Linux its state is read, not signalled."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as handle:
            return handle.read().rpartition(b")")[2].split()[0] not in (b"Z", b"X")
    except FileNotFoundError:
        return False
    except OSError:  # no /proc: a signal 0 tells a live (or zombie) process from none
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:  # the pid was reused by another user's process
            return False
        return True


def run_in_worker(jobs: tuple[Job, ...], work: Work, fail_fast: bool = False) -> list[Result]:
    """:func:`run_job` for a chunk of jobs in a local pool worker, which exits once a SIGTERM has
    unwound the job. Under ``fail_fast`` the chunk stops at a failed job, and at the next job once
    any worker's job failed: the results are then fewer than the jobs."""
    global _busy
    results: list[Result] = []
    _busy = True
    try:
        for job in jobs:
            if _failure_flag is not None and _failure_flag.value:
                break
            results.append(run_job(job, work))
            if _orphan:  # nobody is waiting for the results; the outputs are whole either way
                os._exit(1)
            if fail_fast and results[-1].status == "failed":
                if _failure_flag is not None:
                    _failure_flag.value = 1
                break
        return results
    except Stopped as stop:
        interrupts.stopped()  # os._exit runs no other cleanup
        os._exit(stop.args[0])
    finally:
        _busy = False
        if _orphan:  # the watcher saw the batch die while this worker was busy
            os._exit(1)
