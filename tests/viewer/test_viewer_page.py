"""The viewer page and server without a browser: what is embedded, where it is written, who may connect."""
from __future__ import annotations

import base64
import json
import re
import shutil

import pytest

from fishgen.errors import FishgenError
from fishgen.viewer.page import build_page, page_path
from fishgen.web.page import KIT, bundle
from tests.conftest import run_cli


def _payload(html: str) -> dict:
    m = re.search(r'<script type="application/json" id="fishgen-asset">(.*?)</script>', html, re.S)
    return json.loads(m.group(1))


def test_no_serve_writes_only_the_page_beside_the_asset(viewer_assets):
    result = run_cli("view", viewer_assets["fish"], "--no-serve")
    assert result.returncode == 0, result.stderr
    page = page_path(viewer_assets["fish"])
    assert page.name == "bream.glb.html" and page.is_file()
    assert "serving" not in result.stdout


def _module_scripts(html: str) -> list[str]:
    return re.findall(r'<script type="module">\n(.*?)\n</script>', html, re.S)


def test_page_inlines_the_viewer_bundle_and_embeds_the_asset(viewer_assets):
    html = build_page(viewer_assets["fish"])
    payload = _payload(html)
    assert payload["kind"] == "glb"
    assert base64.b64decode(payload["files"]["bream.glb"]) == viewer_assets["fish"].read_bytes()
    assert _module_scripts(html) == [bundle("viewer").read_text(encoding="ascii")], "the committed app"
    kit = KIT.read_text(encoding="ascii")
    assert f"<script>\n{kit}\n</script>" in html and "KHR_materials_unlit" in kit  # three's loader too
    assert not re.search(r"<script[^>]+src=|importmap", html), "nothing may be loaded from outside the page"
    assert html.count("</script>") == html.count("<script") == 3, "no bundle may end its element early"


def test_instancing_is_on_unless_the_page_is_written_without_it(viewer_assets, tmp_path):
    assert _payload(build_page(viewer_assets["fish"]))["instancing"] is True
    page = tmp_path / "nodes.html"
    made = run_cli("view", viewer_assets["fish"], "-o", page, "--no-serve", "--no-instancing")
    assert made.returncode == 0, made.stderr
    assert _payload(page.read_text(encoding="utf-8"))["instancing"] is False


def test_bonybream_page_is_under_1_mb(viewer_assets):
    # The bound; the page was 3.4 MB with unminified three.js modules in base64.
    size = len(build_page(viewer_assets["fish"]).encode("utf-8"))
    assert size < 1_000_000, f"BonyBream's page is {size:,} bytes"


def test_placeholders_in_a_file_name_are_not_expanded(viewer_assets, tmp_path):
    asset = tmp_path / "{{VIEWER}}{{ASSET}}.glb"
    shutil.copy(viewer_assets["fish"], asset)
    html = build_page(asset)
    assert _payload(html)["main"] == asset.name
    assert f"<title>{asset.name} · fishgen viewer</title>" in html
    assert len(_module_scripts(html)) == 1


def test_obj_page_carries_its_mtl_and_texture(viewer_assets):
    payload = _payload(build_page(viewer_assets["obj"]))
    assert payload["mtl"] == "bream.mtl"
    assert {"bream.obj", "bream.mtl", "bream_skin.png"} <= set(payload["files"])


def test_missing_side_file_is_a_one_line_error(viewer_assets, tmp_path):
    shutil.copy(viewer_assets["obj"], tmp_path / "lonely.obj")
    result = run_cli("view", tmp_path / "lonely.obj", "--no-serve")
    assert result.returncode == 2 and "bream.mtl" in result.stderr and "Traceback" not in result.stderr
    assert not (tmp_path / "lonely.obj.html").exists()


def test_unsupported_asset_is_refused(tmp_path):
    (tmp_path / "fish.txt").write_text("x")
    wrong = "expected an asset ending in .glb, .gltf, .obj, .ply, found '.txt'"
    with pytest.raises(FishgenError, match=wrong) as err:
        build_page(tmp_path / "fish.txt")
    assert err.value.file == str(tmp_path / "fish.txt")      # it was named by no file: `fishgen: expected …`


def test_server_listens_on_loopback_only(tmp_path):
    from fishgen.viewer.server import make_server

    page = tmp_path / "page.html"
    page.write_text("<!doctype html>")
    server = make_server(page, 0)
    try:
        assert server.server_address[0] == "127.0.0.1"
    finally:
        server.server_close()


def test_help_documents_options():
    text = " ".join(run_cli("view", "--help").stdout.split())
    for option in ("--port", "--no-serve", "--output", "--background", "--instancing / --no-instancing"):
        assert option in text
    assert "default: 8765" in text
    assert "to compare (the page's ?instancing=0 does too). [default: on]" in text


@pytest.mark.parametrize("page", ["x.xyz", "-", "x"])
def test_a_page_that_is_not_html_is_refused(tmp_path, viewer_assets, page):
    """`-o outv/x.xyz` and `-o -` (a file named -) were written, exit 0; every command refuses
    an output extension it does not write."""
    result = run_cli("view", viewer_assets["fish"], "-o", page, "--no-serve", cwd=tmp_path)
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert "expected a page ending in .html or .htm" in result.stderr and list(tmp_path.iterdir()) == []


def test_a_taken_port_leaves_no_page(tmp_path, viewer_assets):
    import socket

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        result = run_cli("view", viewer_assets["fish"], "-o", tmp_path / "p.html", "--port",
                         str(taken.getsockname()[1]))
    assert result.returncode == 1 and "port" in result.stderr and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("colour", ["transparent", "#ff000080"])
def test_a_see_through_background_is_refused_for_a_page(tmp_path, viewer_assets, colour):
    """`--background transparent` was taken and gave a black page: a page's background is opaque."""
    result = run_cli("view", "--no-serve", viewer_assets["fish"], "-o", tmp_path / "p.html",
                     "--background", colour)
    assert result.returncode == 2 and result.stderr.count("\n") == 1
    assert "expected an opaque colour (#8cadcc, white)" in result.stderr
    assert not (tmp_path / "p.html").exists()
