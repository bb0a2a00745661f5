"""An editor's server on loopback for the tests, and a client that speaks to it as the page does."""
from __future__ import annotations

import http.client
import json
import shutil
import struct
import threading
from dataclasses import dataclass
from pathlib import Path

import pytest

from fishgen.clouds.lighting import Lighting
from fishgen.editor.session import Session
from tests.clouds.cloud_tables import TABLES

ROOT = Path(__file__).resolve().parents[2]


@dataclass
class Answer:
    status: int
    body: bytes

    def json(self):
        return json.loads(self.body)

    def fill(self) -> tuple[dict, bytes]:
        """The fill route's facts and GLB."""
        (length,) = struct.unpack_from("<I", self.body)
        return json.loads(self.body[4:4 + length]), self.body[4 + length:]


class Client:
    def __init__(self, server):
        self.server = server

    def ask(self, method: str, path: str, body: bytes | None = None, *, token: str | None = None,
            host: str | None = None, length: int | None = None) -> Answer:
        conn = http.client.HTTPConnection("127.0.0.1", self.server.port, timeout=60)
        conn.putrequest(method, path, skip_host=True)
        conn.putheader("Host", host or f"127.0.0.1:{self.server.port}")
        conn.putheader("X-Fishgen-Token", self.server.token if token is None else token)
        if body is not None or length is not None:
            conn.putheader("Content-Length", str(len(body or b"") if length is None else length))
        conn.endheaders(body)
        response = conn.getresponse()
        return Answer(response.status, response.read())

    def get(self, path: str, **kw) -> Answer:
        return self.ask("GET", path, **kw)

    def post(self, path: str, value, **kw) -> Answer:
        return self.ask("POST", path, json.dumps(value).encode(), **kw)


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
