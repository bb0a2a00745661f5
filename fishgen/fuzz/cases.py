"""Fuzz cases: how one is generated from ``(seed, target, index)``, run, and judged.

A case passes when the code under test either succeeds (and every output it wrote is
finite) or raises :class:`fishgen.errors.FishgenError`; for the CLI, when it exits 0
(outputs finite) or exits 2 with one error line on stderr and no traceback. Anything
else is a *finding*, keyed by exception type + innermost fishgen frame so that one bug
found a thousand times is reported once.
"""
from __future__ import annotations

import io
import json
import math
import os
import random
import shutil
import struct
import sys
import traceback
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fishgen.fuzz import mutate

TARGETS = ("species", "cubes", "gltf", "obj", "ply", "cli",
           "scene", "paths", "manifest", "fxl", "photo", "awa", "editor", "options")
READERS = ("gltf", "obj", "ply")
#: Issue 26's targets (the newer commands' inputs).
NEW_TARGETS = ("scene", "paths", "manifest", "fxl", "photo", "awa", "editor", "options")
FISHGEN_ROOT = Path(__file__).resolve().parents[1]
DEFAULT_CORPUS = FISHGEN_ROOT.parent / "tests" / "fuzz" / "corpus"


class CaseTimeout(BaseException):
    """Raised by the worker's timer; a BaseException so ``except Exception`` guards cannot hide it."""


@dataclass
class Case:
    target: str
    index: int
    text: str | None = None                 # species
    data: bytes | None = None               # cubes
    files: dict[str, bytes | int] = field(default_factory=dict)  # readers/CLI: name -> bytes or sparse size
    main: str = ""                          # readers: the file load_input opens
    argv: list[str] = field(default_factory=list)  # CLI
    requests: list[bytes] = field(default_factory=list)  # editor: raw HTTP requests, one connection each

    def save(self, folder: Path) -> list[Path]:
        """Write this case's input(s) into ``folder`` (made); returns the paths written."""
        folder.mkdir(parents=True, exist_ok=True)
        written = []
        if self.text is not None:
            p = folder / "input.txt"
            p.write_bytes(self.text.encode("utf-8", "surrogatepass"))
            written.append(p)
        if self.data is not None:
            p = folder / "input.awn"
            p.write_bytes(self.data)
            written.append(p)
        written += write_files(folder, self.files)
        if self.argv:
            p = folder / "argv.json"
            p.write_text(json.dumps(self.argv) + "\n")
            written.append(p)
        for k, request in enumerate(self.requests):
            p = folder / f"request-{k}.http"
            p.write_bytes(request)
            written.append(p)
        return written


def write_files(folder: Path, files: dict[str, bytes | int]) -> list[Path]:
    out = []
    for name, content in files.items():
        if not name or name in (".", "..") or "/" in name or "\\" in name or "\0" in name:
            continue  # a mutated reference such as "../x.png" names no file the case may write
        p = folder / name
        p.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, int):  # a sparse file of this many bytes: huge, but no disk
            with open(p, "wb") as f:
                f.truncate(content)
        else:
            p.write_bytes(content)
        out.append(p)
    return out


# -- seeds -----------------------------------------------------------------------------------------
@dataclass
class Seeds:
    species: list[str]
    cubes: list[bytes]
    assets: dict[str, list[tuple[str, dict[str, bytes | int]]]]  # target -> [(main, files)]
    new: dict[str, dict[str, bytes]] = field(default_factory=dict)  # issue 26's: folder -> {name: bytes}

    def texts(self, folder: str, suffix: str) -> list[str]:
        return [v.decode("utf-8") for k, v in sorted(self.new[folder].items()) if k.endswith(suffix)]

    def count(self, target: str) -> int:
        if target == "species":
            return len(self.species)
        if target == "cubes":
            return len(self.cubes)
        if target in ("cli", "options", "editor", "photo"):
            return 0
        if target in ("scene", "manifest"):
            return len(self.texts(target, ".toml"))
        if target == "paths":
            return 1
        if target == "fxl":
            return len(self.texts("fxl", ".fxl"))
        if target == "awa":
            return 1
        return len(self.assets[target])


def load_seeds(corpus: Path = DEFAULT_CORPUS) -> Seeds:
    species = [p.read_bytes().decode("utf-8") for p in sorted((corpus / "species").glob("*.txt"))]
    cubes = [p.read_bytes() for p in sorted((corpus / "cubes").glob("*.awn"))]
    assets: dict[str, list[tuple[str, dict[str, bytes | int]]]] = {}
    for target, exts in (("gltf", (".glb", ".gltf")), ("obj", (".obj",)), ("ply", (".ply",))):
        assets[target] = []
        for folder in sorted(p for p in (corpus / target).iterdir() if p.is_dir()):
            files: dict[str, bytes | int] = {p.name: p.read_bytes() for p in sorted(folder.iterdir())
                                             if p.is_file()}
            mains = [n for n in files if n.endswith(exts)]
            if len(mains) != 1:
                raise ValueError(f"{folder}: expected one {'/'.join(exts)} file, found {mains}")
            assets[target].append((mains[0], files))
    new = {sub: {p.name: p.read_bytes() for p in sorted((corpus / sub).iterdir()) if p.is_file()}
           for sub in ("scene", "manifest", "fxl", "photo", "awa") if (corpus / sub).is_dir()}
    if not species or not cubes or not all(assets.values()) or len(new) != 5 or not all(new.values()):
        raise ValueError(f"{corpus}: incomplete seed corpus")
    return Seeds(species, cubes, assets, new)


def case_rng(seed: int, target: str, index: int) -> random.Random:
    return random.Random(f"{seed}:{target}:{index}")


def make_case(seeds: Seeds, target: str, seed: int, index: int) -> Case:
    """Case ``index`` of ``target``: the first ones replay the seed corpus verbatim, then mutants."""
    rng = case_rng(seed, target, index)
    verbatim = index < seeds.count(target)
    if target == "species":
        text = seeds.species[index] if verbatim else mutate.species_text(seeds.species, rng)
        return Case(target, index, text=text)
    if target == "cubes":
        data = seeds.cubes[index] if verbatim else mutate.cubes_bytes(seeds.cubes, rng)
        return Case(target, index, data=data)
    if target in READERS:
        main, files = seeds.assets[target][index if verbatim else rng.randrange(len(seeds.assets[target]))]
        if not verbatim:
            fn = {"gltf": mutate.mutate_gltf, "obj": mutate.mutate_obj, "ply": mutate.mutate_ply}[target]
            files = fn(files, main, rng)
        return Case(target, index, files=files, main=main)
    if target == "cli":
        from fishgen.fuzz.cli_gen import cli_case
        files, argv = cli_case(seeds, rng)
        return Case(target, index, files=files, argv=argv)
    if target in NEW_TARGETS:
        from fishgen.fuzz.new_cases import make_new_case
        return make_new_case(seeds, target, rng, index, verbatim)
    raise ValueError(f"unknown target {target!r}")


# -- running one case -------------------------------------------------------------------------------
@dataclass
class Outcome:
    status: str                 # "ok", "error" (a FishgenError / clean CLI error) or "finding"
    key: str = ""
    detail: str = ""


def innermost_fishgen_frame(tb) -> str:
    frames = traceback.extract_tb(tb)
    for fr in reversed(frames):
        path = Path(fr.filename)
        try:
            rel = path.resolve().relative_to(FISHGEN_ROOT)
        except ValueError:
            continue
        if rel.parts and rel.parts[0] == "fuzz":
            continue
        return f"fishgen/{rel.as_posix()}:{fr.lineno} ({fr.name})"
    return "no fishgen frame"


def _chain(err: BaseException):
    seen = set()
    while err is not None and id(err) not in seen:
        seen.add(id(err))
        yield err
        err = err.__cause__ or err.__context__  # type: ignore[assignment]


def classify(err: BaseException) -> Outcome:
    """A raised exception -> an outcome (FishgenError is the one expected error)."""
    from fishgen.errors import FishgenError

    for inner in _chain(err):  # a guard turning MemoryError/timeout into FishgenError hides an overrun
        if isinstance(inner, (MemoryError, CaseTimeout)):
            kind = "memory" if isinstance(inner, MemoryError) else "time"
            where = innermost_fishgen_frame(inner.__traceback__)
            return Outcome("finding", f"budget overrun ({kind}) at {where}",
                           _format(inner))
        if isinstance(inner, RecursionError):
            return Outcome("finding", f"RecursionError at {innermost_fishgen_frame(inner.__traceback__)}",
                           _format(inner))
    if isinstance(err, FishgenError):
        text = str(err)
        if "\n" in text.strip() or "Traceback" in text:
            return Outcome("finding", f"FishgenError with a multi-line message at "
                                      f"{innermost_fishgen_frame(err.__traceback__)}", text[:2000])
        return Outcome("error")
    return Outcome("finding", f"{type(err).__name__} at {innermost_fishgen_frame(err.__traceback__)}",
                   _format(err))


def _format(err: BaseException) -> str:
    text = "".join(traceback.format_exception(type(err), err, err.__traceback__))
    return text[-6000:]


def run_case(case: Case, workdir: Path) -> Outcome:
    """Run one case in this process (the worker); never raises except CaseTimeout/KeyboardInterrupt."""
    try:
        if case.target == "species":
            from fishgen.species.parser import parse_species
            parse_species(case.text or "", "<fuzz>")
            return Outcome("ok")
        if case.target == "cubes":
            return _run_cubes(case)
        if case.target in READERS:
            return _run_reader(case, workdir)
        if case.target in NEW_TARGETS and case.target not in ("photo", "options"):
            from fishgen.fuzz.new_cases import run_new_case
            return run_new_case(case, workdir)
        return _run_cli(case, workdir)
    except CaseTimeout as err:
        return Outcome("finding", f"budget overrun (time) in {case.target} at "
                                  f"{innermost_fishgen_frame(err.__traceback__)}", _format(err))
    except Exception as err:  # the point of the harness: judge whatever came out
        return classify(err)


def _run_cubes(case: Case) -> Outcome:
    from fishgen.clouds.parser import parse_cubes
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cubes = parse_cubes(case.data or b"", "<fuzz>", max_particles=10_000_000)
    if cubes.total <= 2000:  # a small valid file is also filled: its particles must be finite
        import numpy as np

        from fishgen.clouds.fill import fill_cloud
        cloud = fill_cloud(cubes, seed=case.index, method="paper" if case.index % 2 else "uniform")
        for name in ("centers", "radii", "density"):
            values = getattr(cloud, name, None)
            if values is not None and not np.isfinite(np.asarray(values, float)).all():
                return Outcome("finding", f"non-finite cloud {name} from fill_cloud", "")
    return Outcome("ok")


def _fresh(workdir: Path) -> Path:
    case_dir = workdir / "case"
    if case_dir.exists():
        shutil.rmtree(case_dir)
    case_dir.mkdir(parents=True)
    return case_dir


def _run_reader(case: Case, workdir: Path) -> Outcome:
    from fishgen.preview.inputs import load_input
    from fishgen.scene.pose import bounds

    folder = _fresh(workdir)
    write_files(folder, case.files)
    scene = load_input(folder / case.main)
    # What every consumer does next (preview frames the subject, the viewer poses it): a reader
    # that accepts a file must hand over a scene that can be posed, at rest and mid-clip.
    import numpy as np

    boxes = [bounds(scene)]
    clip = scene.clips[0] if scene.clips else None
    if clip is not None:
        boxes.append(bounds(scene, t=clip.duration / 2, clip=clip))
    if not all(np.isfinite(np.asarray(b, float)).all() for b in boxes):
        return Outcome("finding", f"{case.target} reader accepted an asset whose posed bounds are not finite",
                       "")
    return Outcome("ok")


def _run_cli(case: Case, workdir: Path) -> Outcome:
    from fishgen.cli import main

    folder = _fresh(workdir)
    write_files(folder, case.files)
    old_cwd, old_out, old_err = os.getcwd(), sys.stdout, sys.stderr
    out, err = io.StringIO(), io.StringIO()
    code: Any = 0
    os.chdir(folder)
    sys.stdout, sys.stderr = out, err
    from fishgen.fuzz.new_cases import WouldServe, no_serving
    try:
        try:
            with no_serving(case.argv):
                main(list(case.argv))
        except SystemExit as stop:
            code = stop.code if stop.code is not None else 0
        except WouldServe:  # `fishgen fly` got past its checks: it would serve now
            code = 0
    finally:
        sys.stdout, sys.stderr = old_out, old_err
        os.chdir(old_cwd)
    stderr = err.getvalue()
    lines = [ln for ln in stderr.splitlines() if ln.strip() and "warning:" not in ln]
    command = case.argv[0] if case.argv else "?"
    if "Traceback" in stderr:
        return Outcome("finding", f"cli {command}: traceback on stderr", stderr[-3000:])
    if code == 0:
        problem = check_outputs(folder)
        if problem:
            return Outcome("finding", f"cli {command}: {problem}", " ".join(case.argv))
        return Outcome("ok")
    if code == 2:
        if len(lines) != 1:
            many = f"{min(len(lines), 2)}{'+' if len(lines) > 1 else ''}"
            return Outcome("finding", f"cli {command}: exit 2 with {many} error lines on stderr",
                           stderr[-3000:])
        return Outcome("error")
    return Outcome("finding", f"cli {command}: exit status {code} ({_shape(lines[-1] if lines else '')})",
                   stderr[-3000:])


def _shape(line: str) -> str:
    """An error line with paths and numbers blanked, so one cause dedups to one finding."""
    import re
    line = re.sub(r"/[^\s:'\"]+", "PATH", line)
    return re.sub(r"\d+(\.\d+)?", "N", line)[:120]


# -- output checks ----------------------------------------------------------------------------------
def _no_constants(name: str) -> Any:
    raise ValueError(f"JSON holds {name}")


def check_gltf_document(doc: dict, buffers: list[bytes]) -> str:
    """Every float accessor of a glTF document is finite; '' or what is wrong."""
    views = doc.get("bufferViews") or []
    for k, acc in enumerate(doc.get("accessors") or []):
        if acc.get("componentType") != 5126 or acc.get("bufferView") is None:
            continue
        view = views[acc["bufferView"]]
        width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}[acc["type"]]
        raw = buffers[view.get("buffer", 0)]
        start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        stride = view.get("byteStride") or 4 * width
        for row in range(acc["count"]):
            values = struct.unpack_from(f"<{width}f", raw, start + row * stride)
            if not all(math.isfinite(v) for v in values):
                return f"non-finite float in accessor {k} of the written glTF"
    return ""


def check_glb(data: bytes) -> str:
    try:
        length, kind = struct.unpack_from("<II", data, 12)
        doc = json.loads(data[20:20 + length], parse_constant=_no_constants)
        blob = b""
        pos = 20 + length
        if pos + 8 <= len(data):
            blen, _ = struct.unpack_from("<II", data, pos)
            blob = data[pos + 8: pos + 8 + blen]
    except ValueError as err:
        return f"written GLB: {err}"
    return check_gltf_document(doc, [blob])


def check_outputs(folder: Path) -> str:
    """Every file a successful command wrote is finite (glb/gltf floats, JSON, npy, csv)."""
    import numpy as np

    for path in sorted(folder.rglob("*")):
        suffix = path.suffix.lower()
        try:
            if suffix == ".glb":
                problem = check_glb(path.read_bytes())
            elif suffix == ".gltf":
                doc = json.loads(path.read_text(), parse_constant=_no_constants)
                bufs = [(path.parent / b["uri"]).read_bytes() for b in doc.get("buffers") or []]
                problem = check_gltf_document(doc, bufs)
            elif suffix == ".npy":
                arr = np.load(path)
                problem = "" if not np.issubdtype(arr.dtype, np.floating) or np.isfinite(arr).all() \
                    else "non-finite value in the written .npy"
            elif suffix == ".csv":
                bad = any(w.strip().lower() in ("nan", "inf", "-inf", "infinity")
                          for line in path.read_text().splitlines() for w in line.split(","))
                problem = "non-finite value in the written .csv" if bad else ""
            elif suffix == ".ply":
                problem = _check_ply(path.read_bytes())
            else:
                problem = ""
        except ValueError as err:
            problem = f"written {suffix}: {err}"
        if problem:
            return problem
    return ""


def _check_ply(data: bytes) -> str:
    import numpy as np
    end = data.find(b"end_header\n")
    if end < 0:
        return "written .ply has no end_header"
    header = data[:end].decode("ascii", "replace").splitlines()
    if "format binary_little_endian 1.0" not in header:
        return ""
    types = {"float": "<f4", "double": "<f8", "uchar": "u1", "char": "i1", "ushort": "<u2", "short": "<i2",
             "uint": "<u4", "int": "<i4", "float32": "<f4", "uint8": "u1", "int32": "<i4"}
    fields, count, first = [], 0, True
    for line in header:
        words = line.split()
        if words[:1] == ["element"]:
            if not first:
                break  # only the vertex element (the first) is checked
            first, count = False, int(words[2])
        elif words[:1] == ["property"] and words[1] != "list" and not first:
            fields.append((words[2], types.get(words[1], "<f4")))
    if not fields:
        return ""
    rows = np.frombuffer(data, np.dtype(fields), count, end + len(b"end_header\n"))
    for name, kind in fields:
        if kind.endswith(("f4", "f8")) and not np.isfinite(rows[name]).all():
            return f"non-finite {name} in the written .ply"
    return ""
