"""The house holds: the package, its tests and its scripts (benchmarks/, tools/) lint clean (ruff),
its types check (mypy), and the core install alone, without the test extra, runs every command
(tools/core_smoke.sh). Run as tests so that they share the suite's workers instead of running one
after another before it."""
from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT


def _run(*command: str) -> subprocess.CompletedProcess:
    return subprocess.run(command, cwd=ROOT, capture_output=True, text=True)


def test_ruff_finds_nothing_in_the_package_its_tests_and_scripts():
    done = _run(sys.executable, "-m", "ruff", "check", "fishgen", "tests", "benchmarks", "tools")
    assert done.returncode == 0, done.stdout + done.stderr


def test_mypy_finds_no_type_error():
    done = _run(sys.executable, "-m", "mypy")
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.mark.slow
def test_the_core_install_runs_every_command():
    done = _run("bash", "tools/core_smoke.sh")
    assert done.returncode == 0 and "every command ran without a traceback" in done.stdout, \
        done.stdout + done.stderr


def test_benchmarks_and_tools_take_harness_code_not_tests():
    """Scripts outside the suite import the harness modules the tests use (a page driver, a
    photographer, the client matrix), never a test module or a conftest: those are the suite's own."""
    import ast

    found = []
    for folder in ("benchmarks", "tools", "docs"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                         else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
                found += [f"{path.relative_to(ROOT)}: {name}" for name in names
                          if name.startswith("tests.")
                          and name.rsplit(".", 1)[-1].startswith(("test_", "conftest"))]
    assert found == []
