"""The editor's page: one HTML document, its bundle committed with a manifest, under 1 MB."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from fishgen.editor.page import BUNDLE, STATIC, build_page
from tests.conftest import ROOT

BUDGET = 1 << 20
"""The issue: keep the editor's bundle under 1 MB."""


def test_the_bundle_is_committed_with_its_manifest_and_stays_under_1_mb():
    manifest = json.loads((STATIC / "manifest.json").read_text())
    assert manifest["entry"] == "fishgen/editor/app.js" and manifest["bundle"]["file"] == BUNDLE.name
    assert sorted(p.name for p in STATIC.iterdir()) == ["THREE-LICENSE", "editor.min.js", "manifest.json"]
    inputs = manifest["inputs"]
    for part in ("fishgen/editor/app.js", "fishgen/editor/cloudview.js",
                 "node_modules/three/examples/jsm/controls/TransformControls.js",
                 "node_modules/three/examples/jsm/controls/OrbitControls.js",
                 "node_modules/three/examples/jsm/loaders/GLTFLoader.js"):
        assert part in inputs, part
    assert BUNDLE.stat().st_size == manifest["bundle"]["bytes"] < BUDGET


def test_the_bundle_is_what_esbuild_rebuilds():
    if not (ROOT / "node_modules" / "esbuild").is_dir():
        pytest.fail("node_modules is missing esbuild: run `npm ci` (the README's test command does)")
    check = subprocess.run([sys.executable, "tools/bundle_viewer.py", "--check", "--page", "editor"],
                           cwd=ROOT, capture_output=True, text=True)
    assert check.returncode == 0, "stale: run python tools/bundle_viewer.py --page editor\n" + check.stderr


def test_the_page_inlines_the_bundle_and_escapes_the_file_name():
    page = build_page("<b>&.awn")
    assert "<title>&lt;b&gt;&amp;.awn · fishgen edit</title>" in page
    assert BUNDLE.read_text(encoding="ascii") in page
    assert page.count("<script") == 1 and "src=" not in page.split("<script", 1)[1][:40]
