"""Where jobs run: in this process (``-j 1``), a local process pool, or a Dask distributed cluster.

Every runner hands each finished job's :class:`~fishgen.batch.jobs.Result` to ``done`` in the
calling thread, as it finishes, so the record is updated job by job. On Ctrl-C or SIGTERM the
local workers are stopped with SIGTERM (their atomic writers remove their temp files) and
Dask's futures are cancelled; a worker that dies fails only the jobs it was running.
"""
from __future__ import annotations

import os
import sys
import threading
from collections import deque
from collections.abc import Callable, Sequence

# light: the jobs import the library only when one runs
from fishgen.batch.jobs import Result, init_worker, run_in_worker, run_job
from fishgen.batch.manifest import Job
from fishgen.errors import FishgenError

Done = Callable[[Job, Result], bool]
"""Called with each finished job; returns True to stop starting new jobs (--fail-fast)."""

# Imported by the forkserver once, so each worker starts with what its jobs need already loaded.
PRELOAD = {"build": ["fishgen.assembly.fish", "fishgen.species.parser", "fishgen.exchange.gltf"],
           "school": ["fishgen.school", "fishgen.school.simulate", "fishgen.school.bake",
                      "fishgen.exchange.gltf"],
           "clouds": ["fishgen.clouds", "fishgen.clouds.scene", "fishgen.exchange.gltf"]}


def run_jobs(jobs: Sequence[Job], done: Done, *, workers: int = 1, scheduler: str | None = None) -> None:
    """Run ``jobs``, calling ``done`` for each as it finishes."""
    if not jobs:
        return
    if scheduler is not None:
        _dask(jobs, done, scheduler)
    elif workers <= 1 or len(jobs) == 1:
        _here(jobs, done)
    else:
        _pool(jobs, done, workers)


def _here(jobs: Sequence[Job], done: Done) -> None:
    """One job after another in this process: no worker start-up to pay for (``-j 1``)."""
    for job in jobs:
        if done(job, run_job(job)):
            return


def _failed(job: Job, message: str, kind: str = "worker") -> Result:
    return Result(job.name, "failed", error={"message": message, "file": None, "line": None, "kind": kind})


def _context(kinds: set[str]):
    import multiprocessing

    # fork while this process has one thread (the command: nothing is imported yet that a worker
    # would not import anyway, and no lock can be held by another thread); else a forkserver, a
    # clean single-threaded server with the library imported. Both start a worker in milliseconds.
    if sys.platform.startswith("linux") and threading.active_count() == 1:
        return multiprocessing.get_context("fork")
    if sys.platform.startswith("linux"):
        context = multiprocessing.get_context("forkserver")
        modules = ["fishgen.batch.jobs"] + [m for kind in sorted(kinds) for m in PRELOAD[kind]]
        context.set_forkserver_preload(list(dict.fromkeys(modules)))
        return context
    return multiprocessing.get_context("spawn")


def _pool(jobs: Sequence[Job], done: Done, workers: int) -> None:
    """A local process pool with two jobs queued per worker (a worker never waits for this process
    to hand it the next one). A pool a dead worker broke is replaced and the jobs it held are
    tried once more; a job that breaks a second pool fails."""
    from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")  # before the forkserver imports numpy: the pool is the parallelism
    pending = deque(jobs)
    context = _context({job.kind for job in jobs})
    stop = False
    lost: set[str] = set()  # jobs a dead worker took down once
    while pending and not stop:
        pool = ProcessPoolExecutor(max_workers=min(workers, len(pending)), mp_context=context,
                                   initializer=init_worker, initargs=(os.getpid(),))
        running: dict[Future, Job] = {}
        broken = clean = False
        try:
            while pending or running:
                while pending and len(running) < 2 * workers and not (stop or broken):
                    job = pending.popleft()
                    try:
                        running[pool.submit(run_in_worker, job)] = job
                    except BrokenProcessPool:
                        pending.appendleft(job)
                        broken = True
                if not running:
                    break
                finished, _ = wait(running, return_when=FIRST_COMPLETED)
                for future in finished:
                    job = running.pop(future)
                    try:
                        result = future.result()
                    except BrokenProcessPool:
                        broken = True
                        if job.name not in lost:  # perhaps only queued behind the job that died
                            lost.add(job.name)
                            pending.appendleft(job)
                            continue
                        result = _failed(job, "a worker process died twice while building it (killed, or "
                                              "out of memory)")
                    stop = done(job, result) or stop
            clean = True
        finally:
            _close(pool, clean)


def _close(pool, clean: bool) -> None:
    """Shut the pool down; when interrupted, stop its workers first and wait for them to unwind.
    (A forked worker inherits the command's SIGTERM handler until its initializer replaces it.)"""
    if clean:
        pool.shutdown(wait=True)
        return
    procs = list((getattr(pool, "_processes", None) or {}).values())  # the executor has no public handle
    for proc in procs:
        if proc.is_alive():
            proc.terminate()  # SIGTERM: the worker raises, its atomic writer removes the temp file
    for proc in procs:
        proc.join(timeout=10)
        if proc.is_alive():
            proc.kill()
            proc.join(timeout=5)
    pool.shutdown(wait=False, cancel_futures=True)


def _dask(jobs: Sequence[Job], done: Done, address: str) -> None:
    """Dask distributed: the scheduler places each job on a worker; outputs go to their shared paths."""
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise FishgenError("expected Dask distributed for --scheduler, found it not installed "
                           "(pip install 'fishgen[cluster]')") from None

    try:
        client = Client(address, timeout=30, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as err:
        raise FishgenError(f"expected a Dask scheduler at {address}, found none reachable ({err})") from None
    futures = {}
    try:
        for index, job in enumerate(jobs):
            # pure=False: two runs of the same job are two builds (the outputs may have been removed)
            futures[client.submit(run_job, job, pure=False, key=f"fishgen-batch-{index}-{os.getpid()}-"
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
