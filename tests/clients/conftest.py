"""The client matrix as a package fixture: assets made once by the CLI, one browser for all cells.

When its tests end, the table is written to out/client-matrix.md (or $FISHGEN_CLIENT_MATRIX) by the
worker that ran them; the session's summary prints it (tests/conftest.py).
"""
from __future__ import annotations

import time

import pytest

from tests.clients.matrix import Matrix, write_report
from tests.conftest import CLIENT_MATRIX


@pytest.fixture(scope="package")
def matrix(tmp_path_factory):
    start = time.perf_counter()
    m = Matrix(tmp_path_factory.mktemp("clients"))
    yield m
    m.close()
    if m.results:
        write_report(m.results, CLIENT_MATRIX, time.perf_counter() - start)
