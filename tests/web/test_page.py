"""The one page kit: the shared bundle and each page's app (tools/bundle_viewer.py), and the one
assembly of the pages (fishgen/web/page.py)."""
from __future__ import annotations

import base64
import hashlib
import json
import re
import shutil
import subprocess
import sys

import pytest

from fishgen.errors import FishgenError
from fishgen.web import page
from fishgen.web.page import KIT, PAGES, STATIC, bundle, page_html
from tests.conftest import ROOT

BUDGET = 1 << 20
"""The issues' bound for a page's scripts: under 1 MB."""
_SCRIPTS = re.compile(r"<script([^>]*)>\n?(.*?)\n?</script>", re.S)


def _bundle_tool(*args):
    return subprocess.run([sys.executable, "tools/bundle_viewer.py", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True)


def _manifest() -> dict:
    return json.loads((STATIC / "manifest.json").read_text())


def test_one_kit_holds_three_and_every_app_takes_it_from_there():
    manifest = _manifest()
    assert sorted(p.name for p in STATIC.iterdir()) == sorted(
        ["THREE-LICENSE", "manifest.json", "kit.min.js", *(f"{p}.min.js" for p in PAGES)])
    bundles = manifest["bundles"]
    kit = bundles["kit"]["inputs"]
    for part in ("fishgen/web/kit.js", "fishgen/web/three-parts.js", "fishgen/web/cloudlight.js",
                 "fishgen/web/drawing.js", "node_modules/three/build/three.module.js",
                 "node_modules/three/examples/jsm/loaders/GLTFLoader.js",
                 "node_modules/three/examples/jsm/controls/TransformControls.js"):
        assert part in kit, part
    for name in PAGES:
        inputs = bundles[name]["inputs"]
        assert bundles[name]["entry"] == f"fishgen/{name}/app.js" in inputs
        assert not [f for f in inputs if f.startswith("node_modules/") or f.startswith("fishgen/web/")], \
            f"{name}'s app bundles what the kit holds"
        assert bundle(name).stat().st_size == bundles[name]["bytes"] < 64 << 10
    assert "fishgen/editor/cloudview.js" in bundles["editor"]["inputs"]
    assert KIT.stat().st_size == bundles["kit"]["bytes"] < BUDGET - (64 << 10)
    assert "MIT License" in (STATIC / "THREE-LICENSE").read_text()


def test_the_bundles_import_nothing():
    for path in (KIT, *(bundle(name) for name in PAGES)):
        text = path.read_text(encoding="ascii")
        assert not re.search(r"(^|[;}\n])import\s*[\w{*\"'(]", text), f"{path.name} imports something"
    assert KIT.read_text(encoding="ascii").startswith("var fishgenKit=")


@pytest.mark.parametrize("name", sorted(PAGES))
def test_every_page_is_the_shared_head_with_the_kit_then_its_app(name):
    html = page_html(name, "<b>&\"{{APP}}")
    assert html.startswith('<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">')
    assert f"<title>&lt;b&gt;&amp;&quot;{{{{APP}}}} · {PAGES[name]}</title>" in html
    scripts = _SCRIPTS.findall(html)
    assert [attrs for attrs, _ in scripts] == ["", ' type="module"'], "the kit, then the app; nothing else"
    assert scripts[0][1] == KIT.read_text(encoding="ascii")
    assert scripts[1][1] == bundle(name).read_text(encoding="ascii")
    assert not re.search(r"<script[^>]+src=|importmap|<link[^>]+href=\"(?!data:)", html), \
        "nothing may be loaded from outside the page"
    assert html.count("</script>") == html.count("<script") == 2
    policy = re.search(r'<meta http-equiv="Content-Security-Policy" content="([^"]*)">', html)[1]
    hashes = {f"'sha256-{base64.b64encode(hashlib.sha256(m[1].encode()).digest()).decode()}'"
              for m in re.finditer(r"<script[^>]*>(.*?)</script>", html, re.S)}
    directives = dict(d.strip().split(" ", 1) for d in policy.split(";"))
    assert set(directives["script-src"].split()) == hashes, "only the page's own two scripts may run"
    assert directives["default-src"] == "'none'" and "unsafe" not in directives["script-src"]
    own = (ROOT / "fishgen" / name / "template.html").read_text(encoding="utf-8")
    assert "<head" not in own and "<title" not in own and "<script" not in own, "the head is shared"
    assert own.split("</style>")[1].strip().removesuffix("</body>").rstrip() in html


def test_data_is_json_that_cannot_end_its_element():
    html = page_html("fly", "t", ("fishgen-fly", {"name": "</script><script>alert(1)"}))
    m = re.search(r'<script type="application/json" id="fishgen-fly">(.*?)</script>', html, re.S)
    assert json.loads(m[1]) == {"name": "</script><script>alert(1)"}
    assert html.count("<script") == 3


def test_a_bundle_that_would_end_its_script_element_is_refused(tmp_path, monkeypatch):
    bad = tmp_path / "kit.min.js"
    bad.write_text('console.log("</script><script>alert(1)")')
    monkeypatch.setattr(page, "KIT", bad)
    with pytest.raises(FishgenError, match="inside a <script> element"):
        page_html("viewer", "x")


def test_committed_bundles_match_their_manifest_and_sources():
    # Needs no node: catches an app.js edited without rebuilding, or a hand-edited bundle.
    check = _bundle_tool("--check-hashes")
    assert check.returncode == 0, "stale bundle: run python tools/bundle_viewer.py\n" + check.stderr


def test_bundles_are_what_esbuild_rebuilds_from_the_npm_install():
    if not (ROOT / "node_modules" / "three").is_dir() or not (ROOT / "node_modules" / "esbuild").is_dir():
        pytest.fail("node_modules is missing three or esbuild: run `npm ci` (the README's test command does)")
    package = json.loads((ROOT / "package.json").read_text())["devDependencies"]
    assert _manifest()["tools"] == {"esbuild": package["esbuild"], "three": package["three"]}
    check = _bundle_tool("--check")  # a byte-for-byte rebuild: also proves the build is deterministic
    assert check.returncode == 0, "stale bundle: run python tools/bundle_viewer.py\n" + check.stderr


def test_checks_notice_a_stale_bundle_or_source(tmp_path):
    static = tmp_path / "static"
    shutil.copytree(STATIC, static)
    with open(static / "fly.min.js", "a") as f:
        f.write(";")
    assert _bundle_tool("--check-hashes", "--static", static).returncode == 1
    if (ROOT / "node_modules" / "esbuild").is_dir():
        assert _bundle_tool("--check", "--static", static).returncode == 1

    shutil.copy(STATIC / "fly.min.js", static / "fly.min.js")
    assert _bundle_tool("--check-hashes", "--static", static).returncode == 0
    manifest = json.loads((static / "manifest.json").read_text())
    manifest["bundles"]["viewer"]["inputs"]["fishgen/viewer/app.js"] = "0" * 64  # as if app.js had changed
    (static / "manifest.json").write_text(json.dumps(manifest))
    result = _bundle_tool("--check-hashes", "--static", static)
    assert result.returncode == 1 and "fishgen/viewer/app.js changed" in result.stderr

    (static / "manifest.json").write_bytes((STATIC / "manifest.json").read_bytes())
    (static / "viewer.min.js").rename(static / "three.core.js")  # a file of another layout, one missing
    result = _bundle_tool("--check-hashes", "--static", static)
    assert result.returncode == 1 and "three.core.js" in result.stderr
    assert "viewer.min.js differs" in result.stderr


def test_the_bundler_refuses_an_app_that_would_bundle_three_or_miss_a_name(tmp_path, monkeypatch):
    tool = _load_tool()
    monkeypatch.setattr(tool, "ROOT", tmp_path)
    web = tmp_path / "fishgen" / "web"
    web.mkdir(parents=True)
    (web / "three-parts.js").write_text("export {\n\tColor, Scene,\n} from 'three';\n")
    (tmp_path / "app.js").write_text("const a = new THREE.Color(), s = new THREE.Scene();\n")
    (tmp_path / "bad.js").write_text("const m = new THREE.Mesh();\n")
    tool._check_apps({"kit": [], "viewer": ["app.js"]})
    with pytest.raises(SystemExit, match="THREE.Mesh: add to fishgen/web/three-parts.js"):
        tool._check_apps({"kit": [], "viewer": ["app.js", "bad.js"]})
    with pytest.raises(SystemExit, match="imports node_modules/three/build/three.module.js"):
        tool._check_apps({"kit": [], "fly": ["app.js", "node_modules/three/build/three.module.js"]})


def _load_tool():
    import importlib.util

    spec = importlib.util.spec_from_file_location("bundle_viewer", ROOT / "tools" / "bundle_viewer.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
