"""Run one batch job through the library API, in whatever process or Dask worker it lands on.

A job returns a :class:`Result` and never raises for bad input: a species file's
``FILE:LINE`` error fails its own job and the batch goes on. Every file the job read (the
manifest's inputs, the textures a species names, the species of a school's scene, a path CSV)
and every file it wrote come back with their SHA-256, so the record can tell later whether
anything changed without parsing anything.
"""
from __future__ import annotations

import os
import time
import traceback
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fishgen.batch.manifest import Job
from fishgen.batch.record import file_sha256
from fishgen.errors import FishgenError


@dataclass
class Result:
    name: str
    status: str                                   # "built" or "failed"
    seconds: float = 0.0
    inputs: dict[str, str] = field(default_factory=dict)   # absolute path -> sha256, every file read
    outputs: dict[str, str] = field(default_factory=dict)  # absolute path -> sha256, every file written
    error: dict[str, Any] | None = None           # message, file, line, kind (input | os | worker | internal)
    notes: list[str] = field(default_factory=list)  # warnings about the inputs, one line each


def run_job(job: Job) -> Result:
    """Build one job's output atomically; its errors become a failed :class:`Result`."""
    start = time.perf_counter()
    result = Result(job.name, "failed")
    reads: list[Path] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            written = RUNNERS[job.kind](job, reads)
        result.notes = [str(w.message) for w in caught if issubclass(w.category, UserWarning)]
        result.inputs = {os.fspath(p): file_sha256(p) for p in dict.fromkeys(reads)}
        result.outputs = {os.fspath(p): file_sha256(p) for p in written}
        result.status = "built"
    except FishgenError as err:
        result.error = {"message": str(err), "file": err.file, "line": err.line, "kind": "input"}
    except OSError as err:
        result.error = {"message": f"{err.filename or ''}: {err.strerror or err}".lstrip(": "),
                        "file": err.filename, "line": None, "kind": "os"}
    except Exception as err:  # a bug in one job must not take the batch down; the trace says where
        result.error = {"message": f"internal error: {type(err).__name__}: {err}", "file": None, "line": None,
                        "kind": "internal", "traceback": traceback.format_exc()}
    result.seconds = time.perf_counter() - start
    return result


def _build(job: Job, reads: list[Path]) -> list[Path]:
    from fishgen.assembly.fish import build_fish
    from fishgen.exchange import export
    from fishgen.exchange.registry import MESHES
    from fishgen.species.parser import load_species

    o = job.options
    reads.extend(job.inputs)
    species = load_species(job.inputs[0], o["textures"])
    reads.extend(t for t in (species.colour_texture, species.mask_texture) if t is not None)
    scene = build_fish(species, fins=o["fins"], length=o["length"], fps=o["fps"], swim=o["swim"],
                       speed=o["speed"])
    return export(scene, job.output, require=[MESHES])


def _school(job: Job, reads: list[Path]) -> list[Path]:
    from fishgen.exchange import export
    from fishgen.exchange.registry import MESHES, NODE_ANIMATION
    from fishgen.school import run_school
    from fishgen.school.scene_file import SceneFile, SpeciesEntry, check_size, load_scene_file, with_options
    from fishgen.species.parser import load_species

    o = job.options
    reads.extend(job.inputs)
    if job.inputs[0].suffix.lower() == ".toml":
        scene = load_scene_file(job.inputs[0])
        reads.extend(_scene_side_files(job.inputs[0]))
    else:
        scene = SceneFile(species=tuple(SpeciesEntry(p, 50) for p in job.inputs))
    # The options override the scene file exactly as `fishgen school`'s do.
    scene = with_options(scene, count=o["count"], frames=o["frames"], fps=o["fps"], seed=o["seed"],
                         model=o["model"])
    check_size(scene, job.source, job.line)
    for entry in scene.species:  # the species and their textures are inputs too
        species = load_species(entry.file, o["textures"])
        reads.append(Path(entry.file))
        reads.extend(t for t in (species.colour_texture, species.mask_texture) if t is not None)
    run = run_school(scene, fins=o["fins"], swim=o["swim"], tolerance=o["tolerance"],
                     textures_dir=o["textures"])
    return export(run.scene, job.output, require=[MESHES, NODE_ANIMATION])


def _scene_side_files(path: Path) -> list[Path]:
    """A scene file's target or predator path given as a CSV file (load_scene_file checked it)."""
    from fishgen.school.scene_file import PATHS
    from fishgen.tomlfile import loads

    data = loads(path.read_text(encoding="utf-8", errors="replace").removeprefix("\ufeff"), os.fspath(path))
    files = []
    for table in ("target", "predator"):
        kind = data.get(table, {}).get("path") if isinstance(data.get(table), dict) else None
        if isinstance(kind, str) and kind not in PATHS:
            files.append(path.parent / kind)
    return files


def _clouds(job: Job, reads: list[Path]) -> list[Path]:
    from fishgen.clouds import check_output, export_cloud, fill_cloud, load_cubes, merge_clouds

    o = job.options
    billboards, limit = o["billboards"], o["max-particles"]
    check_output(job.output, billboards)
    reads.extend(job.inputs)
    files = [load_cubes(p, max_particles=limit) for p in job.inputs]
    total = sum(f.total for f in files)
    if total > limit:
        raise FishgenError(f"expected at most {limit:,} particles in the scene (raise the limit with "
                           f"max-particles), found {total:,} in {len(files)} files", job.source, job.line)
    check_output(job.output, billboards, particles=total)
    places = [tuple(v) for v in o["offset"]] if o["offset"] is not None else [(0.0, 0.0, 0.0)] * len(files)
    # Input number i is filled with seed + i, as `fishgen clouds` does.
    cloud = merge_clouds([fill_cloud(f, seed=o["seed"] + i, method=o["method"], offset=place)
                          for i, (f, place) in enumerate(zip(files, places, strict=True))])
    return export_cloud(cloud, job.output, billboards=billboards)


RUNNERS = {"build": _build, "school": _school, "clouds": _clouds}


_busy = False    # a local pool worker is running a job (its SIGTERM must unwind the atomic writer)
_orphan = False  # the batch that started this worker is gone (killed with SIGKILL)
_failure_flag: Any = None  # the pool's shared byte: 1 once a job failed under --fail-fast, start no other


class Stopped(BaseException):
    """SIGTERM in a pool worker: unwinds the job (atomic writers remove their temp files)."""


def _stop(signum: int, _frame: object) -> None:
    if _busy:
        raise Stopped(128 + signum)
    os._exit(128 + signum)  # idle: nothing to clean up, and no traceback from the pool's loop


def init_worker(batch_pid: int, failed: Any = None) -> None:
    """A local pool's worker: SIGTERM stops it cleanly; Ctrl-C is the parent's to handle (it stops
    the workers itself, so the terminal's SIGINT to the whole group is ignored here); and when
    the batch itself is killed, the worker finishes the file it is writing and exits. ``failed``
    is the pool's shared byte for --fail-fast (a RawValue: no lock a killed worker could hold)."""
    import signal
    import threading

    global _failure_flag
    _failure_flag = failed

    signal.signal(signal.SIGTERM, _stop)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_watch, args=(batch_pid,), daemon=True).start()


def _watch(batch_pid: int) -> None:
    """A forkserver's worker is not the batch's child, so no pipe or signal tells it the batch died."""
    global _orphan
    while _alive(batch_pid):
        time.sleep(0.2)
    _orphan = True
    if not _busy:
        os._exit(1)


def _alive(pid: int) -> bool:
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


def run_in_worker(jobs: tuple[Job, ...], fail_fast: bool = False) -> list[Result]:
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
            results.append(run_job(job))
            if _orphan:  # nobody is waiting for the results; the outputs are whole either way
                os._exit(1)
            if fail_fast and results[-1].status == "failed":
                if _failure_flag is not None:
                    _failure_flag.value = 1
                break
        return results
    except Stopped as stop:
        os._exit(stop.args[0])
    finally:
        _busy = False
        if _orphan:  # the watcher saw the batch die while this worker was busy
            os._exit(1)
