"""A private copy of the shipped params and textures per test, so tests may edit and touch inputs."""
from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import pytest

from tests.conftest import ROOT, run_cli


@pytest.fixture
def shipped(tmp_path) -> Path:
    """tmp/params (species, cube files, reef.toml, assets.toml) and tmp/textures, as shipped."""
    shutil.copytree(ROOT / "params", tmp_path / "params")
    shutil.copytree(ROOT / "textures", tmp_path / "textures", ignore=shutil.ignore_patterns("*.py"))
    return tmp_path


def batch(*args, cwd: Path | None = None):
    return run_cli("batch", *args, cwd=cwd)


def hashes(folder: Path) -> dict[str, str]:
    """sha256 of every asset under ``folder`` (not the record or lock), by relative path."""
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and not p.name.startswith(".")}


def record(folder: Path) -> dict:
    return json.loads((folder / ".fishgen-batch.json").read_text())["jobs"]


def statuses(stdout: str) -> dict[str, str]:
    """The one line per job of a non-TTY run: `STATUS NAME ...` -> {name: status}."""
    found = {}
    for line in stdout.splitlines():
        parts = line.split()
        if parts and parts[0] in ("built", "skipped"):
            found[parts[1]] = parts[0]
    return found
