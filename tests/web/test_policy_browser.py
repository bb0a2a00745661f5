"""Every page's Content-Security-Policy in Chromium: the page runs whole under it (no violation
while it loads and draws), and it is in force (no script but its own runs)."""
from __future__ import annotations

import time

import pytest

from fishgen.viewer.page import write_page
from tests.browser import browser as shared_browser
from tests.browser import still_fly, unavailable
from tests.conftest import PARAMS, run_cli

pytestmark = pytest.mark.skipif(unavailable() is not None, reason=str(unavailable()))
LOAD_MS = 120_000
#: Run before the page's own scripts: every violation the policy reports.
RECORD = """window.violations = [];
document.addEventListener('securitypolicyviolation',
                          e => window.violations.push(`${e.violatedDirective} ${e.blockedURI}`));"""
#: A script put into the page, which the policy must refuse.
INJECT = """() => {
    const tag = document.createElement('script');
    tag.textContent = 'window.injected = true';
    document.body.append(tag);
    return window.injected === true;
}"""


def check(page, loaded: str) -> None:
    """Wait for ``loaded`` and two more frames; no violation so far, and a script put in is refused.
    Polled from here: Playwright's wait_for_function would poll with eval, which the policy forbids
    (an evaluate() from here is the debugger's, which the policy does not govern)."""
    deadline = time.monotonic() + LOAD_MS / 1000
    while not page.evaluate(loaded):
        assert time.monotonic() < deadline, f"not loaded: {loaded}"
        page.wait_for_timeout(25)
    page.evaluate("() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
    assert page.evaluate("window.violations") == []
    assert page.evaluate(INJECT) is False
    assert page.evaluate("window.violations") == ["script-src-elem inline"]


def new_page():
    page = shared_browser().new_page(viewport={"width": 640, "height": 480}, bypass_csp=False)
    page.add_init_script(RECORD)
    return page


def test_the_viewer_page_of_a_textured_fish_runs_under_its_policy_from_disk(tmp_path):
    fish = tmp_path / "bonybream.glb"
    assert run_cli("build", PARAMS / "bonybream.txt", "-o", fish).returncode == 0
    page = new_page()
    try:
        page.goto(write_page(fish, tmp_path / "fish.html").as_uri())
        check(page, "window.fishgenViewer && (fishgenViewer.loaded || fishgenViewer.error)")
        assert page.evaluate("fishgenViewer.error") is None
    finally:
        page.close()


def test_the_fly_page_runs_under_its_policy_when_served():
    with still_fly(PARAMS / "clouds" / "table_4_4.awn") as session:
        page = new_page()
        try:
            page.goto(session.url())
            check(page, "window.fishgenFly.loaded || window.fishgenFly.error")
            assert page.evaluate("window.fishgenFly.error") is None
        finally:
            page.close()


def test_the_editor_page_runs_under_its_policy_when_served():
    from tests.editor.browser import serve_editor, stop

    proc, url = serve_editor(PARAMS / "clouds" / "table_4_4.awn")
    page = new_page()
    try:
        page.goto(url)
        check(page, "window.fishgenEditor && (fishgenEditor.ready || fishgenEditor.error)")
        assert page.evaluate("fishgenEditor.error") is None
    finally:
        page.close()
        stop(proc)
