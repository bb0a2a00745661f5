"""The incremental record: what each output was built from, so unchanged jobs are skipped.

``OUT/.fishgen-batch.json`` holds, per job (keyed by its output name): its key, every file it
read and every file it wrote with their SHA-256, paths relative to the out folder. A job is up
to date when the key computed from today's files equals the recorded one and every recorded
output still has its recorded hash. The record is rewritten atomically while jobs finish (at
most every SAVE_INTERVAL) and at the end, so an interrupted batch leaves it consistent with the
files on disk: an entry it lost only makes that job run again.

Leaf module (hashlib and json only): deciding that nothing changed must not import numpy.
"""
from __future__ import annotations

import functools
import hashlib
import json
import os
import re
import sys
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from fishgen import __version__
from fishgen.atomic import write_bytes
from fishgen.batch.manifest import Job

RECORD_NAME = ".fishgen-batch.json"
FORMAT = "fishgen-batch-record"
FORMAT_VERSION = 1
CHUNK = 1 << 20


LIBRARIES = ("numpy", "scipy", "pillow", "usd_core")
"""Packages whose results reach an output's bytes (as their distributions name them, normalised):
a job built with other versions of them runs again. Pillow 10.4 and 13.0 drew one random species'
texture 15 pixels apart, and the record held fishgen's version alone (QA pass 17)."""
_DISTRIBUTION = re.compile(r"^([A-Za-z0-9_.]+?)-([^-]+?)(?:-py[^-]*)?\.(?:dist|egg)-info$")


@functools.lru_cache(maxsize=1)
def library_versions() -> dict[str, str]:
    """The installed version of each of LIBRARIES that is installed, as Python would import it:
    the first ``NAME-VERSION.dist-info`` (or ``.egg-info``) on ``sys.path``. One listing of each
    folder, no import and no importlib.metadata (50 ms here; a batch with nothing to do took 0.10 s)."""
    found: dict[str, str] = {}
    for folder in sys.path:
        try:
            names = os.listdir(folder or ".")
        except OSError:
            continue
        for name in names:
            match = _DISTRIBUTION.match(name)
            if match is None:
                continue
            key = re.sub(r"[-_.]+", "_", match[1]).lower()
            if key in LIBRARIES and key not in found:
                found[key] = match[2]
        if len(found) == len(LIBRARIES):
            break
    return dict(sorted(found.items()))


def file_sha256(path: str | os.PathLike) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        while block := handle.read(CHUNK):
            digest.update(block)
    return digest.hexdigest()


class Hashes:
    """SHA-256 of files, each read once per run (species share textures; schools share species)."""

    def __init__(self) -> None:
        self._known: dict[str, str | None] = {}

    def __call__(self, path: str | os.PathLike) -> str | None:
        """The file's hash, or None when it cannot be read (the job will run and say why)."""
        key = os.fspath(path)
        if key not in self._known:
            try:
                self._known[key] = file_sha256(key)
            except OSError:
                self._known[key] = None
        return self._known[key]

    def forget(self, path: str | os.PathLike) -> None:
        self._known.pop(os.fspath(path), None)


def relative(path: str | os.PathLike, base: Path) -> str:
    """A path as the record stores it: relative to the out folder, with forward slashes."""
    where, home = os.fspath(path), os.fspath(base)
    if not (os.path.isabs(where) and os.path.isabs(home)):
        where, home = os.path.abspath(where), os.path.abspath(home)
    return _relative(where, home)


@functools.lru_cache(maxsize=8192)
def _relative(path: str, base: str) -> str:
    # memoised on absolute paths (relpath normalises them): a batch asks about the same species
    # and textures for every job that reads them, eight questions per finished job, and relpath
    # was most of the command's own work per job
    return Path(os.path.relpath(path, base)).as_posix()


def canonical_options(options: Any, base: Path) -> dict[str, Any]:
    """The options a manifest may set, by their long names, as JSON values: folders relative to the
    out folder, so keys match on any machine."""
    from fishgen.options import flat, manifest_options

    values = flat(options)
    declared = manifest_options(type(options))
    return {key: _plain(values[f.name], base) for key, (f, _) in sorted(declared.items())}


def _plain(value: Any, base: Path) -> Any:
    if isinstance(value, Path):
        return relative(value, base)
    if isinstance(value, (tuple, list)):
        return [_plain(v, base) for v in value]
    return value


def job_key(job: Job, inputs: Mapping[str, str], base: Path) -> str:
    """SHA-256 of the job's kind, options, fishgen's version and every input's path and content hash."""
    doc = {"record": FORMAT_VERSION, "fishgen": __version__, "kind": job.kind,
           "options": canonical_options(job.options, base), "inputs": sorted(inputs.items())}
    return hashlib.sha256(json.dumps(doc, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


SAVE_INTERVAL = 1.0
"""Seconds between rewrites of the record during a run (each job's entry is kept in memory).
Each rewrite is the whole record (60 kB for 100 jobs, 5 ms of the command's CPU, taken from the
workers); a batch killed outright loses at most this long's entries, and those jobs run again."""


class Record:
    """The record file of one out folder."""

    def __init__(self, out: Path):
        self.out = out
        self.path = out / RECORD_NAME
        self.jobs: dict[str, dict[str, Any]] = {}
        self.damaged = False  # unreadable: every job rebuilds, and the next save repairs it
        self.changed = False  # a job's entry was put since the file was read
        self._saved = time.monotonic()
        try:
            data = json.loads(self.path.read_bytes())
        except FileNotFoundError:
            return
        except (OSError, ValueError):
            self.damaged = True
            return
        if (not isinstance(data, dict) or data.get("format") != FORMAT
                or data.get("version") != FORMAT_VERSION or not isinstance(data.get("jobs"), dict)):
            self.damaged = True
            return
        self.jobs = {k: v for k, v in data["jobs"].items() if isinstance(v, dict)}

    def stale(self, job: Job, hashes: Hashes) -> str | None:
        """Why ``job`` must run, or None when its outputs are up to date."""
        entry = self.jobs.get(job.name)
        if entry is None:
            return "not built before"
        try:
            inputs: dict[str, str] = dict(entry["inputs"])
            outputs: dict[str, str] = dict(entry["outputs"])
            if entry.get("kind") != job.kind:
                return "the job's kind changed"
            if entry.get("fishgen") != __version__:
                return f"fishgen {entry.get('fishgen')} built it, this is {__version__}"
            built, installed = entry.get("libraries"), library_versions()
            if built != installed:
                if not isinstance(built, dict):
                    return "its libraries' versions were not recorded"
                name = next(n for n in sorted({*built, *installed}) if built.get(n) != installed.get(n))
                return f"{name} {built.get(name, '(none)')} built it, this is {installed.get(name, '(none)')}"
            if canonical_options(job.options, self.out) != entry.get("options"):
                return "its options changed"
            if any(relative(p, self.out) not in inputs for p in job.inputs):
                return "its inputs changed"
            current = {}
            for name, digest in inputs.items():
                now = hashes(self.out / name)
                if now != digest:
                    return f"{name} {'changed' if now is not None else 'is gone'}"
                current[name] = now
            if job_key(job, current, self.out) != entry.get("key"):
                return "its key changed"
            for name, digest in outputs.items():
                now = hashes(self.out / name)
                if now != digest:
                    return f"output {name} {'changed' if now is not None else 'is missing'}"
        except (KeyError, TypeError, ValueError):
            return "its record entry is damaged"
        return None

    def entry(self, job: Job, inputs: Mapping[str, str], outputs: Mapping[str, str]) -> dict[str, Any]:
        """The entry for a job just built; ``inputs``/``outputs`` map absolute paths to hashes."""
        ins = {relative(p, self.out): h for p, h in inputs.items()}
        return {"kind": job.kind, "key": job_key(job, ins, self.out), "fishgen": __version__,
                "libraries": library_versions(), "options": canonical_options(job.options, self.out),
                "inputs": dict(sorted(ins.items())),
                "outputs": {relative(p, self.out): h for p, h in sorted(outputs.items())}}

    def put(self, name: str, entry: dict[str, Any]) -> None:
        """Set a job's entry; the record is rewritten atomically at most every SAVE_INTERVAL
        seconds (and once at the end, however the run ends). A batch killed before a rewrite
        loses only that moment's entries: those jobs run again, their outputs whole either way.
        A failed job keeps its old entry: its old output is still there, whole, and its changed
        inputs make it run again."""
        self.jobs[name] = entry
        self.changed = True
        if time.monotonic() - self._saved >= SAVE_INTERVAL:
            try:
                self.save(durable=False)
            except OSError:  # a full disk: the final, durable save says so, with the path
                pass

    def save(self, durable: bool = True) -> None:
        """Replace the record file atomically. ``durable=False`` skips the fsync: the rename alone
        is atomic against a killed process, and after a power cut an older or unreadable record
        only means more jobs run (an fsync per job cost 1 s over 100 builds here)."""
        # One line per job: readable, diffable, and written by json's C encoder (an indented dump
        # goes through the pure-Python one: rewriting it after each of 100 jobs took 1.2 s of CPU
        # away from the workers on a 2-core machine).
        jobs = ",\n".join(f" {json.dumps(name)}:{json.dumps(entry, sort_keys=True, separators=(',', ':'))}"
                           for name, entry in sorted(self.jobs.items()))
        data = (f'{{"format":{json.dumps(FORMAT)},"version":{json.dumps(FORMAT_VERSION)},"jobs":{{\n'
                f"{jobs}\n}}}}\n").encode()
        if durable:
            write_bytes(self.path, data)
        else:
            temporary = self.path.with_name(f".{self.path.name}.{os.getpid()}.tmp")
            try:
                temporary.write_bytes(data)
                os.replace(temporary, self.path)
            except BaseException:
                temporary.unlink(missing_ok=True)
                raise
        self.damaged = False
        self._saved = time.monotonic()
