"""The house holds: the package, its tests and its scripts (benchmarks/, tools/) lint clean (ruff),
its types check (mypy), and the core install alone, without the test extra, runs every command
(tools/core_smoke.sh). Run as tests so that they share the suite's workers instead of running one
after another before it."""
from __future__ import annotations

import os
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


def test_the_suite_timeline_says_where_the_time_goes(tmp_path):
    """FISHGEN_SUITE_TIMELINE records each test's start and end on each worker, and
    tools/suite_timeline.py reports the workers' spans, the tail, the machine's idle share and the
    longest groups, modules and tests."""
    folder = tmp_path / "timeline"
    inherited = ("PYTEST_XDIST_WORKER", "FISHGEN_SUITE_TIMELINE_OWNER")
    env = {k: v for k, v in os.environ.items() if k not in inherited}
    env["FISHGEN_SUITE_TIMELINE"] = str(folder)
    for _ in range(2):      # a second run into the folder replaces the first's timeline
        done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-n", "2",
                               "tests/test_tomlfile.py"], cwd=ROOT, capture_output=True, text=True, env=env)
        assert done.returncode == 0, done.stdout + done.stderr
    assert sorted(p.name for p in folder.iterdir()) == ["gw0.jsonl", "gw1.jsonl"]
    said = _run(sys.executable, "tools/suite_timeline.py", str(folder), "--top", "3")
    assert said.returncode == 0, said.stderr
    lines = said.stdout.splitlines()
    counted = sum(int(line.split()[1]) for line in lines if line.startswith("gw"))
    assert counted == 5 and any(line.startswith("tail: ") for line in lines)
    assert any(line.startswith("machine idle over the run: ") for line in lines)
    assert lines[-4] == "longest tests:" and "tests/test_tomlfile.py::" in lines[-3]


def test_a_pytest_a_test_starts_records_nothing_in_the_suites_timeline(tmp_path):
    """A test that runs pytest again (the preview's softpipe run) inherits the variable: that run
    must not write into the folder, where it had truncated its worker's own file."""
    folder = tmp_path / "timeline"
    env = {k: v for k, v in os.environ.items() if k != "PYTEST_XDIST_WORKER"}
    env.update(FISHGEN_SUITE_TIMELINE=str(folder), FISHGEN_SUITE_TIMELINE_OWNER="1")  # not this run's
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist",
                           "tests/test_tomlfile.py"], cwd=ROOT, capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    assert not folder.exists()


def test_the_suite_timeline_report_counts_groups_and_the_tail():
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        from suite_timeline import Test, report
    finally:
        sys.path.remove(str(ROOT / "tools"))
    tests = [Test("gw0", "a.py::x@g", 0.0, 3.0), Test("gw0", "a.py::y@g", 3.0, 4.0),
             Test("gw1", "b.py::z", 0.0, 10.0)]
    text = report(tests, [[0, 0, 0, 50, 0], [60, 0, 20, 70, 10]], top=2)
    assert "gw0: 2 tests, 4.0 s in tests, last ended at 4.0 s" in text
    assert "tail: the last worker ended 6.0 s after the first" in text
    assert "machine idle over the run: 27.3 %" in text     # (20 idle + 10 iowait) / 110
    assert "     10.0 s  b.py::z\n      4.0 s  g\n" in text


def test_a_damaged_timeline_is_one_line_naming_its_file_and_line(tmp_path):
    for damage in ('\0\0{"event": "start"', '{"event": "start"}', '[1, 2]'):   # cut, no id, no event
        (tmp_path / "gw0.jsonl").write_text(f'{{"cpu": [1, 2]}}\n{damage}\n', encoding="utf-8")
        said = _run(sys.executable, "tools/suite_timeline.py", str(tmp_path))
        assert said.returncode == 2 and said.stdout == "", damage
        assert said.stderr.startswith(f"{tmp_path / 'gw0.jsonl'}:2: expected one JSON event a line, found ")
        assert said.stderr.count("\n") == 1


@pytest.fixture(scope="module")
def _shared_by_this_module():
    return object()


def test_tests_sharing_a_fixture_run_as_one_group_on_one_worker(request, _shared_by_this_module):
    """Under `--dist loadgroup` (tools/test.sh) a test that shares a fixture wider than a function
    carries its group in its id, which is how pytest-xdist keeps the group on one worker. pytest
    9.2 builds ids pytest-xdist 3.8 cannot add the group to: every group was split, its fixtures
    (a built asset, a browser, the fuzz run) made on both workers, and the suite took 487 s against
    384 (pyproject.toml keeps pytest under 9.2)."""
    if getattr(request.config, "workerinput", None) is None or not request.config.getvalue("loadgroup"):
        pytest.skip("only pytest-xdist's --dist loadgroup names groups")
    assert request.node.nodeid.endswith("@_shared_by_this_module@tests/test_house.py"), request.node.nodeid
