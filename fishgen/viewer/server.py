"""Serve one viewer page on loopback only, until interrupted.

The page is self-contained (three.js and the asset are inside it), so the server hands out that
one file and nothing else: not the folder it sits in (which may hold anything), no directory
listing, no symlinks to follow. It is a :class:`fishgen.web.server.LocalServer`: loopback only,
Host checked, and this run's token in the URL that every request must carry.
"""
from __future__ import annotations

from http import HTTPStatus
from pathlib import Path
from urllib.parse import quote

from fishgen.web.server import LocalServer, Refused, Request, Response


def make_server(page: Path, port: int) -> LocalServer:
    """A server for the one file ``page`` on 127.0.0.1:``port`` (0 picks a free port), at ``/`` and at
    its own name; the page is read at each request, so a rewritten page is served as it is now."""
    page = Path(page).absolute()

    def serve(request: Request) -> Response:
        try:
            return Response.of_html(page.read_text(encoding="utf-8"))
        except OSError:
            raise Refused(HTTPStatus.NOT_FOUND, "the page is gone") from None

    def no_icon(request: Request) -> Response:  # the page's icon is inline; a stray ask gets nothing
        return Response(HTTPStatus.NO_CONTENT)

    routes = {("GET", "/"): serve, ("GET", "/" + page.name): serve, ("GET", "/favicon.ico"): no_icon}
    return LocalServer(routes, port)


def url_of(server: LocalServer, page: Path) -> str:
    return server.url("/" + quote(Path(page).name))
