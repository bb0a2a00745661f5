"""The house holds: the package lints clean (ruff), its types check (mypy), and the core install
alone, without the test extra, runs every command (tools/core_smoke.sh). Run as tests so that they
share the suite's workers instead of running one after another before it."""
from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT


def _run(*command: str) -> subprocess.CompletedProcess:
    return subprocess.run(command, cwd=ROOT, capture_output=True, text=True)


def test_ruff_finds_nothing_in_the_package():
    done = _run(sys.executable, "-m", "ruff", "check", "fishgen")
    assert done.returncode == 0, done.stdout + done.stderr


def test_mypy_finds_no_type_error():
    done = _run(sys.executable, "-m", "mypy")
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.mark.slow
def test_the_core_install_runs_every_command():
    done = _run("bash", "tools/core_smoke.sh")
    assert done.returncode == 0 and "every command ran without a traceback" in done.stdout, \
        done.stdout + done.stderr
