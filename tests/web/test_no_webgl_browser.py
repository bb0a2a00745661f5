"""Every page in a browser that gives it no WebGL context (WebGL off, or no GPU and no software
rasterizer): it says why in words, and the editor still edits and saves by its numbers. Before
(QA pass 22) the viewer and fly stayed on "loading…" and the editor was a dead panel."""
from __future__ import annotations

import shutil

import pytest

from fishgen.clouds.parser import load_cubes
from fishgen.viewer.page import write_page
from tests.browser import browser as shared_browser
from tests.browser import still_fly, unavailable
from tests.conftest import PARAMS, run_cli

pytestmark = pytest.mark.skipif(unavailable() is not None, reason=str(unavailable()))
#: Run before the page's scripts: a canvas gives no WebGL context, as with WebGL turned off.
NO_WEBGL = """HTMLCanvasElement.prototype.getContext = ((own) => function (kind, ...rest) {
    return /webgl/i.test(kind) ? null : own.call(this, kind, ...rest);
})(HTMLCanvasElement.prototype.getContext);"""
SAID = "this page draws with WebGL, and the browser gave it none"


def _page():
    page = shared_browser().new_page(viewport={"width": 800, "height": 600})
    page.add_init_script(NO_WEBGL)
    return page


def test_the_viewer_says_it_has_no_webgl(tmp_path):
    fish = tmp_path / "bonybream.glb"
    assert run_cli("build", PARAMS / "bonybream.txt", "-o", fish).returncode == 0
    page = _page()
    try:
        page.goto(write_page(fish, tmp_path / "fish.html").as_uri())
        page.wait_for_function("window.fishgenViewer && fishgenViewer.error", timeout=30_000)
        assert SAID in page.locator("#status").inner_text()
    finally:
        page.close()


def test_fly_says_it_has_no_webgl_and_its_driver_hears_it():
    with still_fly(PARAMS / "clouds" / "table_4_4.awn") as session:
        page = _page()
        try:
            page.goto(session.url())
            page.wait_for_function("window.fishgenFly && fishgenFly.error", timeout=30_000)
            assert SAID in page.locator("#hud").inner_text() and SAID in page.evaluate("fishgenFly.error")
        finally:
            page.close()


def test_the_editor_without_webgl_says_so_and_still_edits_and_saves_by_numbers(tmp_path):
    from tests.editor.browser import serve_editor, stop

    file = tmp_path / "t.awn"
    shutil.copy(PARAMS / "clouds" / "table_4_4.awn", file)
    proc, url = serve_editor(file)
    page = _page()
    try:
        page.goto(url)
        page.wait_for_function("window.fishgenEditor && fishgenEditor.ready", timeout=30_000)
        assert page.evaluate("fishgenEditor.cubes.length") == 23
        assert SAID in page.locator("#message").inner_text()
        page.get_by_label("Radius", exact=True).fill("1.5")
        page.get_by_role("button", name="Save", exact=True).click()
        page.wait_for_function("fishgenEditor.message.startsWith('saved')", timeout=30_000)
        assert SAID in page.locator("#message").inner_text()      # each message keeps saying it
        assert load_cubes(file).cubes[0].max_radius == 1.5
    finally:
        page.close()
        stop(proc)
