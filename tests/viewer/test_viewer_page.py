"""The viewer page and server without a browser: what is embedded, where it is written, who may connect."""
from __future__ import annotations

import base64
import json
import re
import shutil
import subprocess
import sys

import pytest

from fishgen.errors import FishgenError
from fishgen.viewer.page import BUNDLE, STATIC, build_page, page_path
from tests.conftest import ROOT, run_cli


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
    bundle = BUNDLE.read_text(encoding="ascii")
    assert _module_scripts(html) == [bundle], "the page runs exactly the committed bundle"
    assert "GLTFLoader" in bundle or "KHR_materials_unlit" in bundle  # three's loader is inside it
    assert not re.search(r"<script[^>]+src=|importmap", html), "nothing may be loaded from outside the page"
    assert not re.search(r"(^|[;}\n])import\s*[\w{*\"'(]", bundle), "the bundle must import nothing"
    assert html.count("</script>") == html.count("<script"), "the bundle must not end its element early"


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


def test_a_bundle_that_would_end_its_script_element_is_refused(viewer_assets, tmp_path, monkeypatch):
    import fishgen.viewer.page as page

    bad = tmp_path / "viewer.min.js"
    bad.write_text('console.log("</script><script>alert(1)")')
    monkeypatch.setattr(page, "BUNDLE", bad)
    with pytest.raises(FishgenError, match="inside a <script> element"):
        build_page(viewer_assets["fish"])


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
    with pytest.raises(FishgenError, match="expected an asset ending in"):
        build_page(tmp_path / "fish.txt")


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
    for option in ("--port", "--no-serve", "--output", "--background"):
        assert option in text
    assert "default: 8765" in text


def _bundle_tool(*args):
    return subprocess.run([sys.executable, "tools/bundle_viewer.py", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True)


def test_committed_bundle_matches_its_manifest_and_app_js():
    # Needs no node: catches an app.js edited without rebuilding, or a hand-edited bundle.
    check = _bundle_tool("--check-hashes")
    assert check.returncode == 0, "stale bundle: run python tools/bundle_viewer.py\n" + check.stderr
    manifest = json.loads((STATIC / "manifest.json").read_text())
    assert manifest["entry"] == "fishgen/viewer/app.js" and manifest["entry"] in manifest["inputs"]
    assert sorted(p.name for p in STATIC.iterdir()) == ["THREE-LICENSE", "manifest.json", "viewer.min.js"]
    assert "MIT License" in (STATIC / "THREE-LICENSE").read_text()


def test_bundle_is_what_esbuild_rebuilds_from_the_npm_install():
    if not (ROOT / "node_modules" / "three").is_dir() or not (ROOT / "node_modules" / "esbuild").is_dir():
        pytest.fail("node_modules is missing three or esbuild: run `npm ci` (the README's test command does)")
    manifest = json.loads((STATIC / "manifest.json").read_text())
    package = json.loads((ROOT / "package.json").read_text())["devDependencies"]
    assert manifest["tools"] == {"esbuild": package["esbuild"], "three": package["three"]}
    check = _bundle_tool("--check")  # a byte-for-byte rebuild: also proves the build is deterministic
    assert check.returncode == 0, "stale bundle: run python tools/bundle_viewer.py\n" + check.stderr


def test_checks_notice_a_stale_bundle_or_app_js(tmp_path):
    static = tmp_path / "static"
    shutil.copytree(STATIC, static)
    with open(static / "viewer.min.js", "a") as f:
        f.write(";")
    assert _bundle_tool("--check-hashes", "--static", static).returncode == 1
    if (ROOT / "node_modules" / "esbuild").is_dir():
        assert _bundle_tool("--check", "--static", static).returncode == 1

    shutil.copy(STATIC / "viewer.min.js", static / "viewer.min.js")
    assert _bundle_tool("--check-hashes", "--static", static).returncode == 0
    manifest = json.loads((static / "manifest.json").read_text())
    manifest["inputs"]["fishgen/viewer/app.js"] = "0" * 64  # as if app.js had changed since the build
    (static / "manifest.json").write_text(json.dumps(manifest))
    result = _bundle_tool("--check-hashes", "--static", static)
    assert result.returncode == 1 and "fishgen/viewer/app.js changed" in result.stderr

    (static / "manifest.json").write_bytes((STATIC / "manifest.json").read_bytes())
    (static / "three.core.js").write_text("// left over from the unminified layout")
    result = _bundle_tool("--check-hashes", "--static", static)
    assert result.returncode == 1 and "three.core.js" in result.stderr
