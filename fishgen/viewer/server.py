"""Serve a viewer page's folder on loopback only, until interrupted."""
from __future__ import annotations

import functools
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

HOST = "127.0.0.1"  # never another interface: the folder may hold anything


class _QuietHandler(SimpleHTTPRequestHandler):
    def log_message(self, format, *args):  # one line per request would bury the URL
        pass


def make_server(folder: Path, port: int) -> ThreadingHTTPServer:
    """A server for ``folder`` on 127.0.0.1:``port`` (0 picks a free port)."""
    handler = functools.partial(_QuietHandler, directory=str(folder))
    return ThreadingHTTPServer((HOST, port), handler)


def url_of(server: ThreadingHTTPServer, page: Path) -> str:
    from urllib.parse import quote

    return f"http://{HOST}:{server.server_address[1]}/{quote(page.name)}"
