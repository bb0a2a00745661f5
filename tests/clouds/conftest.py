"""Fixtures for the cloud tests: the report's three cube files and a writer for bad ones."""
from __future__ import annotations

from pathlib import Path

import pytest
from cloud_tables import TABLES


@pytest.fixture
def tables() -> dict[str, Path]:
    return dict(TABLES)


@pytest.fixture
def write_awn(tmp_path):
    """``write_awn(text_or_bytes, name="cubes.awn") -> Path``."""
    def write(content: str | bytes, name: str = "cubes.awn") -> Path:
        path = tmp_path / name
        path.write_bytes(content.encode() if isinstance(content, str) else content)
        return path
    return write
