"""Serve one viewer page on loopback only, until interrupted.

The page is self-contained (three.js and the asset are inside it), so the
server hands out that one file and nothing else: not the folder it sits in
(which may hold anything), no directory listing, no symlinks to follow. It
answers only requests addressed to 127.0.0.1:PORT or localhost:PORT, so a web
page elsewhere cannot reach it through a rebound DNS name.
"""
from __future__ import annotations

import os
import shutil
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from urllib.parse import quote, unquote, urlsplit

HOST = "127.0.0.1"  # never another interface


class PageServer(ThreadingHTTPServer):
    """A loopback HTTP server for exactly one page file."""

    daemon_threads = True

    def __init__(self, page: Path, port: int):
        self.page = Path(page).absolute()
        super().__init__((HOST, port), _PageHandler)

    @property
    def port(self) -> int:
        return self.server_address[1]

    def allowed_hosts(self) -> set[str]:
        return {f"{HOST}:{self.port}", f"localhost:{self.port}"}

    def paths(self) -> set[str]:
        """Request paths (decoded) that return the page."""
        return {"/", "/" + self.page.name}


class _PageHandler(BaseHTTPRequestHandler):
    server: PageServer
    server_version = "fishgen-view"
    sys_version = ""

    def log_message(self, format, *args):  # one line per request would bury the URL
        pass

    def do_HEAD(self):
        self._answer(body=False)

    def do_GET(self):
        self._answer(body=True)

    def _answer(self, body: bool) -> None:
        host = (self.headers.get("Host") or "").strip().lower()
        if host not in self.server.allowed_hosts():
            self.send_error(HTTPStatus.FORBIDDEN, "only 127.0.0.1 and localhost may ask")
            return
        path = unquote(urlsplit(self.path).path)
        if path == "/favicon.ico":  # the page names an empty inline icon; older browsers still ask
            self.send_response(HTTPStatus.NO_CONTENT)
            self._common_headers()
            self.end_headers()
            return
        if path not in self.server.paths():
            self.send_error(HTTPStatus.NOT_FOUND)
            return
        try:
            f = open(self.server.page, "rb")
        except OSError:
            self.send_error(HTTPStatus.NOT_FOUND)
            return
        with f:
            size = os.fstat(f.fileno()).st_size
            self.send_response(HTTPStatus.OK)
            self.send_header("Content-Type", "text/html; charset=utf-8")
            self.send_header("Content-Length", str(size))
            self._common_headers()
            self.end_headers()
            if body:
                shutil.copyfileobj(f, self.wfile)

    def _common_headers(self) -> None:
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.send_header("Referrer-Policy", "no-referrer")
        self.send_header("Cross-Origin-Resource-Policy", "same-origin")


def make_server(page: Path, port: int) -> PageServer:
    """A server for the one file ``page`` on 127.0.0.1:``port`` (0 picks a free port)."""
    return PageServer(page, port)


def url_of(server: ThreadingHTTPServer, page: Path) -> str:
    return f"http://{HOST}:{server.server_address[1]}/{quote(page.name)}"
