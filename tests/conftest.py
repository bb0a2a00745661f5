"""Shared test fixtures: the Khronos glTF-Validator and CLI runner helpers."""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import pytest

from tests.cli_runner import run_cli, run_cli_process  # noqa: F401 - the tests take them from here

ROOT = Path(__file__).resolve().parents[1]

# The Ctrl-C tests send SIGINT to the commands they start, and fishgen, as a well-behaved program,
# leaves SIGINT ignored where its parent ignored it. A suite started in the background by a script
# (`bash .ci/run &`) ignores it from the shell on, every command it starts did too, and those tests
# failed and left a `fishgen edit` serving (seen in a dry run started so). Ctrl-C is restored here.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
VALIDATOR_SCRIPT = ROOT / "tools" / "validate_gltf.mjs"
PARAMS = ROOT / "params"
#: Where the client matrix's table is written when its tests have run (tests/clients/conftest.py).
CLIENT_MATRIX = Path(os.environ.get("FISHGEN_CLIENT_MATRIX", ROOT / "out" / "client-matrix.md"))


def _validator_available() -> bool:
    return shutil.which("node") is not None and (ROOT / "node_modules" / "gltf-validator").is_dir()


def validate_gltf(*paths: Path) -> list[dict]:
    """Run the Khronos glTF-Validator on files; return one report per file."""
    if not _validator_available():
        pytest.fail("gltf-validator is not installed: run `npm ci` in the project root "
                    "(the README's test command does this)")
    out = subprocess.run(["node", str(VALIDATOR_SCRIPT), *map(str, paths)], cwd=ROOT,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def assert_valid_gltf(*paths: Path) -> None:
    """Zero errors and zero warnings from the Khronos validator, for each file."""
    for report in validate_gltf(*paths):
        bad = [m for m in report["messages"] if m["severity"] <= 1]
        assert report["numErrors"] == 0 and report["numWarnings"] == 0, (
            f"{report['file']}: {report['numErrors']} errors, {report['numWarnings']} warnings: "
            + json.dumps(bad[:10], indent=1))


def species_textured_as(folder: Path, colour: str, mask: str) -> dict[Path, bytes]:
    """The shipped bonybream in ``folder`` with its textures renamed ``colour`` and ``mask``: what
    each of its three files holds, to check that none was written over."""
    import shutil

    text = (PARAMS / "bonybream.txt").read_text()
    named = text.replace("bonybream.png bonybream_mask.png", f"{colour} {mask}")
    (folder / "bonybream.txt").write_text(named)
    shutil.copy(ROOT / "textures" / "bonybream.png", folder / colour)
    shutil.copy(ROOT / "textures" / "bonybream_mask.png", folder / mask)
    return {p: p.read_bytes() for p in (folder / "bonybream.txt", folder / colour, folder / mask)}


@pytest.fixture
def gltf_validator():
    """The validator as a fixture: ``gltf_validator(path, ...)`` asserts a clean report."""
    return assert_valid_gltf


@pytest.fixture
def cli():
    return run_cli


@pytest.fixture(scope="session")
def gl_available():
    """An OpenGL context from EGL (Mesa llvmpipe on CI), for the tests that render."""
    try:
        import moderngl

        moderngl.create_context(standalone=True, backend="egl").release()
    except Exception as err:  # noqa: BLE001 - any failure means no context
        pytest.fail(f"no headless OpenGL: install libegl1 libegl-mesa0 libgl1-mesa-dri ({err})")


_STARTED = pytest.StashKey[float]()
#: Session fixtures cheap enough that sharing them is no reason to keep their tests together.
_CHEAP_SHARED = {"gl_available", "tmp_path_factory", "worker_id", "testrun_uid"}
#: Modules whose long stretches go to the workers first, longest first (seconds on 2 busy cores): a
#: group or test that starts late ends the run alone while the other core idles (the core install,
#: 18-22 s, had started last). The rest follow in groups, most tests first, and single tests last,
#: which fill in the end. tools/test.sh passes --no-loadscope-reorder so pytest-xdist keeps this
#: order (it would sort by test count alone, and the README's one 55-s test came after every group).
_FIRST = ("tests/authoring/test_fit.py",          # the goldie fits' group, 77 s
          "tests/test_readme.py",                 # the README's examples in order, 55 s
          "tests/authoring/test_blender_photos.py", "tests/authoring/test_threejs_roundtrip.py",
          "tests/web/test_schools_browser.py",    # 34-37 s each
          "tests/test_house.py",                  # the core install, 18-22 s
          "tests/fuzz/test_fuzz.py")


@pytest.hookimpl(tryfirst=True)  # before pytest-xdist reads the groups
@pytest.hookimpl(tryfirst=True)   # before pytest-xdist's, which names each item's group from its marker
def pytest_collection_modifyitems(config, items):
    """Tests that share a fixture wider than a function (a built asset, a browser page, a server,
    the fuzz run) stay on one pytest-xdist worker, so it is made once, not once per worker: one
    `xdist_group` for each set of tests joined by such fixtures (``--dist loadgroup``); every other
    test is scheduled alone."""
    parent: dict[str, str] = {}

    def root(key: str) -> str:
        while parent.setdefault(key, key) != key:
            parent[key] = parent[parent[key]]
            key = parent[key]
        return key

    keys: dict[int, list[str]] = {}
    for item in items:
        defs = getattr(getattr(item, "_fixtureinfo", None), "name2fixturedefs", {})
        mine = []
        for name, fixturedefs in defs.items():
            scope = fixturedefs[-1].scope
            if scope == "function" or name in _CHEAP_SHARED:
                continue
            where = item.nodeid.split("::")[0] if scope in ("module", "class") else fixturedefs[-1].baseid
            mine.append(f"{name}@{where}")
        keys[id(item)] = mine
        for key in mine[1:]:
            parent[root(key)] = root(mine[0])
    for item in items:
        mine = keys[id(item)]
        if mine and not item.get_closest_marker("xdist_group"):
            item.add_marker(pytest.mark.xdist_group(root(mine[0])))
    group = {id(item): _group(item) for item in items}
    sizes = Counter(group.values())

    def order(item) -> tuple[int, int]:
        first = next((k for k, module in enumerate(_FIRST) if item.nodeid.startswith(module)), len(_FIRST))
        name = group[id(item)]
        return first, -(sizes[name] if name is not None else 1)

    items.sort(key=order)     # stable: tests keep their order within a group and among equals


def _group(item) -> str | None:
    """The item's pytest-xdist group, or None."""
    marker = item.get_closest_marker("xdist_group")
    return None if marker is None else str(marker.args[0] if marker.args else marker.kwargs.get("name", ""))


def pytest_sessionstart(session):
    session.config.stash[_STARTED] = time.time()
    global _TIMELINE
    if session.config.pluginmanager.has_plugin("dsession"):
        _TIMELINE = None    # pytest-xdist's controller hears every worker's tests too: they record


#: With FISHGEN_SUITE_TIMELINE=folder, each worker writes when each test starts and ends there, and
#: the machine's CPU counters at its first and last test (replacing an earlier run's file there):
#: `python tools/suite_timeline.py folder`.
_TIMELINE = os.environ.get("FISHGEN_SUITE_TIMELINE")
if _TIMELINE:
    # The run that was given the folder (or its pytest-xdist workers, its children) records; a
    # pytest some test starts inherits the variable and records nothing (it had truncated the
    # worker's own file).
    _OWNER = os.environ.setdefault("FISHGEN_SUITE_TIMELINE_OWNER", str(os.getpid()))
    if str(os.getppid() if os.environ.get("PYTEST_XDIST_WORKER") else os.getpid()) != _OWNER:
        _TIMELINE = None
_timeline: list = []


def _record(**event) -> None:
    if not _timeline:
        folder = Path(str(_TIMELINE))
        folder.mkdir(parents=True, exist_ok=True)
        _timeline.append(open(folder / f"{os.environ.get('PYTEST_XDIST_WORKER', 'main')}.jsonl", "w",
                              encoding="utf-8"))
        _record(cpu=_cpu_counters())
    _timeline[0].write(json.dumps(event) + "\n")
    _timeline[0].flush()


def _cpu_counters() -> list[int]:
    try:
        with open("/proc/stat", encoding="ascii") as stat:
            return [int(v) for v in stat.readline().split()[1:]]
    except OSError:
        return []


def pytest_runtest_logstart(nodeid, location):
    if _TIMELINE:
        _record(event="start", id=nodeid, t=time.time())


def pytest_runtest_logfinish(nodeid, location):
    if _TIMELINE:
        _record(event="end", id=nodeid, t=time.time())


def pytest_terminal_summary(terminalreporter, config):
    """The client matrix's table, when this session's tests (on whichever worker) wrote it."""
    started = config.stash.get(_STARTED, None)
    if started is None or not CLIENT_MATRIX.is_file() or CLIENT_MATRIX.stat().st_mtime < started:
        return
    terminalreporter.write_sep("-", f"client matrix (also in {CLIENT_MATRIX})")
    terminalreporter.write_line(CLIENT_MATRIX.read_text(encoding="utf-8").split("\n", 2)[2].rstrip())


def pytest_sessionfinish(session, exitstatus):
    if _timeline:
        _record(cpu=_cpu_counters())
        _timeline.pop().close()
    shared = sys.modules.get("tests.browser")
    if shared is not None:
        shared.close()
