"""Serve one viewer page on loopback only, until interrupted.

The page is self-contained (three.js and the asset are inside it), so the server hands out that
one file and nothing else: not the folder it sits in (which may hold anything), no directory
listing, no symlink put in its place. It is a :class:`fishgen.web.server.LocalServer`: loopback only,
Host checked, and this run's token in the URL that every request must carry.
"""
from __future__ import annotations

import os
import stat
from http import HTTPStatus
from pathlib import Path
from urllib.parse import unquote

from fishgen.exchange.sidefiles import name_uri
from fishgen.viewer import MAX_EMBED_BYTES
from fishgen.web.server import LocalServer, Refused, Request, Response

MAX_PAGE_BYTES = 2 * MAX_EMBED_BYTES
"""Largest page served: an embedded asset grows by a third in base64, and three.js comes with it."""


def make_server(page: Path, port: int) -> LocalServer:
    """A server for the one file ``page`` on 127.0.0.1:``port`` (0 picks a free port), at ``/`` and at
    its own name; the page is read at each request, so a rewritten page is served as it is now."""
    page = Path(page).absolute()

    def serve(request: Request) -> Response:
        # not through a link put in the page's place, nor from a FIFO or device there: a regular
        # file of at most the largest page a viewer writes (QA pass 15 had a link serve a secret)
        try:
            fd = os.open(page, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
        except OSError:
            raise Refused(HTTPStatus.NOT_FOUND, "the page is gone") from None
        with os.fdopen(fd, "rb") as handle:
            info = os.fstat(handle.fileno())
            if not stat.S_ISREG(info.st_mode) or info.st_size > MAX_PAGE_BYTES:
                raise Refused(HTTPStatus.NOT_FOUND, "the page is gone")
            return Response.of_html(handle.read().decode("utf-8", errors="replace"))

    def no_icon(request: Request) -> Response:  # the page's icon is inline; a stray ask gets nothing
        return Response(HTTPStatus.NO_CONTENT)

    # the route is the name a browser asks for: its bytes, percent-decoded as UTF-8 text
    routes = {("GET", "/"): serve, ("GET", "/" + unquote(name_uri(page.name))): serve,
              ("GET", "/favicon.ico"): no_icon}
    return LocalServer(routes, port)


def url_of(server: LocalServer, page: Path) -> str:
    return server.url("/" + name_uri(Path(page).name))
