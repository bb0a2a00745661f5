"""The JSON report of a batch (``--report``): per job its inputs and their hashes, options,
outputs and their hashes, seconds, status and error."""
from __future__ import annotations

import json
import os
from collections.abc import Sequence
from typing import Any

from fishgen import __version__
from fishgen.atomic import write_bytes
from fishgen.batch import STATUSES, Outcome
from fishgen.batch.manifest import Manifest
from fishgen.batch.record import canonical_options
from fishgen.errors import FishgenError


def report(manifest: Manifest, outcomes: Sequence[Outcome], seconds: float, workers: int,
           scheduler: str | None) -> dict[str, Any]:
    """The report as JSON values; paths are relative to the out folder, as in the record."""
    out = manifest.out
    counts = {status: sum(o.status == status for o in outcomes) for status in STATUSES}
    return {
        "fishgen": __version__,
        "manifest": os.fspath(manifest.file) if manifest.file is not None else None,
        "out": os.fspath(out),
        "workers": workers,
        "scheduler": scheduler,
        "seconds": round(seconds, 4),
        "counts": counts,
        "jobs": [{
            "name": o.job.name,
            "kind": o.job.kind,
            "where": o.job.where,
            "status": o.status,
            "reason": o.reason,
            "seconds": round(o.seconds, 4),
            "options": canonical_options(o.job.options, out),
            "inputs": o.inputs,
            "output": o.job.name,
            "output_sha256": o.outputs.get(o.job.name),
            "outputs": o.outputs,
            "error": _error(o.error),
            "notes": o.notes,
        } for o in outcomes],
    }


def _error(error: FishgenError | None) -> dict[str, Any] | None:
    if error is None:
        return None
    return {"message": str(error), "file": error.file, "line": error.line, "kind": error.kind}


def write_report(path: str | os.PathLike, doc: dict[str, Any]) -> None:
    write_bytes(path, (json.dumps(doc, indent=1) + "\n").encode("utf-8"))
