"""A fly-through's server: the page and assets behind the run's token, the report checked on arrival."""
from __future__ import annotations

import http.client
import json

import pytest

from fishgen.fly.assets import Asset
from fishgen.fly.session import FlyConfig, FlySession
from tests.fly.conftest import page_report


@pytest.fixture
def session():
    got = []
    s = FlySession([Asset("a", b"glTF-bytes", "glb")], FlyConfig(timeout=3, report=True),
                   on_report=got.append)
    s.serve_in_background()
    s.got = got
    yield s
    s.close()


def ask(s, method, path, body=None, token=True):
    conn = http.client.HTTPConnection("127.0.0.1", s.server.port, timeout=5)
    headers = {"X-Fishgen-Token": s.server.token} if token else {}
    conn.request(method, path, body=body, headers=headers)
    response = conn.getresponse()
    return response.status, response.read()


def test_the_page_holds_the_app_and_the_settings(session):
    status, page = ask(session, "GET", "/")
    assert status == 200 and b'id="fishgen-fly"' in page and b"window.fishgenFly" in page
    settings = json.loads(page.split(b'id="fishgen-fly">')[1].split(b"</script>")[0])
    assert settings["assets"] == [{"name": "a", "url": "asset/0"}] and settings["timeout"] == 3
    assert settings["instancing"] is True   # a school drawn one instanced mesh per species and material
    assert session.url().startswith("http://127.0.0.1:") and f"token={session.server.token}" in session.url()


def test_assets_are_served_only_with_the_token(session):
    assert ask(session, "GET", "/asset/0") == (200, b"glTF-bytes")
    assert ask(session, "GET", "/asset/0", token=False)[0] == 403
    assert ask(session, "GET", "/asset/1")[0] == 404


def test_a_good_report_is_received_a_bad_one_refused(session):
    status, body = ask(session, "POST", "/report", json.dumps(page_report(frames=-3)).encode())
    assert status == 422 and b"expected frames" in body and not session.received.is_set()
    status, _ = ask(session, "POST", "/report", json.dumps(page_report()).encode())
    assert status == 200 and session.received.is_set() and session.report["frames"] == 40
    assert session.got == [session.report]


def test_mode_alone_needs_no_input_and_neither_is_one_line():
    """`fishgen fly --mode thick` (the README's first example) takes no INPUT; nothing at all is a
    usage error naming both."""
    from tests.conftest import run_cli

    none = run_cli("fly")
    assert none.returncode == 2 and "expected INPUT... (cube files, .awa, .glb) or --mode" in none.stderr
    assert "Missing argument" not in none.stderr
    from fishgen.commands import command

    assert command("fly").inputs.required is False


def test_no_instancing_reaches_the_page():
    from fishgen.commands.fly import FlyOptions, fly
    from tests.conftest import PARAMS

    made = fly([PARAMS / "clouds" / "table_4_3.awn"], None, FlyOptions(instancing=False))
    try:
        settings = json.loads(made.server.routes[("GET", "/")](None).body.split(b'id="fishgen-fly">')[1]
                              .split(b"</script>")[0])
        assert settings["instancing"] is False
    finally:
        made.server.server_close()
