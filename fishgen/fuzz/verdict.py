"""How a fuzz case is judged: what it raised, and whether what it wrote is finite.

A case passes when the code under test either succeeds (and every output it wrote is finite) or
raises :class:`fishgen.errors.FishgenError`. Anything else is a *finding*, keyed by exception
type + innermost fishgen frame so that one bug found a thousand times is reported once.
"""
from __future__ import annotations

import json
import math
import struct
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any

FISHGEN_ROOT = Path(__file__).resolve().parents[1]


class CaseTimeout(BaseException):
    """Raised by the worker's timer; a BaseException so ``except Exception`` guards cannot hide it."""


@dataclass
class Outcome:
    status: str                 # "ok", "error" (a FishgenError / clean CLI error) or "finding"
    key: str = ""
    detail: str = ""            # a finding's traceback or input; an error's one-line message


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
                           formatted(inner))
        if isinstance(inner, RecursionError):
            return Outcome("finding", f"RecursionError at {innermost_fishgen_frame(inner.__traceback__)}",
                           formatted(inner))
    if isinstance(err, FishgenError):
        text = str(err)
        if "\n" in text.strip() or "Traceback" in text:
            return Outcome("finding", f"FishgenError with a multi-line message at "
                                      f"{innermost_fishgen_frame(err.__traceback__)}", text[:2000])
        return Outcome("error", detail=text)
    return Outcome("finding", f"{type(err).__name__} at {innermost_fishgen_frame(err.__traceback__)}",
                   formatted(err))


def formatted(err: BaseException) -> str:
    """The exception's traceback, its last 6,000 characters."""
    text = "".join(traceback.format_exception(type(err), err, err.__traceback__))
    return text[-6000:]

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
