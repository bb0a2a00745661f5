"""Batch manifests (TOML) and folder scans, read into typed jobs.

    out = "../out/assets"          # outputs and the record go here (relative to this file; --out overrides)

    [[build]]
    input = "bonybream.txt"        # relative to this file
    output = "fish/bonybream.glb"  # relative to out; the extension picks the format
    fins = "mask"                  # any `fishgen build` option, by its long name

    [[school]]
    input = "reef.toml"            # a scene file, or inputs = ["a.txt", "b.txt"]
    output = "reef.glb"
    frames = 90

    [[clouds]]
    inputs = ["clouds/table_4_3.awn", "clouds/table_4_4.awn"]
    offset = [[0, 0, 0], [20, 2, -8]]
    output = "sky.glb"

Every mistake is one ``FILE:LINE: expected ..., found ...`` line, found before any job runs.
Leaf module (no numpy): it is read on every run, including the fast run where nothing changed.
"""
from __future__ import annotations

import hashlib
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path, PurePosixPath
from typing import Any

from fishgen.errors import FishgenError, UsageError, not_a_file
from fishgen.exchange.registry import first_shared, output_format
from fishgen.options import build, check_value, manifest_options
from fishgen.tomlfile import Where, loads, text_of

MAX_MANIFEST_BYTES = 16 << 20


@dataclass(frozen=True)
class Kind:
    """A command a manifest may list jobs of, as the batch command declares it: the batch itself
    knows no command."""

    name: str                        # its [[table]] in a manifest, and Job.kind
    options: type                    # its frozen options record, whose manifest keys a job may set
    holds: tuple[str, ...] = ()      # what its output's format must hold
    check: Callable[[Any, str | os.PathLike | None], None] | None = None  # refuses options that cannot
                                                    # go together, or with the output (UsageError)


@dataclass(frozen=True)
class Job:
    """One unit of work: a command, its inputs, its options record (every option, defaults filled)
    and its output."""

    kind: str
    name: str                        # the output relative to the out folder, POSIX: the job's identity
    inputs: tuple[Path, ...]         # the files the manifest names (absolute)
    output: Path                     # absolute
    options: Any = None              # the command's options record
    source: str = ""                 # the manifest (or the input of a folder scan) naming the job
    line: int | None = None          # the job's output line in its manifest
    # other jobs' inputs in this job's output folder, which its writers may not replace
    guard: tuple[Path, ...] = field(default=(), compare=False, repr=False)

    @property
    def where(self) -> str:
        """``FILE:LINE`` of the job, for messages."""
        return f"{self.source}:{self.line}" if self.line is not None else self.source


@dataclass(frozen=True)
class Manifest:
    file: Path | None                # None for a folder scan
    out: Path                        # absolute; the record lives here
    jobs: tuple[Job, ...]


def derived_seed(name: str) -> int:
    """A job's seed from its identity (its output name), the same on every machine and run."""
    digest = hashlib.sha256(f"fishgen batch seed\0{name}".encode()).digest()
    return int.from_bytes(digest[:4], "big")


def load_manifest(path: str | os.PathLike, out: str | os.PathLike | None = None, *,
                  kinds: Sequence[Kind]) -> Manifest:
    """Read and check a manifest of jobs of ``kinds``; ``out`` (the command's ``--out``) overrides its
    ``out`` key."""
    path = Path(path)
    file = os.fspath(path)
    if not path.is_file():
        raise not_a_file("a batch manifest or a folder", file)
    if path.stat().st_size > MAX_MANIFEST_BYTES:
        raise FishgenError(f"expected a manifest of at most {MAX_MANIFEST_BYTES:,} bytes, "
                           "found a larger file", file)
    text = text_of(path.read_bytes(), file)
    data = loads(text, file)
    where = Where(text, file)
    tables = ", ".join(f"[[{k.name}]]" for k in kinds)
    known = ("out", *[k.name for k in kinds])
    for key in data:
        if key not in known:  # a misspelt key, or a misspelt [[table]] (its header line)
            raise FishgenError(f"expected one of out, {tables}, found {key!r}",
                               file, where.line(key) or where.line("", key))
    folder = path.resolve().parent
    if out is None and "out" in data:
        if not isinstance(data["out"], str) or not data["out"]:
            raise where.fail("out as a folder name", data["out"], "out")
        out = folder / data["out"]
    out_dir = Path(os.path.abspath(out if out is not None else "out"))
    jobs: list[Job] = []
    seen: dict[str, str] = {}
    for kind in kinds:
        entries = data.get(kind.name, [])
        if isinstance(entries, dict):   # [build], one table, where each job is a [[build]]
            raise FishgenError(f"expected [[{kind.name}]] tables (one a job), found a single [{kind.name}] "
                               "table", file, where.line("", kind.name))
        if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
            raise where.fail(f"[[{kind.name}]] tables", entries, kind.name)
        for nth, entry in enumerate(entries):
            job = _job(where, kind, nth, entry, folder, out_dir)
            if job.name in seen:
                raise where.fail(f"one job per output, the first at {seen[job.name]}", job.name, "output",
                                 kind.name, nth)
            seen[job.name] = job.where
            jobs.append(job)
    if not jobs:
        raise FishgenError(f"expected at least one job ({tables}), found none", file)
    _apart(jobs)
    return Manifest(path, out_dir, tuple(jobs))


def _apart(jobs: Sequence[Job]) -> None:
    """No two jobs may write one file, side files included (a.gltf's and a.obj's ``a_skin.png``):
    the later would replace the earlier's, and each run would rebuild both."""
    clash = first_shared([job.output for job in jobs])
    if clash is not None:
        first, second = sorted((jobs[clash[0]], jobs[clash[1]]), key=lambda job: job.line or 0)
        name = clash[2]
        raise FishgenError(f"expected jobs whose outputs are different files, found {first.name} "
                           f"({first.where}) and {second.name}, which both write {name}", second.source,
                           second.line)


def _job(where: Where, of: Kind, nth: int, entry: dict[str, Any], folder: Path, out: Path) -> Job:
    kind = of.name

    def fail_at(key: str) -> Callable[[str], FishgenError]:
        return lambda what: where.fail(f"{key} as {what}", entry.get(key, "no value"), key, kind, nth)

    record = of.options
    declared = manifest_options(record)
    known = {"input", "inputs", "output", *declared}
    for key in entry:
        if key not in known:
            raise where.fail(f"one of {', '.join(sorted(known))} in [[{kind}]]", key, key, kind, nth)
    if ("input" in entry) == ("inputs" in entry):
        raise where.fail(f"either input or inputs in [[{kind}]]", "both" if "input" in entry else "no input",
                         "inputs" if "inputs" in entry else "input", kind, nth)
    names = [entry["input"]] if "input" in entry else entry["inputs"]
    key = "input" if "input" in entry else "inputs"
    if not (isinstance(names, list) and names and all(isinstance(n, str) and n for n in names)):
        raise fail_at(key)("a file name" if key == "input" else "a list of file names")
    if kind == "build" and len(names) != 1:
        raise fail_at(key)("one species file (one job per species)")
    inputs = tuple(Path(os.path.abspath(folder / n)) for n in names)
    if kind == "school" and len(inputs) > 1 and any(p.suffix.lower() == ".toml" for p in inputs):
        raise fail_at(key)("one scene file alone or species files")
    output = entry.get("output")
    if not isinstance(output, str) or not output:
        raise fail_at("output")("a file name inside the out folder")
    relative = PurePosixPath(output.replace("\\", "/"))
    if relative.is_absolute() or ".." in relative.parts or relative.name in ("", "."):
        raise fail_at("output")("a file name inside the out folder (no absolute path, no ..)")
    try:
        output_format(relative, of.holds)
    except FishgenError as err:
        raise err.at(where.file, where.line("output", kind, nth)) from None
    name = relative.as_posix()
    values: dict[str, Any] = {}
    for key, (f, spec) in declared.items():
        if key in entry:
            value = check_value(spec, entry[key], fail_at(key))
            values[f.name] = Path(os.path.abspath(folder / value)) if spec.path else value
            if spec.exists and not values[f.name].is_dir():   # said at its line, before any job runs
                raise fail_at(key)("an existing folder (relative to the manifest)")
    options: Any = build(record, values)
    offsets = getattr(options, "offset", None)
    if offsets and len(offsets) != len(inputs):
        raise fail_at("offset")(f"one [x, y, z] per input ({len(inputs)})")
    if of.check is not None:
        try:
            of.check(options, relative)
        except UsageError as err:  # said at the job's line, before any job runs
            line = where.line("output", kind, nth)
            raise FishgenError(err.message.replace("--", ""), where.file, line) from None
    return Job(kind, name, inputs, out / relative, _seeded(kind, options, inputs, name), where.file,
               where.line("output", kind, nth))


def _seeded(kind: str, options: Any, inputs: tuple[Path, ...], name: str) -> Any:
    """Seeds come from the job's identity unless the manifest (or a school's scene file) sets one."""
    scene = kind == "school" and inputs[0].suffix.lower() == ".toml"
    if getattr(options, "seed", 0) is None and not scene:
        return replace(options, seed=derived_seed(name))
    return options


def scan_folder(folder: str | os.PathLike, out: str | os.PathLike, *, kinds: Sequence[Kind]) -> Manifest:
    """Every species file (.txt), cube file (.awn) and texture cloud (.awa) under ``folder``, default
    options (of ``kinds``' records), as ``.glb`` in ``out`` at the same relative place. Hidden folders
    and ``out`` itself are not searched."""
    from fishgen.exchange.registry import FORMATS

    # the source formats a single file makes an asset from: species files, cube and texture clouds
    scanned = {ext: fmt.command for fmt in FORMATS.values() if fmt.command in ("build", "clouds")
               for ext in fmt.extensions}
    records = {k.name: k.options for k in kinds}
    root = Path(os.path.abspath(folder))
    out_dir = Path(os.path.abspath(out))
    jobs: list[Job] = []
    seen: dict[str, Path] = {}
    for dirpath, dirnames, filenames in os.walk(root):
        here = Path(dirpath)
        dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and here / d != out_dir)
        for filename in sorted(filenames):
            source = here / filename
            suffix = source.suffix.lower()
            kind = scanned.get(suffix)
            if kind is None or filename.startswith("."):
                continue
            name = source.relative_to(root).with_suffix(".glb").as_posix()
            if name in seen:
                raise FishgenError(f"expected one source per output, found {seen[name].name} and {filename} "
                                   f"both making {name}", source)
            seen[name] = source
            options = _seeded(kind, records[kind](), (source,), name)
            jobs.append(Job(kind, name, (source,), out_dir / name, options, os.fspath(source)))
    if not jobs:
        raise FishgenError(f"expected species files or cube files ({', '.join(scanned)}) in the folder, "
                           "found none",
                           folder)
    return Manifest(None, out_dir, tuple(jobs))
