"""The local server every page of fishgen's uses: loopback, Host and token checked, bodies capped,
slow clients cut off, only the routes given."""
from __future__ import annotations

import http.client
import socket
import threading
import time

import pytest

from fishgen.errors import FishgenError
from fishgen.web.server import LocalServer, Request, Response


@pytest.fixture
def server():
    def echo(request: Request) -> Response:
        return Response.of_json({"got": request.json()})

    def bad(request: Request) -> Response:
        raise FishgenError("expected a cube, found none", "x.awn", 3)

    server = LocalServer({("GET", "/"): lambda r: Response.of_html("<p>hi</p>"), ("POST", "/echo"): echo,
                          ("POST", "/bad"): bad}, max_body=1000, timeout=1.0)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield server
    server.shutdown()
    server.server_close()


def ask(server, method="GET", path="/", body=None, host=None, token="", headers=None):
    conn = http.client.HTTPConnection("127.0.0.1", server.port, timeout=5)
    query = f"?token={token}" if token else ""
    conn.putrequest(method, path + query, skip_host=True)
    conn.putheader("Host", host or f"127.0.0.1:{server.port}")
    for k, v in (headers or {}).items():
        conn.putheader(k, v)
    if body is not None:
        conn.putheader("Content-Length", str(len(body)))
    conn.endheaders(body)
    response = conn.getresponse()
    return response.status, response.read()


def test_it_binds_loopback_only_and_its_url_carries_the_token(server):
    assert server.server_address[0] == "127.0.0.1"
    assert server.url("/") == f"http://127.0.0.1:{server.port}/?token={server.token}"
    assert len(server.token) >= 32 and LocalServer({}, 0).token != server.token


def test_the_right_token_and_host_get_the_page(server):
    assert ask(server, token=server.token) == (200, b"<p>hi</p>")
    assert ask(server, token=server.token, host=f"localhost:{server.port}")[0] == 200
    assert ask(server, headers={"X-Fishgen-Token": server.token})[0] == 200


@pytest.mark.parametrize("case", ["no token", "wrong token", "foreign host", "rebound name"])
def test_a_request_without_the_token_or_from_another_host_is_refused(server, case):
    wrong = server.token[:-1] + ("y" if server.token.endswith("x") else "x")   # 1 in 64 ended in x
    token = {"no token": "", "wrong token": wrong}.get(case, server.token)
    host = {"foreign host": "evil.example:80", "rebound name": f"evil.example:{server.port}"}.get(case)
    status, body = ask(server, token=token, host=host)
    assert status == 403 and b"<p>hi</p>" not in body


def test_a_request_that_says_its_host_or_token_twice_or_names_another_site_is_refused(server):
    """QA pass 12: a second Host header, a second token and an absolute-form address were read past
    (the first Host, the last token, the path of http://evil.example/...)."""
    good = f"127.0.0.1:{server.port}"
    assert ask(server, token=server.token, headers={"Host": good})[0] == 403
    assert ask(server, token=f"bad&token={server.token}")[0] == 403
    conn = http.client.HTTPConnection("127.0.0.1", server.port, timeout=5)
    conn.putrequest("GET", "/", skip_host=True)
    for header, value in (("Host", good), ("X-Fishgen-Token", "bad"), ("X-Fishgen-Token", server.token)):
        conn.putheader(header, value)
    conn.endheaders()
    assert conn.getresponse().status == 403
    conn = http.client.HTTPConnection("127.0.0.1", server.port, timeout=5)
    conn.putrequest("GET", f"http://evil.example/?token={server.token}", skip_host=True)
    conn.putheader("Host", good)
    conn.endheaders()
    response = conn.getresponse()
    assert response.status == 400 and b"<p>hi</p>" not in response.read()
    assert response.getheader("Server") == "fishgen"


def test_bodies_are_capped_before_they_are_read_and_must_be_json(server):
    assert ask(server, "POST", "/echo", b'{"a": 1}', token=server.token) == (200, b'{"got": {"a": 1}}')
    status, body = ask(server, "POST", "/echo", b"x" * 1001, token=server.token)
    assert status == 413 and b"at most 1,000 bytes" in body
    status, body = ask(server, "POST", "/echo", b"{not json", token=server.token)
    assert status == 400 and b"expected a JSON body, found invalid JSON at line 1 column 2" in body
    status, body = ask(server, "POST", "/echo", b'{"a": "\xff"}', token=server.token)
    assert status == 400 and b"found bytes that are not UTF-8 at byte 7" in body


def test_bad_input_from_the_page_is_one_line_with_its_place(server):
    status, body = ask(server, "POST", "/bad", b"{}", token=server.token)
    assert status == 422 and b"x.awn:3: expected a cube, found none" in body


def test_only_the_routes_given_are_served(server):
    for path in ("/../etc/passwd", "/index.html", "/api"):
        assert ask(server, path=path, token=server.token)[0] == 404


def test_a_slow_client_is_cut_off(server):
    with socket.create_connection(("127.0.0.1", server.port)) as sock:
        sock.sendall(f"POST /echo?token={server.token} HTTP/1.1\r\nHost: 127.0.0.1:{server.port}\r\n"
                     "Content-Length: 100\r\n\r\n{".encode())
        start = time.monotonic()
        sock.settimeout(10)
        assert sock.recv(100) == b""  # closed, not waiting for the other 99 bytes
        assert time.monotonic() - start < 5
    assert ask(server, token=server.token)[0] == 200  # and the server goes on


def test_a_client_trickling_its_request_is_cut_off_at_the_deadline(server):
    """Each read within the time-out, the request never whole: its reads end at the deadline."""
    server.read_deadline = 1.0
    request = f"GET /?token={server.token} HTTP/1.1\r\nHost: 127.0.0.1:{server.port}\r\nX-Slow: ".encode()
    with socket.create_connection(("127.0.0.1", server.port)) as sock:
        sock.settimeout(0.05)
        start = time.monotonic()
        answer = b""
        for byte in request + b"a" * 100:
            try:
                sock.sendall(bytes([byte]))
                answer += sock.recv(1000)
            except TimeoutError:
                continue
            except OSError:        # reset: the server has gone from this connection
                break
            if time.monotonic() - start > 8 or (answer and not answer.startswith(b"HTTP/1.0 200")):
                break
            time.sleep(0.25)       # within the 1 s time-out of each read
        took = time.monotonic() - start
    assert took < 4, f"still connected after {took:.1f} s"
    assert not answer.startswith(b"HTTP/1.0 200")
    assert ask(server, token=server.token)[0] == 200  # and the server goes on


def test_an_integer_past_pythons_digit_limit_is_a_400_not_a_dropped_connection(server):
    """Python's int-digit limit raises a plain ValueError, which the JSON check let through: the
    connection closed with no answer (QA pass 15)."""
    status, body = ask(server, "POST", "/echo", b'{"x": ' + b"9" * 900 + b"}", token=server.token)
    assert status == 200
    huge = LocalServer({("POST", "/echo"): lambda r: Response.of_json(r.json())}, max_body=10_000)
    thread = threading.Thread(target=huge.serve_forever, daemon=True)
    thread.start()
    try:
        status, body = ask(huge, "POST", "/echo", b'{"x": ' + b"9" * 5000 + b"}", token=huge.token)
        assert status == 400 and body.startswith(b'{"error": "expected a JSON body, found '), body
    finally:
        huge.shutdown()
        huge.server_close()


def test_a_route_that_fails_outside_fishgens_errors_is_answered_and_the_server_goes_on():
    def long_name(request: Request) -> Response:
        open("x" * 300)           # ENAMETOOLONG: an OSError no route turned into a FishgenError
        raise AssertionError

    def bug(request: Request) -> Response:
        raise KeyError("oops")

    server = LocalServer({("GET", "/long"): long_name, ("GET", "/bug"): bug,
                          ("GET", "/"): lambda r: Response()})
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        status, body = ask(server, path="/long", token=server.token)
        assert status == 422 and b"expected names of at most 255 bytes" in body, body
        assert ask(server, path="/bug", token=server.token) == (
            500, b'{"error": "fishgen could not answer (KeyError)"}')
        assert ask(server, token=server.token)[0] == 200
    finally:
        server.shutdown()
        server.server_close()


def test_options_and_patch_meet_the_same_checks(server):
    """They got http.server's HTML 501 page, before the Host check and without its headers."""
    for method in ("OPTIONS", "PATCH"):
        assert ask(server, method, host="evil.example:80", token=server.token)[0] == 403
        status, body = ask(server, method, token=server.token)
        assert status == 404 and body == f'{{"error": "no {method} /"}}'.encode()


def test_on_port_80_a_host_without_its_port_is_the_server_itself():
    """Browsers leave :80 out of Host, and every request to `--port 80` was refused (QA pass 15)."""
    server = LocalServer({}, 0)
    server.server_close()
    server.server_address = ("127.0.0.1", 80)
    assert {"127.0.0.1", "localhost", "127.0.0.1:80"} <= server.allowed_hosts()
    other = LocalServer({}, 0)
    other.server_close()
    assert "127.0.0.1" not in other.allowed_hosts()


def test_bodies_are_parsed_two_at_a_time_and_a_busy_server_says_so():
    """Four 7 MB saves at once took the server from 175 to 626 MB (QA pass 15): bodies beyond
    MAX_IN_FLIGHT wait, and past the time-out get a 503."""
    from fishgen.web.server import MAX_IN_FLIGHT

    inside, release = threading.Semaphore(0), threading.Event()

    def slow(request: Request) -> Response:
        inside.release()
        release.wait(10)
        return Response.of_json({"ok": True})

    server = LocalServer({("POST", "/slow"): slow}, timeout=0.5)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    results: list[int] = []
    try:
        workers = [threading.Thread(target=lambda: results.append(
            ask(server, "POST", "/slow", b"{}", token=server.token)[0])) for _ in range(MAX_IN_FLIGHT)]
        for worker in workers:
            worker.start()
        for _ in workers:
            assert inside.acquire(timeout=5)
        status, body = ask(server, "POST", "/slow", b"{}", token=server.token)
        assert status == 503 and b"server busy" in body
        release.set()
        for worker in workers:
            worker.join(10)
        assert results == [200] * MAX_IN_FLIGHT
    finally:
        release.set()
        server.shutdown()
        server.server_close()
