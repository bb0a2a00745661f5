"""Where jobs run: in this process (``-j 1``), a local process pool, or a Dask distributed cluster.

Every runner hands each finished job's :class:`~fishgen.batch.jobs.Result` to ``done`` in the
calling thread as it finishes (a local pool's, as its chunk finishes), so the record is updated
as the batch goes. On Ctrl-C or SIGTERM the local workers are stopped with SIGTERM (their atomic
writers remove their temp files) and Dask's futures are cancelled. A worker that dies breaks its
pool: the jobs the pool held run again, each alone, and only a job that kills a worker on its own
fails.
"""
from __future__ import annotations

import os
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence

# light: the jobs import the library only when one runs
from fishgen.batch.jobs import Result, Work, WorkerLost, alive, init_worker, run_in_worker, run_job
from fishgen.batch.manifest import Job
from fishgen.errors import MissingDependency, SystemFailure

Done = Callable[[Job, Result], bool]
"""Called with each finished job; returns True to stop starting new jobs (--fail-fast)."""

def run_jobs(jobs: Sequence[Job], work: Work, done: Done, *, workers: int = 1, scheduler: str | None = None,
             fail_fast: bool = False, preload: Sequence[str] = ()) -> None:
    """Run each of ``jobs`` through ``work``, calling ``done`` for each as it finishes. ``fail_fast``: a
    local pool's workers start no job after a failed one (``done`` decides what the caller stops).
    ``preload``: the modules ``work`` imports, loaded once where a local pool's workers start (the
    command before it forks them, or the forkserver), so that each worker starts with them instead of
    importing them itself (0.1 s of CPU per worker here)."""
    if not jobs:
        return
    if scheduler is not None:
        _dask(jobs, work, done, scheduler)
    elif workers <= 1 or len(jobs) == 1:
        _here(jobs, work, done)
    else:
        _pool(jobs, work, done, workers, fail_fast, preload)


def _here(jobs: Sequence[Job], work: Work, done: Done) -> None:
    """One job after another in this process: no worker start-up to pay for (``-j 1``)."""
    for job in jobs:
        if done(job, run_job(job, work)):
            return


def _failed(job: Job, message: str) -> Result:
    return Result(job.name, "failed", error=WorkerLost(message))


def _context(preload: Sequence[str]):
    import importlib
    import multiprocessing

    modules = list(dict.fromkeys(["fishgen.batch.jobs", *preload]))
    # fork while this process has one thread (no lock can be held by another thread), with the
    # jobs' modules imported here first so each worker starts with them; else a forkserver, a clean
    # single-threaded server that imports them. Both start a worker in milliseconds.
    if sys.platform.startswith("linux") and threading.active_count() == 1:
        for module in modules:
            importlib.import_module(module)
        return multiprocessing.get_context("fork")
    if sys.platform.startswith("linux"):
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(modules)
        return context
    return multiprocessing.get_context("spawn")


CHUNKS_PER_WORKER = 4
MAX_CHUNK = 8
"""A local pool hands its workers jobs in chunks, guided self-scheduling: each chunk is the jobs
left over CHUNKS_PER_WORKER times the workers, at most MAX_CHUNK and at least 1, so chunks shrink
to single jobs as the batch ends and the workers finish together. Each chunk is one round trip
through the executor, which wakes three of this process's threads (each taking a core from a
worker): handed out job by job, 100 builds ran 4 % slower with -j 2 on 2 cores."""


def chunk_size(left: int, workers: int) -> int:
    return max(1, min(MAX_CHUNK, left // (CHUNKS_PER_WORKER * workers)))


def _pool(jobs: Sequence[Job], work: Work, done: Done, workers: int, fail_fast: bool = False,
          preload: Sequence[str] = ()) -> None:
    """A local process pool with two chunks queued per worker (a worker never waits for this
    process to hand it the next one). A pool a dead worker broke is replaced, and the jobs it held
    (the dead worker's, and those merely queued behind it) are suspects: each runs again alone,
    with nothing else in flight, so a death then names its job. A job that kills a worker on its
    own twice fails."""
    from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")  # before numpy is imported: the pool is the parallelism
    pending = deque(jobs)
    context = _context(preload)
    stop = False
    lost: set[str] = set()  # suspects: jobs a broken pool held
    struck: set[str] = set()  # suspects that were running alone when their pool broke

    def next_chunk() -> tuple[Job, ...]:
        if pending[0].name in lost:
            return (pending.popleft(),)
        chunk = [pending.popleft()]
        size = chunk_size(len(pending) + 1, workers)
        while pending and len(chunk) < size and pending[0].name not in lost:
            chunk.append(pending.popleft())
        return tuple(chunk)

    def suspect_alone(running: dict) -> bool:
        """A suspect runs with nothing else in flight, and waits until nothing is."""
        return bool(running) and (pending[0].name in lost or any(
            chunk[0].name in lost for chunk in running.values()))

    while pending and not stop:
        # per pool: a worker of a broken pool may have set it before its failed job's result came
        # back; that job runs again in the next pool, which must not start stopped
        failed = context.RawValue("b", 0)  # a job failed under --fail-fast: start no other
        pids = context.SimpleQueue()  # each worker says who it is, so an interrupted batch can stop it
        pool = ProcessPoolExecutor(max_workers=min(workers, len(pending)), mp_context=context,
                                   initializer=init_worker, initargs=(os.getpid(), failed, pids))
        running: dict[Future, tuple[Job, ...]] = {}
        broken = clean = False
        try:
            while pending or running:
                while (pending and len(running) < 2 * workers
                       and not (stop or broken or suspect_alone(running))):
                    chunk = next_chunk()
                    try:
                        running[pool.submit(run_in_worker, chunk, work, fail_fast)] = chunk
                    except BrokenProcessPool:
                        pending.extendleft(reversed(chunk))
                        broken = True
                if not running:
                    break
                finished, _ = wait(running, return_when=FIRST_COMPLETED)
                for future in finished:
                    chunk = running.pop(future)
                    try:
                        results = future.result()
                    except BrokenProcessPool:
                        broken = True
                        chunk, results = _broken(chunk, lost, struck, pending)
                    # a chunk cut short by --fail-fast returns fewer results: the rest were not run
                    for job, result in zip(chunk, results, strict=False):
                        stop = done(job, result) or stop
                if stop:
                    failed.value = 1  # the chunks already handed out start no further job
            clean = True
        finally:
            _close(pool, clean, pids)


def _broken(chunk: tuple[Job, ...], lost: set[str], struck: set[str],
            pending: deque[Job]) -> tuple[tuple[Job, ...], list[Result]]:
    """The jobs of a chunk whose pool broke: what to report now (a suspect that killed a worker
    on its own a second time), the others back at the front of the queue as suspects."""
    if len(chunk) == 1 and chunk[0].name in lost:  # it ran alone: it killed the worker itself
        job = chunk[0]
        if job.name in struck:
            return chunk, [_failed(job, "a worker process died twice while building it on its own "
                                        "(killed, or out of memory)")]
        struck.add(job.name)  # once more: the kill may have come from outside (an OOM killer)
    lost.update(job.name for job in chunk)
    pending.extendleft(reversed(chunk))
    return (), []


def _close(pool, clean: bool, pids) -> None:
    """Shut the pool down; when interrupted, stop its workers first and wait for them to unwind.
    (A forked worker inherits the command's SIGTERM handler until its initializer replaces it.)
    The executor names no workers before Python 3.14 (``terminate_workers``), so each worker put
    its pid on ``pids`` when it started."""
    if clean:
        pool.shutdown(wait=True)
        return
    workers = []
    while not pids.empty():
        workers.append(pids.get())
    for pid in workers:
        _signal(pid, signal.SIGTERM)  # the worker raises, its atomic writer removes the temp file
    for pid, patience in ((pid, 10.0) for pid in workers):
        if not _gone(pid, patience):
            _signal(pid, signal.SIGKILL)
            _gone(pid, 5.0)
    pool.shutdown(wait=False, cancel_futures=True)


def _signal(pid: int, signum: int) -> None:
    try:
        os.kill(pid, signum)
    except ProcessLookupError:
        pass


def _gone(pid: int, seconds: float) -> bool:
    """Wait up to ``seconds`` for ``pid`` to end (it may be the forkserver's child, not ours)."""
    deadline = time.monotonic() + seconds
    while alive(pid):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)
    return True


PROBE_SECONDS = 10.0
"""How long a TCP scheduler address has to connect, and then to send its greeting."""


def _probe(address: str, seconds: float = PROBE_SECONDS) -> None:
    """Refuse, in one line and within ``seconds`` twice, a TCP address where no Dask scheduler
    answers. A scheduler speaks first: a frame of its handshake (an 8-byte little-endian length, a
    frame count, the frames' lengths). Dask's Client hung for good on a server that waits for a
    request (its dashboard's HTTP port: 13 minutes and counting), and on one that answers HTTP it
    read a length of 3 EiB and died out of memory, its own time-out never firing."""
    import socket
    import struct
    from urllib.parse import urlsplit

    scheme, _, rest = address.rpartition("://")
    if scheme not in ("", "tcp"):
        return              # tls://, ucx://, inproc://: Dask's own connection says what it finds
    try:
        where = urlsplit(f"tcp://{rest}")
        host, port = where.hostname, where.port
    except ValueError:
        return              # Dask says what is wrong with the address
    if host is None or port is None:
        return

    def refused(why: str) -> SystemFailure:
        return SystemFailure(f"cannot reach a Dask scheduler at {address} ({why})")

    try:
        sock = socket.create_connection((host, port), timeout=seconds)
    except TimeoutError:
        raise refused(f"no connection in {seconds:g} s") from None
    except OSError as err:
        raise refused(err.strerror or str(err)) from None
    head = b""
    with sock:
        try:
            while len(head) < 16:
                got = sock.recv(16 - len(head))
                if not got:
                    break
                head += got
        except TimeoutError:
            raise refused(f"something there said nothing in {seconds:g} s, where a scheduler greets at "
                          "once: another port, such as its dashboard's?") from None
        except OSError as err:
            raise refused(err.strerror or str(err)) from None
    total, frames = struct.unpack("<QQ", head) if len(head) == 16 else (0, 0)
    if not (0 < total <= 1 << 20 and 0 < frames <= 64):
        said = head[:12].decode("latin-1").encode("unicode_escape").decode("ascii")
        raise refused(f"something else answers there: {said!r}" if head else "it closed at once")


def _dask(jobs: Sequence[Job], work: Work, done: Done, address: str) -> None:
    """Dask distributed: the scheduler places each job on a worker; outputs go to their shared paths."""
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise MissingDependency("--scheduler needs Dask distributed, which is not installed; install it "
                                "with pip install 'fishgen[cluster]'") from None

    _probe(address)
    try:
        client = Client(address, timeout=30, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as err:
        raise SystemFailure(f"cannot reach a Dask scheduler at {address} ({err})") from None
    except Exception as err:  # it answered in another protocol after all (a 3 EiB frame: MemoryError)
        raise SystemFailure(f"cannot reach a Dask scheduler at {address} (it does not answer as one: "
                            f"{type(err).__name__})") from None
    futures = {}
    try:
        for index, job in enumerate(jobs):
            # pure=False: two runs of the same job are two builds (the outputs may have been removed)
            futures[client.submit(run_job, job, work, pure=False, key=f"fishgen-batch-{index}-{os.getpid()}-"
                                  f"{job.name}")] = job
        for future in as_completed(list(futures), loop=client.loop):
            job = futures[future]
            try:
                result = future.result()
            except Exception as err:  # KilledWorker, a lost connection: this job failed, not the batch
                result = _failed(job, f"the Dask worker failed: {type(err).__name__}: {err}")
            if done(job, result):
                break
    finally:
        client.cancel(list(futures))
        client.close()
