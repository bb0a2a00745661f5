"""A client that speaks to an editor's server as its page does (token, Host), for the tests and the
benchmark."""
from __future__ import annotations

import http.client
import json
import struct
from dataclasses import dataclass


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
