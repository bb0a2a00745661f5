"""A local web server for fishgen's pages (`view`, `edit`, `fly`), safe to leave running.

- It binds 127.0.0.1 only, never another interface.
- It answers only requests addressed to ``127.0.0.1:PORT`` or ``localhost:PORT``: a web page
  elsewhere cannot reach it through a DNS name rebound to 127.0.0.1.
- Every request carries the random token of this run (``?token=`` in the URL, or the
  ``X-Fishgen-Token`` header that the pages' own requests send), compared in constant time: another
  local user's or another site's guess is refused.
- Request bodies are capped before they are read, at most MAX_IN_FLIGHT are taken at once (a
  busy server answers 503), and a client that sends nothing for TIMEOUT seconds, or has not sent
  its whole request in READ_DEADLINE, is cut off; pending connections queue behind QUEUE.
- It serves only the routes a command gives it: no folder, no directory listing, no file by name.
"""
from __future__ import annotations

import hmac
import json
import secrets
import socket
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any
from urllib.parse import parse_qs, unquote, urlsplit

HOST = "127.0.0.1"
MAX_BODY = 16 << 20
"""Largest request body any route takes (a cube file of 100,000 cubes is about 8 MB)."""
TIMEOUT = 10.0
"""Seconds a client may stay silent while sending its request: then it is cut off."""
MAX_IN_FLIGHT = 2
"""Request bodies parsed at once: a 16 MiB cube file takes 110-150 MB while it is read and checked,
and the threads a client can open are not otherwise bounded (QA pass 15: four saves at once took the
server from 175 to 626 MB)."""
QUEUE = 64
"""Connections the kernel holds for the server to accept (http.server's 5 made a burst of page
requests wait for SYN retries of a second each)."""
READ_DEADLINE = 60.0
"""Seconds a request may take to arrive whole: TIMEOUT bounds each read, so a client trickling a
byte every few seconds held a thread for ever."""


@dataclass(frozen=True)
class Request:
    method: str
    path: str
    query: dict[str, str]
    body: bytes

    def json(self) -> Any:
        """The body as JSON; a malformed body is a :class:`Refused` (400), never a traceback."""
        try:
            return json.loads(self.body.decode("utf-8"))
        except UnicodeDecodeError as err:
            raise Refused(HTTPStatus.BAD_REQUEST, "expected a JSON body, found bytes that are not UTF-8 "
                          f"at byte {err.start}") from None
        except json.JSONDecodeError as err:
            raise Refused(HTTPStatus.BAD_REQUEST, f"expected a JSON body, found invalid JSON at line "
                          f"{err.lineno} column {err.colno} ({err.msg})") from None
        except RecursionError:
            raise Refused(HTTPStatus.BAD_REQUEST,
                          "expected a JSON body, found JSON nested too deeply") from None
        except ValueError as err:  # Python's limit on an integer's digits: not a JSONDecodeError
            raise Refused(HTTPStatus.BAD_REQUEST, f"expected a JSON body, found {str(err)[:120]}") from None


@dataclass(frozen=True)
class Response:
    status: int = 200
    body: bytes = b""
    type: str = "application/octet-stream"

    @classmethod
    def of_json(cls, value: Any, status: int = 200) -> Response:
        return cls(status, json.dumps(value).encode("utf-8"), "application/json")

    @classmethod
    def of_html(cls, text: str) -> Response:
        return cls(200, text.encode("utf-8"), "text/html; charset=utf-8")


class Refused(Exception):
    """A request answered with an error status and a one-line reason (sent as JSON)."""

    def __init__(self, status: int, message: str):
        super().__init__(message)
        self.status = int(status)
        self.message = message


Route = Callable[[Request], Response]


POLL = 0.05
"""Seconds between a serving loop's looks for a shutdown: a wake-up at 20 Hz costs nothing measurable."""


class LocalServer(ThreadingHTTPServer):
    """Loopback, Host-checked, token-checked routes: ``{("GET", "/"): page, ("POST", "/api/save"): save}``."""

    daemon_threads = True
    request_queue_size = QUEUE

    def __init__(self, routes: Mapping[tuple[str, str], Route], port: int = 0, max_body: int = MAX_BODY,
                 token: str | None = None, timeout: float = TIMEOUT):
        self.routes = dict(routes)
        self.max_body = max_body
        self.timeout_seconds = timeout
        self.token = token or secrets.token_urlsafe(24)
        self.in_flight = threading.BoundedSemaphore(MAX_IN_FLIGHT)
        self.bugs: list[BaseException] = []   # errors answered with a 500, the last few (for a harness)
        self.read_deadline = READ_DEADLINE
        super().__init__((HOST, port), _Handler)

    def handle_error(self, request, client_address) -> None:  # a dropped client is not news
        pass

    def serve_forever(self, poll_interval: float = POLL) -> None:
        """Serve until :meth:`shutdown`, which returns within ``poll_interval`` (http.server's 0.5 s
        was how late a fly-through's report stopped its server, and each served test ended)."""
        super().serve_forever(poll_interval)

    @property
    def port(self) -> int:
        return int(self.server_address[1])

    def url(self, path: str = "/") -> str:
        """The address a user opens: the route and this run's token."""
        return f"http://{HOST}:{self.port}{path}?token={self.token}"

    def allowed_hosts(self) -> set[str]:
        hosts = {f"{HOST}:{self.port}", f"localhost:{self.port}"}
        # on port 80 a browser leaves the port out of Host (every request was refused)
        return hosts | {HOST, "localhost"} if self.port == 80 else hosts


class _Handler(BaseHTTPRequestHandler):
    server: LocalServer
    server_version = "fishgen"
    sys_version = ""

    def setup(self) -> None:
        super().setup()
        self.connection.settimeout(self.server.timeout_seconds)  # a slow sender is cut off
        # and a trickling one: past the deadline its reads end, and what it sent is refused as short
        self._deadline = threading.Timer(self.server.read_deadline, self._stop_reading)
        self._deadline.daemon = True
        self._deadline.start()

    def _stop_reading(self) -> None:
        try:
            self.connection.shutdown(socket.SHUT_RD)
        except OSError:   # already closed
            pass

    def finish(self) -> None:
        self._deadline.cancel()
        super().finish()

    def log_message(self, format, *args):  # one line per request would bury the URL
        pass

    def do_GET(self):
        self._answer("GET")

    def do_HEAD(self):
        self._answer("HEAD")

    def do_POST(self):
        self._answer("POST")

    def do_PUT(self):
        self._answer("PUT")

    def do_DELETE(self):
        self._answer("DELETE")

    def do_PATCH(self):     # answered by the same checks, not http.server's HTML 501 page
        self._answer("PATCH")

    def do_OPTIONS(self):
        self._answer("OPTIONS")

    def _answer(self, method: str) -> None:
        from fishgen.errors import FishgenError

        try:
            response = self._route(method)
        except Refused as refused:
            response = Response.of_json({"error": refused.message}, refused.status)
        except FishgenError as err:  # bad input from the page: its one line, as the CLI says it
            response = Response.of_json({"error": str(err), "line": err.line},
                                        HTTPStatus.UNPROCESSABLE_ENTITY)
        except TimeoutError:
            self.close_connection = True
            return
        except OSError as err:  # a name too long for the file system, say: answered, not dropped
            from fishgen.errors import too_long

            where = urlsplit(self.path).path[:100]       # not the query: it holds the token
            message = too_long(err) or f"cannot {method} {where}: {err.strerror or err}"
            response = Response.of_json({"error": message}, HTTPStatus.UNPROCESSABLE_ENTITY)
        except Exception as err:  # a bug: the page hears of it, and the server goes on
            self.server.bugs[:] = [*self.server.bugs[-15:], err]
            response = Response.of_json({"error": f"fishgen could not answer ({type(err).__name__})"},
                                        HTTPStatus.INTERNAL_SERVER_ERROR)
        self.send_response(response.status)
        self.send_header("Content-Type", response.type)
        self.send_header("Content-Length", str(len(response.body)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.send_header("Referrer-Policy", "no-referrer")
        self.send_header("Cross-Origin-Resource-Policy", "same-origin")
        self.end_headers()
        if method != "HEAD":
            self.wfile.write(response.body)

    def version_string(self) -> str:  # "fishgen", not "fishgen " + an empty Python version
        return self.server_version

    def _route(self, method: str) -> Response:
        hosts = self.headers.get_all("Host") or []
        host = hosts[0].strip().lower() if len(hosts) == 1 else ""   # two Host headers: a 400 in RFC 9112
        if host not in self.server.allowed_hosts():
            raise Refused(HTTPStatus.FORBIDDEN, "only 127.0.0.1 and localhost may ask")
        if not self.path.startswith("/"):   # absolute form (http://elsewhere/...) is for proxies
            raise Refused(HTTPStatus.BAD_REQUEST, "expected a path, found another form of address")
        parts = urlsplit(self.path)
        values = parse_qs(parts.query, keep_blank_values=True)
        if len(values.get("token", ())) > 1 or len(self.headers.get_all("X-Fishgen-Token") or []) > 1:
            raise Refused(HTTPStatus.FORBIDDEN, "expected this run's token once, found it given twice")
        query = {k: v[-1] for k, v in values.items()}
        given = self.headers.get("X-Fishgen-Token") or query.get("token") or ""
        if not hmac.compare_digest(given.encode("utf-8", "replace"), self.server.token.encode()):
            raise Refused(HTTPStatus.FORBIDDEN, "expected this run's token, found none or another")
        path = unquote(parts.path)  # routes are exact names: a decoded `..` matches none
        route = self.server.routes.get(("GET" if method == "HEAD" else method, path))
        if route is None:
            raise Refused(HTTPStatus.NOT_FOUND, f"no {method} {path[:100]}")
        if not self.headers.get("Content-Length"):
            return route(Request(method, path, query, self._body()))
        # a body is read and parsed by at most MAX_IN_FLIGHT requests at once
        if not self.server.in_flight.acquire(timeout=self.server.timeout_seconds):
            raise Refused(HTTPStatus.SERVICE_UNAVAILABLE, "expected fewer requests at once, found the "
                          "server busy; try again")
        try:
            return route(Request(method, path, query, self._body()))
        finally:
            self.server.in_flight.release()

    def _body(self) -> bytes:
        length = self.headers.get("Content-Length")
        if length is None:
            if self.headers.get("Transfer-Encoding"):
                raise Refused(HTTPStatus.LENGTH_REQUIRED, "expected a Content-Length, found a chunked body")
            return b""
        if not length.isdigit():
            raise Refused(HTTPStatus.BAD_REQUEST, f"expected a Content-Length, found {length[:20]!r}")
        size = int(length)
        if size > self.server.max_body:
            raise Refused(HTTPStatus.REQUEST_ENTITY_TOO_LARGE,
                          f"expected a body of at most {self.server.max_body:,} bytes, found {size:,}")
        body = self.rfile.read(size)
        self._deadline.cancel()
        if len(body) < size:
            raise Refused(HTTPStatus.BAD_REQUEST, f"expected a body of {size:,} bytes, found {len(body):,}")
        return body
