"""Shared test fixtures: the Khronos glTF-Validator and CLI runner helpers."""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
VALIDATOR_SCRIPT = ROOT / "tools" / "validate_gltf.mjs"
PARAMS = ROOT / "params"


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


@pytest.fixture
def gltf_validator():
    """The validator as a fixture: ``gltf_validator(path, ...)`` asserts a clean report."""
    return assert_valid_gltf


def run_cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """Run the real `fishgen` command line in a subprocess (exit codes, stderr, no traceback)."""
    return subprocess.run([sys.executable, "-m", "fishgen", *map(str, args)], cwd=cwd or ROOT,
                          capture_output=True, text=True)


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
