"""Fuzz cases that run the command line in-process: ``fishgen.cli.main(argv)`` must exit 0 (its
outputs finite) or exit 2 with one error line on stderr and no traceback; `fishgen fly` is
stopped where it would serve.
"""
from __future__ import annotations

import contextlib
import io
import os
import sys
from pathlib import Path
from typing import Any

from fishgen.fuzz.inputs import Case, fresh_folder, write_files
from fishgen.fuzz.verdict import Outcome, check_outputs


def run_cli(case: Case, workdir: Path) -> Outcome:
    """Run a CLI case's ``argv`` in its files' folder and judge its exit, stderr and outputs."""
    from fishgen.cli import main

    folder = fresh_folder(workdir)
    write_files(folder, case.files)
    old_cwd, old_out, old_err = os.getcwd(), sys.stdout, sys.stderr
    out, err = io.StringIO(), io.StringIO()
    code: Any = 0
    os.chdir(folder)
    sys.stdout, sys.stderr = out, err
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
        return Outcome("error", detail=lines[0])
    return Outcome("finding", f"cli {command}: exit status {code} ({_shape(lines[-1] if lines else '')})",
                   stderr[-3000:])


def _shape(line: str) -> str:
    """An error line with paths and numbers blanked, so one cause dedups to one finding."""
    import re
    line = re.sub(r"/[^\s:'\"]+", "PATH", line)
    return re.sub(r"\d+(\.\d+)?", "N", line)[:120]


class WouldServe(BaseException):
    """Raised where `fishgen fly` would start its server or a browser: the case ends there, passed
    (a BaseException so the CLI's guards let it through)."""


@contextlib.contextmanager
def no_serving(argv: list[str]) -> Any:
    """`fishgen fly` runs its validation and reads its inputs, but never binds a server, starts
    Chromium, or composes a --mode sky (minutes of work)."""
    if not argv or argv[0] != "fly":
        yield
        return
    import fishgen.commands.fly as fly_command
    import fishgen.fly.assets as fly_assets
    import fishgen.fly.headless as headless

    saved = (fly_command._session, headless.check_headless, fly_assets.prepare_assets)
    original = fly_assets.prepare_assets

    def stop(*_a, **_k):
        raise WouldServe

    def prepare(inputs, *, mode=None, **kw):
        if mode is not None:
            raise WouldServe
        return original(inputs, mode=mode, **kw)

    fly_command._session, headless.check_headless, fly_assets.prepare_assets = stop, stop, prepare
    try:
        yield
    finally:
        fly_command._session, headless.check_headless, fly_assets.prepare_assets = saved
