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
import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any

from fishgen.assembly.fin_modes import FIN_MODES
from fishgen.assembly.swim_modes import DEFAULT_SPEED, SWIM_MODES
from fishgen.errors import FishgenError
from fishgen.exchange.registry import MESHES, NODE_ANIMATION, POINTS, output_format
from fishgen.tomlfile import Where, loads

KINDS = ("build", "school", "clouds")
# These mirror the library's constants without importing numpy (a test checks they agree).
SCHOOL_MODELS = ("boids", "pso")
CLOUD_METHODS = ("paper", "uniform")
DEFAULT_MAX_PARTICLES = 50_000_000
MAX_MANIFEST_BYTES = 16 << 20
#: What each kind's output must hold (the registry's words), checked when the manifest is read.
HOLDS = {"build": [MESHES], "school": [MESHES, NODE_ANIMATION], "clouds": [POINTS]}
SEED_LIMIT = 2**32  # seeds are 0 .. 2**32 - 1 for every kind, as `fishgen school` takes them


@dataclass(frozen=True)
class Job:
    """One unit of work: a kind, its inputs, its options (every one, defaults filled) and its output."""

    kind: str
    name: str                        # the output relative to the out folder, POSIX: the job's identity
    inputs: tuple[Path, ...]         # the files the manifest names (absolute)
    output: Path                     # absolute
    options: Mapping[str, Any] = field(default_factory=dict)  # JSON values; folders as Path
    source: str = ""                 # the manifest (or the input of a folder scan) naming the job
    line: int | None = None          # the job's output line in its manifest

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


# -- option checks: (value, fail) -> normalized value; ``fail(what)`` raises at the option's line ----

Check = Callable[[Any, Callable[[str], FishgenError]], Any]


def _number(low: float, high: float, whole: bool = False) -> Check:
    def check(value: Any, fail: Callable[[str], FishgenError]) -> Any:
        ok = isinstance(value, int) if whole else isinstance(value, (int, float))
        if isinstance(value, bool) or not ok or not math.isfinite(value) or not low <= value <= high:
            raise fail(f"{'a whole number' if whole else 'a number'} from {low:g} to {high:g}")
        return int(value) if whole else float(value)
    return check


def _choice(choices: tuple[str, ...]) -> Check:
    def check(value: Any, fail: Callable[[str], FishgenError]) -> Any:
        if value not in choices:
            raise fail(f"one of {', '.join(choices)}")
        return value
    return check


def _flag(value: Any, fail: Callable[[str], FishgenError]) -> bool:
    if not isinstance(value, bool):
        raise fail("true or false")
    return value


def _folder(value: Any, fail: Callable[[str], FishgenError]) -> str:
    if not isinstance(value, str) or not value:
        raise fail("a folder name")
    return value  # resolved against the manifest's folder by the caller


def _offsets(value: Any, fail: Callable[[str], FishgenError]) -> list[list[float]]:
    if not (isinstance(value, list) and all(isinstance(v, list) and len(v) == 3 for v in value)):
        raise fail("a list of [x, y, z], one per input")
    try:
        return [[_number(-3.4e38, 3.4e38)(c, fail) for c in v] for v in value]
    except FishgenError:
        raise fail("a list of [x, y, z] of finite numbers within float32 range, one per input") from None


# name -> (check, default). Names and ranges are those of the command's own options.
OPTIONS: dict[str, dict[str, tuple[Check, Any]]] = {
    "build": {"fins": (_choice(FIN_MODES), None), "length": (_number(0.001, 1e4), None),
              "fps": (_number(1, 1000), 30.0), "swim": (_choice(SWIM_MODES), "body"),
              "speed": (_number(0.01, 100), DEFAULT_SPEED), "textures": (_folder, None)},
    "school": {"count": (_number(1, 100_000, whole=True), None),
               "frames": (_number(2, 100_000, whole=True), None), "fps": (_number(1, 1000), None),
               "seed": (_number(0, SEED_LIMIT - 1, whole=True), None),
               "model": (_choice(SCHOOL_MODELS), None),
               "tolerance": (_number(0, 1), 0.002), "fins": (_choice(FIN_MODES), None),
               "swim": (_choice(SWIM_MODES), "body"), "textures": (_folder, None)},
    "clouds": {"offset": (_offsets, None), "seed": (_number(0, SEED_LIMIT - 1, whole=True), None),
               "method": (_choice(CLOUD_METHODS), "paper"), "billboards": (_flag, False),
               "max-particles": (_number(1, 2**62, whole=True), DEFAULT_MAX_PARTICLES)},
}


def load_manifest(path: str | os.PathLike, out: str | os.PathLike | None = None) -> Manifest:
    """Read and check a manifest; ``out`` (the command's ``--out``) overrides its ``out`` key."""
    path = Path(path)
    file = os.fspath(path)
    if not path.is_file():
        raise FishgenError("expected an existing manifest file, found none", file)
    if path.stat().st_size > MAX_MANIFEST_BYTES:
        raise FishgenError(f"expected a manifest of at most {MAX_MANIFEST_BYTES:,} bytes, "
                           "found a larger file", file)
    text = path.read_bytes().decode("utf-8", errors="replace").removeprefix("\ufeff")
    data = loads(text, file)
    where = Where(text, file)
    for key in data:
        if key not in ("out", *KINDS):  # a misspelt key, or a misspelt [[table]] (its header line)
            raise FishgenError(f"expected one of out, {', '.join(f'[[{k}]]' for k in KINDS)}, found {key!r}",
                               file, where.line(key) or where.line("", key))
    folder = path.resolve().parent
    if out is None and "out" in data:
        if not isinstance(data["out"], str) or not data["out"]:
            raise where.fail("out as a folder name", data["out"], "out")
        out = folder / data["out"]
    out_dir = Path(os.path.abspath(out if out is not None else "out"))
    jobs: list[Job] = []
    seen: dict[str, str] = {}
    for kind in KINDS:
        entries = data.get(kind, [])
        if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
            raise where.fail(f"[[{kind}]] tables", entries, kind)
        for nth, entry in enumerate(entries):
            job = _job(where, kind, nth, entry, folder, out_dir)
            if job.name in seen:
                raise where.fail(f"one job per output, the first at {seen[job.name]}", job.name, "output",
                                 kind, nth)
            seen[job.name] = job.where
            jobs.append(job)
    if not jobs:
        raise FishgenError("expected at least one [[build]], [[school]] or [[clouds]] job, found none", file)
    return Manifest(path, out_dir, tuple(jobs))


def _job(where: Where, kind: str, nth: int, entry: dict[str, Any], folder: Path, out: Path) -> Job:
    def fail_at(key: str) -> Callable[[str], FishgenError]:
        return lambda what: where.fail(f"{key} as {what}", entry.get(key, "no value"), key, kind, nth)

    known = {"input", "inputs", "output", *OPTIONS[kind]}
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
        output_format(relative, HOLDS[kind])
    except FishgenError as err:
        raise FishgenError(err.message, where.file, where.line("output", kind, nth)) from None
    name = relative.as_posix()
    options: dict[str, Any] = {}
    for option, (check, default) in OPTIONS[kind].items():
        value = check(entry[option], fail_at(option)) if option in entry else default
        if option == "textures" and value is not None:
            value = Path(os.path.abspath(folder / value))
        options[option] = value
    if kind == "clouds" and options["offset"] is not None and len(options["offset"]) != len(inputs):
        raise fail_at("offset")(f"one [x, y, z] per input ({len(inputs)})")
    _seed(kind, options, inputs, name)
    return Job(kind, name, inputs, out / relative, options, where.file, where.line("output", kind, nth))


def _seed(kind: str, options: dict[str, Any], inputs: tuple[Path, ...], name: str) -> None:
    """Seeds come from the job's identity unless the manifest (or a school's scene file) sets one."""
    if kind == "clouds" and options["seed"] is None:
        options["seed"] = derived_seed(name)
    if kind == "school" and options["seed"] is None and inputs[0].suffix.lower() != ".toml":
        options["seed"] = derived_seed(name)


def scan_folder(folder: str | os.PathLike, out: str | os.PathLike) -> Manifest:
    """Every species file (.txt) and cube file (.awn) under ``folder``, default options, as ``.glb``
    in ``out`` at the same relative place. Hidden folders and ``out`` itself are not searched."""
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
            kind = {".txt": "build", ".awn": "clouds"}.get(suffix)
            if kind is None or filename.startswith("."):
                continue
            name = source.relative_to(root).with_suffix(".glb").as_posix()
            if name in seen:
                raise FishgenError(f"expected one source per output, found {seen[name].name} and {filename} "
                                   f"both making {name}", source)
            seen[name] = source
            options = {option: default for option, (_, default) in OPTIONS[kind].items()}
            _seed(kind, options, (source,), name)
            jobs.append(Job(kind, name, (source,), out_dir / name, options, os.fspath(source)))
    if not jobs:
        raise FishgenError("expected species files (.txt) or cube files (.awn) in the folder, found none",
                           folder)
    return Manifest(None, out_dir, tuple(jobs))
