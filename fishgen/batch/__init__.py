"""Batches: regenerate whole asset sets reproducibly, incrementally and in parallel.

    from fishgen.batch import run_batch
    from fishgen.batch.manifest import load_manifest
    outcomes = run_batch(load_manifest("params/assets.toml", kinds=kinds), work, workers=2)

A service below the commands: it knows no command. What a manifest's jobs may be (``kinds``: each
a command's name, options record and output) and how one runs (``work``) are handed in by the
batch command, :mod:`fishgen.commands.batch`, which is what `fishgen batch` and library users call.
A job whose inputs, options and fishgen version are unchanged and whose outputs are intact is
skipped (:mod:`fishgen.batch.record`); the others run in this process, a local process pool or on
a Dask cluster (:mod:`fishgen.batch.runner`), each through ``work`` (:mod:`fishgen.batch.jobs`).
Nothing here imports numpy: a batch where nothing changed never loads it.
"""
from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from fishgen.batch.jobs import Work
from fishgen.batch.manifest import Job, Manifest
from fishgen.batch.record import Hashes, Record, relative
from fishgen.errors import FishgenError, SystemFailure, cannot

LOCK_NAME = ".fishgen-batch.lock"
STATUSES = ("built", "skipped", "failed", "not run")


@dataclass
class Outcome:
    """What happened to one job, for the progress lines and the report."""

    job: Job
    status: str                                    # one of STATUSES
    reason: str | None = None                      # why it ran ("bonybream.txt changed"), or None
    seconds: float = 0.0
    inputs: dict[str, str] = field(default_factory=dict)    # out-relative path -> sha256
    outputs: dict[str, str] = field(default_factory=dict)   # out-relative path -> sha256
    error: FishgenError | None = None
    notes: list[str] = field(default_factory=list)


def run_batch(manifest: Manifest, work: Work, *, workers: int = 1, force: bool = False,
              fail_fast: bool = False, scheduler: str | None = None, preload: Sequence[str] = (),
              started: Callable[[int], None] | None = None,
              finished: Callable[[Outcome], None] | None = None,
              guarded: Callable[[list[Job]], list[Job]] | None = None) -> list[Outcome]:
    """Bring every output of ``manifest`` up to date, running each job that is not through ``work``;
    returns one outcome per job, in manifest order. ``preload``: the modules ``work`` imports (see
    :func:`fishgen.batch.runner.run_jobs`).

    ``started(n)`` is called once with the number of jobs that will run; ``finished`` with each
    job's outcome as it is known (skipped ones first). ``guarded`` turns the jobs that will run into
    the jobs to run (each with its guards), only when there are some: a batch with nothing to do
    reads no more than the record asks.
    """
    from fishgen.batch.runner import run_jobs

    out = manifest.out
    outcomes: dict[str, Outcome] = {}

    def tell(outcome: Outcome) -> None:
        outcomes[outcome.job.name] = outcome
        if finished is not None:
            finished(outcome)

    with _locked(out):
        record = Record(out)
        hashes = Hashes()
        todo: list[tuple[Job, str]] = []
        for job in manifest.jobs:
            reason = "--force" if force else record.stale(job, hashes)
            if reason is None:
                entry = record.jobs[job.name]
                tell(Outcome(job, "skipped", inputs=dict(entry["inputs"]), outputs=dict(entry["outputs"])))
            else:
                todo.append((job, reason))
        if started is not None:
            started(len(todo))
        reasons = {job.name: reason for job, reason in todo}

        def done(job: Job, result) -> bool:
            if result.status == "built":
                record.put(job.name, record.entry(job, result.inputs, result.outputs))
            inputs = {relative(p, out): h for p, h in result.inputs.items()}
            outputs = {relative(p, out): h for p, h in result.outputs.items()}
            tell(Outcome(job, result.status, reasons[job.name], result.seconds, inputs, outputs, result.error,
                         result.notes))
            return fail_fast and result.status == "failed"

        unsaved: FishgenError | None = None
        try:
            running = [job for job, _ in todo]
            if running and guarded is not None:
                running = guarded(running)
            run_jobs(running, work, done, workers=workers, scheduler=scheduler,
                     fail_fast=fail_fast, preload=preload)
        finally:
            # once, durably, however the run ended, when a job was built: a batch whose every job
            # failed writes no record it did not have (and an unreadable one stays until this run
            # has something to put in its place)
            if record.changed:
                try:
                    record.save()
                except FishgenError as err:  # a full disk: the outputs are whole, their record is not
                    unsaved = err
    result = [outcomes.get(job.name) or Outcome(job, "not run",
                                                reasons.get(job.name)) for job in manifest.jobs]
    if unsaved is not None:
        raise RecordNotSaved(unsaved.message, unsaved.file, result)
    return result


class RecordNotSaved(SystemFailure):
    """The batch ran but its record could not be written (status 1): ``outcomes`` say what ran; the
    next run finds the outputs whole and rebuilds what the record does not vouch for."""

    def __init__(self, message: str, file: str | None, outcomes: list[Outcome]):
        super().__init__(message, file)
        self.outcomes = outcomes


@contextmanager
def _locked(out: Path) -> Iterator[None]:
    """One batch at a time per out folder: two would race on the record and the outputs."""
    try:
        out.mkdir(parents=True, exist_ok=True)
        handle = open(out / LOCK_NAME, "a+b")  # held open for the whole batch
    except (NotADirectoryError, FileExistsError) as err:  # a file where --out names a folder
        from fishgen.atomic import write_failure

        raise write_failure(out, err, folder=True) from None
    except OSError as err:  # the system refused (read-only, permissions, full): not the input
        raise cannot("write", out, err) from None
    try:
        try:
            import fcntl
        except ImportError:  # Windows: no advisory locks; one batch per folder is then up to the user
            yield
            return
        try:
            fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            # the system's refusal, as a port in use is: the same batch may be run again later
            raise SystemFailure(f"cannot write {out}: expected no other `fishgen batch` writing this out "
                                "folder, found one running", out) from None
        yield
    finally:
        handle.close()


__all__ = ["Outcome", "STATUSES", "run_batch"]
