"""fishgen's command line as the tests (and the harnesses the benchmarks share) run it: in this
process, or where the process is the point, in a subprocess."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def run_cli_process(*args: str, cwd: Path | None = None,
                    env: dict[str, str | None] | None = None) -> subprocess.CompletedProcess:
    """Run the real `fishgen` command line in a subprocess: for what only a process shows (the
    exit status the shell sees, signals, start-up imports, its environment: ``env`` sets a
    variable, or unsets it with None)."""
    environ = dict(os.environ)
    for key, value in (env or {}).items():
        if value is None:
            environ.pop(key, None)
        else:
            environ[key] = value
    return subprocess.run([sys.executable, "-m", "fishgen", *map(str, args)], cwd=cwd or ROOT,
                          capture_output=True, text=True, env=environ)


def run_cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """Run the `fishgen` command line in this process, as the console script does
    (:func:`fishgen.cli.main`): its exit status, stdout and stderr, and a traceback on stderr with
    status 1 where one would escape, so tests read it as they would a subprocess's. A process
    costs 0.3-1 s of imports per call; the exit-status and signal tests use :func:`run_cli_process`."""
    import io
    import logging
    import signal
    import traceback
    from contextlib import redirect_stderr, redirect_stdout

    from fishgen.cli import status_of

    argv = [str(a) for a in args]
    if "fly" in argv and "tests.browser" in sys.modules:
        sys.modules["tests.browser"].close()  # fishgen's own Playwright may run in this thread
    out, err = io.StringIO(), io.StringIO()
    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    logger = logging.getLogger("fishgen")
    log_handlers, log_level = list(logger.handlers), logger.level
    here = os.getcwd()
    try:
        os.chdir(cwd or ROOT)
        with redirect_stdout(out), redirect_stderr(err):
            try:
                status = status_of(argv)
            except Exception:  # what Python itself would print, had it escaped the console script
                traceback.print_exc()
                status = 1
    finally:
        os.chdir(here)
        for signum, handler in handlers.items():
            signal.signal(signum, handler)
        logger.handlers[:] = log_handlers  # --verbose's handler holds this call's stderr
        logger.setLevel(log_level)
    return subprocess.CompletedProcess(["fishgen", *argv], status, out.getvalue(), err.getvalue())
