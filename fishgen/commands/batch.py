"""`fishgen batch`: a manifest (or a folder) of build, school and clouds jobs, brought up to date."""
from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import click

from fishgen.commands import MODULES, QUIET, Command, Events, Inputs, Made, Progress, command, run
from fishgen.errors import FishgenError, plural
from fishgen.options import FILE, OUT_FOLDER, option

if TYPE_CHECKING:
    from fishgen.batch.manifest import Job, Kind, Manifest


@dataclass(frozen=True)
class BatchOptions:
    out: Path | None = option(OUT_FOLDER, "Folder for the outputs and the record (.fishgen-batch.json). "
                              "Required with DIR.", shown_default="the manifest's `out`, else ./out",
                              metavar="DIRECTORY", short="-o")   # -o, as every other command's output
    jobs: int | None = option(click.IntRange(1, 1024), "Jobs at once, each in its own process (1: in this "
                              "process).", shown_default="the number of cores", short="-j")
    force: bool = option(click.BOOL, "Rebuild every job, even those the record says are up to date.", False,
                         flag=True)
    fail_fast: bool = option(click.BOOL,
                             "Start no new job after the first failure (the jobs running finish).",
                             False, flag=True)
    scheduler: str | None = option(click.STRING, "Run the jobs on this Dask distributed scheduler "
                                   "(tcp://host:8786) instead of local processes; outputs must be on a "
                                   "path the "
                                   "workers share. Needs `pip install 'fishgen[cluster]'`.",
                                   shown_default="local processes", metavar="ADDRESS")
    report: Path | None = option(FILE,
                                 "Also write a JSON report: per job its inputs and their hashes, options, "
                                 "output and its hash, seconds, status and error.", shown_default="none")


COMMAND = Command(
    name="batch",
    summary="Regenerate an asset set from a manifest or folder, incrementally and in parallel.",
    help="""Bring every output of a MANIFEST.toml (or of every species and cube file under DIR) up to date.

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
    """,
    options=BatchOptions,
    run="fishgen.commands.batch:batch",
    inputs=Inputs("MANIFEST.toml|DIR", many=False),
)


def job_kinds() -> tuple[Kind, ...]:
    """The commands a manifest may list jobs of, as the batch reads them."""
    from fishgen.batch.manifest import Kind

    return tuple(Kind(name, cmd.options, cmd.holds, cmd.check)
                 for name in MODULES if (cmd := command(name)).batch)


def run_job(job: Job, note: Callable[[str], None]) -> tuple[tuple[Path, ...], tuple[Path, ...]]:
    """One batch job: its command's library function, run as the CLI runs it, quiet but for its notes
    (the batch's :data:`~fishgen.batch.jobs.Work`); the files it read and wrote."""
    from fishgen.atomic import protecting

    with protecting(job.guard):
        made = run(command(job.kind), job.inputs, job.output, job.options, Events(note=note, summary=False))
    return made.read, made.written


# What a batch worker needs loaded before its first job (the batch's preload), beyond each kind's
# command module. tests/batch/test_runner.py checks that a job of each kind imports nothing more of
# fishgen, numpy, Pillow or scipy.
_PILLOW = ["PIL.Image", "PIL.ImageOps", "PIL.PngImagePlugin", "PIL.JpegImagePlugin", "PIL.BmpImagePlugin",
           "PIL.GifImagePlugin", "PIL.PpmImagePlugin"]
_FISH = ["fishgen.assembly.fish", "fishgen.assembly.materials", "fishgen.species.parser",
         "fishgen.exchange.sidefiles", *_PILLOW]
PRELOAD = {"build": _FISH,
           "school": [*_FISH, "fishgen.school.run", "fishgen.school.simulate", "fishgen.school.bake",
                      "fishgen.school.scene_file", "fishgen.school.memory", "fishgen.school.behaviour.boids",
                      "fishgen.school.behaviour.pso", "fishgen.school.behaviour.couzin",
                      "fishgen.exchange.sidefiles"],
           "clouds": ["fishgen.clouds.parser", "fishgen.clouds.memory", "fishgen.clouds.fill",
                      "fishgen.exchange.clouds",
                      "fishgen.clouds.scene", "fishgen.clouds.light", "fishgen.exchange.sidefiles",
                      # np.median reaches for numpy.ma on first use
                      "numpy.random", "numpy.fft", "numpy.ma"]}


def preload(kinds: set[str]) -> list[str]:
    """The modules jobs of these kinds need, in import order."""
    jobs = [m for kind in sorted(kinds) for m in (MODULES[kind], *PRELOAD[kind])]
    return list(dict.fromkeys([__name__, "fishgen.commands.paths", *jobs, "fishgen.exchange.gltf",
                                "fishgen.exchange.gltf_container", "fishgen.viewer",
                                "fishgen.exchange.client_limits"]))


@dataclass(frozen=True)
class BatchFacts:
    outcomes: tuple          # one fishgen.batch.Outcome per job, in manifest order
    seconds: float
    workers: int


def _manifest(source: Path, out: Path | None):
    """The manifest at ``source``; a file that is not one but another command's input says which."""
    from fishgen.batch.manifest import load_manifest
    from fishgen.errors import FishgenError, SystemFailure
    from fishgen.exchange.registry import detect

    try:
        return load_manifest(source, out, kinds=job_kinds())
    except FishgenError as err:
        fmt = None if isinstance(err, SystemFailure) else detect(source)
        if fmt is None or fmt.command in (None, "batch"):
            raise
        raise FishgenError(f"expected a batch manifest or a folder, found {fmt.description}; use "
                           f"`fishgen {fmt.command}` for it", source) from None


def batch(inputs: Sequence[Path], output: None, options: BatchOptions = BatchOptions(),
          events: Events = QUIET) -> Made:
    """Run every job that is not up to date; each finished job is told through ``events``."""
    inputs = COMMAND.given(inputs, options)
    import time

    from fishgen.batch import RecordNotSaved, run_batch
    from fishgen.batch.manifest import scan_folder
    from fishgen.errors import JobsFailed, SystemFailure, UsageError
    from fishgen.extras import needs

    start = time.perf_counter()
    (source,) = inputs
    if options.scheduler is not None:
        needs("distributed", "cluster", "--scheduler")
    if source.is_dir():
        if options.out is None:
            raise UsageError(f"expected --out FOLDER with a folder of inputs ({source}), found none")
        manifest = scan_folder(source, options.out, kinds=job_kinds())
    else:
        manifest = _manifest(source, options.out)
    reads: list[tuple[Job, list[Path]]] = []

    def job_reads() -> list[tuple[Job, list[Path]]]:   # once, and only if asked: loading imports numpy
        if not reads:
            reads.extend(_job_reads(manifest))
        return reads

    if options.report is not None:
        _check_report(options.report, manifest, job_reads())
    workers = options.jobs or os.cpu_count() or 1
    with ExitStack() as stack:
        bar: list[Progress] = []

        def started(count: int) -> None:
            if count:
                bar.append(stack.enter_context(events.progress("building", count)))

        def finished(outcome) -> None:
            _tell(outcome, events, bar[0] if bar else None)

        unsaved: FishgenError | None = None
        try:
            outcomes = run_batch(manifest, run_job, workers=workers, force=options.force,
                                 fail_fast=options.fail_fast, scheduler=options.scheduler,
                                 preload=preload({job.kind for job in manifest.jobs}), started=started,
                                 finished=finished, guarded=lambda jobs: _guarded(jobs, job_reads()))
        except RecordNotSaved as err:  # the summary still says what ran, then why the record did not
            outcomes, unsaved = err.outcomes, err
    seconds = time.perf_counter() - start
    written = []
    # What the batch itself could not write (a full disk) goes in its one summary error, after the
    # jobs' own lines: each said why already, and the summary on stdout still says what ran.
    unwritten: list[FishgenError] = [unsaved] if unsaved is not None else []
    if options.report is not None:
        from fishgen.batch.report import report, write_report

        try:
            write_report(options.report, report(manifest, outcomes, seconds, workers, options.scheduler))
            written.append(options.report)
        except SystemFailure as err:
            unwritten.append(err)
    counts = {s: sum(o.status == s for o in outcomes) for s in ("built", "skipped", "failed", "not run")}
    where = options.scheduler or f"-j {workers}"
    line = (f"{_shown(manifest.out)}: {plural(len(outcomes), 'job')}, {counts['built']} built, "
            f"{counts['skipped']} skipped, {counts['failed']} failed"
            + (f", {counts['not run']} not run" if counts["not run"] else "")
            + f" in {seconds:.2f} s ({where})")
    errors = tuple(_job_error(o) for o in outcomes if o.status == "failed")
    verdict: FishgenError | None = None
    if errors:
        verdict = JobsFailed("; ".join([f"{len(errors)} of {len(outcomes)} jobs failed (each said why above)",
                                        *map(str, unwritten)]), any(e.status == 2 for e in errors))
    elif len(unwritten) == 1:
        verdict = unwritten[0]
    elif unwritten:
        verdict = SystemFailure("; ".join(map(str, unwritten)), unwritten[0].file)
    written += [manifest.out / p for o in outcomes if o.status == "built" for p in o.outputs]
    return Made(tuple(written), (manifest.file,) if manifest.file else (), (line,),
                BatchFacts(tuple(outcomes), seconds, workers), errors, verdict)


def _job_reads(manifest: Manifest) -> list[tuple[Job, list[Path]]]:
    """Each job and the files it reads: its inputs and the files they name (a species' textures, a
    texture cloud's pictures). An input that cannot be read adds nothing here: it fails its own job
    when that runs, not the batch."""
    from fishgen.commands.paths import check_inputs, read_beside
    from fishgen.exchange.registry import FORMATS

    found = []
    # a manifest often builds one input many times (variants, LODs): each is read once
    beside: dict[tuple, list[Path]] = {}
    for job in manifest.jobs:
        textures = getattr(job.options, "textures", None)
        key = (tuple(job.inputs), job.kind, textures)
        if key not in beside:
            try:
                kinds = check_inputs(job.inputs, job.kind, list(FORMATS.values()), default=FORMATS["species"])
                beside[key] = read_beside(job.inputs, kinds, textures)
            except FishgenError:
                beside[key] = []
        found.append((job, [*job.inputs, *beside[key]]))
    return found


def _guarded(jobs: list[Job], reads: list[tuple[Job, list[Path]]]) -> list[Job]:
    """``jobs`` each guarded against replacing the files any job reads in its output folder: a side
    file (``a.gltf``'s ``a_b.png``) over another job's texture cloud picture. Which side files a
    job writes is known only as it writes them (the images it holds), so its writers refuse such a
    file then, as a command's writers refuse its own inputs; the job fails, and the others run.
    Only files in some output folder are guards: most batches have none."""
    folders = {job.output.parent.resolve() for job in jobs}
    by_folder: dict[Path, list[Path]] = {}
    for _, paths in reads:
        for path in paths:
            folder = Path(os.path.abspath(path)).parent.resolve()
            if folder in folders:
                by_folder.setdefault(folder, []).append(path)
    if not by_folder:
        return jobs
    guards = {folder: tuple(dict.fromkeys(paths)) for folder, paths in by_folder.items()}
    return [replace(job, guard=guards.get(job.output.parent.resolve(), ())) for job in jobs]


def _check_report(report: Path, manifest: Manifest, reads: list[tuple[Job, list[Path]]]) -> None:
    """``--report`` is none of the files the jobs read or write, checked before any job runs: the
    manifest, each job's inputs and the files they name (a species' textures, a texture cloud's
    pictures, what the record says a job read last time), and each job's output and side files."""
    from fishgen.atomic import check_writable
    from fishgen.batch import LOCK_NAME
    from fishgen.batch.record import RECORD_NAME, Record
    from fishgen.commands.paths import check_targets
    from fishgen.errors import UsageError
    from fishgen.exchange.registry import first_shared

    # realpath, not resolve(): a symlink loop is no error here, as the checks below find it
    own = {name for name in (RECORD_NAME, LOCK_NAME)
           if os.path.realpath(report) == os.path.realpath(manifest.out / name)}
    if own:  # the record says which jobs may be skipped next time; the lock keeps one batch a folder
        raise UsageError(f"expected a report that is not the batch's own {own.pop()}, found "
                         f"{os.fspath(report)!r}")
    recorded = Record(manifest.out).jobs  # first: a file named again below is then named as given
    read = [Path(os.path.normpath(manifest.out / name)) for job in manifest.jobs
            if isinstance(inputs := recorded.get(job.name, {}).get("inputs"), dict) for name in inputs]
    read += [*([manifest.file] if manifest.file else []), *(p for _, ps in reads for p in ps)]
    check_targets([report], read)
    check_writable(report)   # before the jobs, not after them
    clash = first_shared([report, *(job.output for job in manifest.jobs)])
    if clash is not None and clash[0] == 0:
        job = manifest.jobs[clash[1] - 1]
        raise UsageError(f"expected a report that is none of the jobs' outputs, found {os.fspath(report)!r}, "
                         f"which job {job.name} ({job.where}) writes as {clash[2]}")


def _job_error(outcome) -> FishgenError:
    return (outcome.error or FishgenError("failed")).of_job(outcome.job.name)


def _tell(outcome, events: Events, bar: Progress | None) -> None:
    """One finished job: its error and notes on stderr, its line (or the bar's step) on stdout."""
    if outcome.status == "failed" and events.failed is not None:
        events.failed(_job_error(outcome))
    for note in outcome.notes:
        events.note(note)
    if bar is not None and outcome.status != "skipped":
        bar.update(1)
    if outcome.status != "failed":
        text = f"{outcome.status:<8} {outcome.job.name}"
        if outcome.status == "built":
            text += f" ({outcome.seconds:.2f} s)"
        events.line(text, outcome.reason)


def _shown(path: Path) -> str:
    """The out folder as the user would type it: relative below the current folder, else absolute."""
    try:
        shown = os.path.relpath(path)
    except ValueError:  # another drive (Windows)
        return os.fspath(path)
    return os.fspath(path) if shown.startswith("..") else shown
