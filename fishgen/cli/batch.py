"""`fishgen batch`: a manifest (or a folder) of build, school and clouds jobs, brought up to date."""
from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

import click

from fishgen.errors import FishgenError


@click.command("batch", context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("source", type=click.Path(exists=True, path_type=Path), metavar="MANIFEST.toml|DIR")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Folder for the outputs and the record (.fishgen-batch.json). Required with DIR.  "
                   "[default: the manifest's `out`, else ./out]")
@click.option("-j", "--jobs", "workers", type=click.IntRange(1, 1024), default=None,
              help="Jobs at once, each in its own process (1: in this process).  [default: the number of "
                   "cores]")
@click.option("--force", is_flag=True, help="Rebuild every job, even those the record says are up to date.")
@click.option("--fail-fast", is_flag=True,
              help="Start no new job after the first failure (the jobs running finish).")
@click.option("--scheduler", metavar="ADDRESS", default=None,
              help="Run the jobs on this Dask distributed scheduler (tcp://host:8786) instead of local "
                   "processes; outputs must be on a path the workers share. Needs `pip install "
                   "'fishgen[cluster]'`.")
@click.option("--report", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Also write a JSON report: per job its inputs and their hashes, options, output and "
                   "its hash, seconds, status and error.")
def batch(source: Path, out: Path | None, workers: int | None, force: bool, fail_fast: bool,
          scheduler: str | None, report: Path | None) -> None:
    """Bring every output of a MANIFEST.toml (or of every species and cube file under DIR) up to date.

    A manifest lists [[build]], [[school]] and [[clouds]] jobs with their inputs, the options of
    those commands and an output (see params/assets.toml). A job runs only when a file it reads
    (textures and a school's species included), its options or fishgen's version changed, or
    its output is not the one recorded. Seeds come from each job's output name unless set, so
    outputs are byte-identical across runs, -j values and machines. A bad input fails only its
    own job; the exit status is then non-zero. Outputs are written atomically: an interrupted
    batch leaves whole old or whole new files, and the next run does only what is missing.

    \b
    Examples:
      fishgen batch params/assets.toml
      fishgen batch params --out out/all -j 2 --report out/all/report.json
    """
    import time

    from fishgen.batch import run_batch
    from fishgen.batch.manifest import load_manifest, scan_folder
    from fishgen.cli.common import QUIET, VERBOSE, verbosity

    start = time.perf_counter()
    if source.is_dir():
        if out is None:
            raise FishgenError("expected --out FOLDER with a folder of inputs, found none", source)
        manifest = scan_folder(source, out)
    else:
        manifest = load_manifest(source, out)
    workers = workers or os.cpu_count() or 1
    level = verbosity()
    show = _Progress(quiet=level <= QUIET, verbose=level >= VERBOSE)
    try:
        outcomes = run_batch(manifest, workers=workers, force=force, fail_fast=fail_fast, scheduler=scheduler,
                             started=show.start, finished=show.job)
    finally:
        show.close()  # the terminal gets its cursor back, even when interrupted
    seconds = time.perf_counter() - start
    if report is not None:
        from fishgen.batch.report import report as make_report
        from fishgen.batch.report import write_report

        write_report(report, make_report(manifest, outcomes, seconds, workers, scheduler))
    counts = {s: sum(o.status == s for o in outcomes) for s in ("built", "skipped", "failed", "not run")}
    where = scheduler or f"-j {workers}"
    click.echo(f"{_shown(manifest.out)}: {len(outcomes)} jobs, {counts['built']} built, {counts['skipped']} "
               f"skipped, {counts['failed']} failed" + (f", {counts['not run']} not run" if counts["not run"]
                                                       else "") + f" in {seconds:.2f} s ({where})")
    failed = [o for o in outcomes if o.status == "failed"]
    if failed:
        raise _jobs_failed(failed, len(outcomes))


class _Progress:
    """A bar on a terminal; one plain line per job otherwise (CI logs). Failures always, on stderr."""

    def __init__(self, *, quiet: bool, verbose: bool):
        self.quiet, self.verbose = quiet, verbose
        self.bar: Any = None
        self.tty = sys.stderr.isatty() and not quiet

    def start(self, count: int) -> None:
        if self.tty and count and not self.verbose:
            self.bar = click.progressbar(length=count, label="building", file=sys.stderr)
            self.bar.__enter__()

    def job(self, outcome) -> None:
        from fishgen.cli.common import error_line

        if outcome.status == "failed":
            error = outcome.error or {}
            message = error.get("message", "failed")
            status = 2 if error.get("kind") == "input" else 1
            line = f"{outcome.job.name}: {message}" if error.get("file") is None else message
            if self.bar is not None:
                click.echo("", err=True)  # off the bar's line
            click.echo(error_line(line, status, file=error.get("file"), line=error.get("line"),
                                  kind=error.get("kind", "input"), job=outcome.job.name), err=True)
            if self.verbose and error.get("traceback"):
                click.echo(error["traceback"], err=True)
        for note in outcome.notes:
            click.echo(note, err=True)
        if self.bar is not None:
            if outcome.status != "skipped":
                self.bar.update(1)
            return
        if self.quiet or (outcome.status == "failed"):
            return
        text = f"{outcome.status:<8} {outcome.job.name}"
        if outcome.status == "built":
            text += f" ({outcome.seconds:.2f} s)"
        if self.verbose and outcome.reason:
            text += f": {outcome.reason}"
        click.echo(text)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.__exit__(None, None, None)
            self.bar = None


def _shown(path: Path) -> str:
    """The out folder as the user would type it: relative below the current folder, else absolute."""
    try:
        shown = os.path.relpath(path)
    except ValueError:  # another drive (Windows)
        return os.fspath(path)
    return os.fspath(path) if shown.startswith("..") else shown


def _jobs_failed(failed: list, total: int) -> FishgenError:
    err = FishgenError(f"{len(failed)} of {total} jobs failed (each said why above)")
    # Bad input is 2, as for every command; a job lost for another reason (an OS error, a dead
    # worker, a bug) is 1, so that a pipeline can retry only those.
    err.status = 2 if any((o.error or {}).get("kind") == "input" for o in failed) else 1  # type: ignore[attr-defined]
    err.kind = "jobs"  # type: ignore[attr-defined]
    return err
