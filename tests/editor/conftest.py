"""An editor's server on loopback for the tests, and a client that speaks to it as the page does."""
from __future__ import annotations

import shutil
import threading
from pathlib import Path

import pytest

from fishgen.clouds.lighting import Lighting
from fishgen.editor.session import Session
from tests.clouds.cloud_tables import TABLES
from tests.editor.client import Answer, Client  # noqa: F401 - the editor tests take them from here

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def start_editor():
    """``start_editor(file, **session options)`` -> a Client of a served editor; stopped after the test."""
    servers = []

    def start(file: Path, **options) -> Client:
        server = Session(file, **options).server(0)
        threading.Thread(target=server.serve_forever, daemon=True).start()
        servers.append(server)
        return Client(server)

    yield start
    for server in servers:
        server.shutdown()
        server.server_close()


@pytest.fixture
def skies(tmp_path):
    """A folder with Table 4.3 and a texture cloud of two textures (in textures/ beside the folder)."""
    folder = tmp_path / "skies"
    folder.mkdir()
    shutil.copy(TABLES["4.3"], folder / "table_4_3.awn")
    shutil.copytree(ROOT / "textures" / "clouds", tmp_path / "textures" / "clouds",
                    ignore=shutil.ignore_patterns("*.py"))
    (folder / "two.awa").write_text("12\n2\n8, 4, 1, 2, 0, 0, 0, 2, clouds/billow.png\n"
                                    "4, 2, 1, 1, 5, 1, 0, 1.5, clouds/wisp.png\n")
    return folder


LIGHT = Lighting()
