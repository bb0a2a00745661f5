"""The client matrix as a session fixture: assets made once by the CLI, one browser for all cells.

At the end of the session the table is printed and written to out/client-matrix.md
(or $FISHGEN_CLIENT_MATRIX).
"""
from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from tests.clients.matrix import ROOT, Matrix, write_report

_STATE: dict = {}


@pytest.fixture(scope="package")  # closed before other packages' browser tests start their own playwright
def matrix(tmp_path_factory):
    start = time.perf_counter()
    m = Matrix(tmp_path_factory.mktemp("clients"))
    _STATE["matrix"], _STATE["start"] = m, start
    yield m
    m.close()


def pytest_terminal_summary(terminalreporter):
    m = _STATE.get("matrix")
    if m is None or not m.results:
        return
    seconds = time.perf_counter() - _STATE["start"]
    path = Path(os.environ.get("FISHGEN_CLIENT_MATRIX", ROOT / "out" / "client-matrix.md"))
    text = write_report(m.results, path, seconds)
    terminalreporter.write_sep("-", f"client matrix (also in {path})")
    terminalreporter.write_line(text.split("\n", 2)[2].rstrip())
