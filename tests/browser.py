"""The one headless Chromium every browser test drives: the system's, through Playwright, with
software WebGL (SwiftShader), started on first use and closed when the test
session (the pytest-xdist worker) ends.

Playwright's sync API allows one instance per thread, so a test that runs fishgen's own headless
flight in this process (:func:`fishgen.fly.headless.run_headless`) first :func:`close`\\ s the
shared one; the next test that asks for it starts it again.
"""
from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from fishgen.fly.headless import find_chromium

CHROMIUM = find_chromium()
#: No network services, no GPU: WebGL on SwiftShader. The frame rate stays limited (unlike
#: `fishgen fly --headless`, which measures it), so a page left animating does not take a core.
ARGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]

_open: dict[str, Any] = {}


def unavailable() -> str | None:
    """Why no page can be driven here, or None."""
    if CHROMIUM is None:
        return "chromium is not installed (Debian: apt-get install chromium)"
    try:
        import playwright  # noqa: F401
    except ImportError:
        return "playwright is not installed (the test extra)"
    return None


class _Browser:
    """The shared ``Browser``, whose new pages and contexts bypass the pages' Content-Security-Policy
    unless told ``bypass_csp=False``: Playwright's ``wait_for_function`` polls a string predicate
    with ``eval``, which the policy forbids. tests/web/test_policy_browser.py runs every page under
    its policy, and `fishgen fly --headless` flies under it."""

    def __init__(self, real: Any):
        self._real = real

    def new_page(self, **options: Any) -> Any:
        return self._real.new_page(**{"bypass_csp": True, **options})

    def new_context(self, **options: Any) -> Any:
        return self._real.new_context(**{"bypass_csp": True, **options})

    def __getattr__(self, name: str) -> Any:
        return getattr(self._real, name)


def browser() -> Any:
    """The shared Playwright ``Browser`` (started now if it is not running)."""
    if "browser" not in _open:
        from playwright.sync_api import sync_playwright

        playwright = sync_playwright().start()
        try:
            _open["browser"] = _Browser(playwright.chromium.launch(executable_path=CHROMIUM, args=ARGS))
        except Exception:
            playwright.stop()
            raise
        _open["playwright"] = playwright
    return _open["browser"]


def close() -> None:
    """Close the shared Chromium and its Playwright, if they run."""
    browser, playwright = _open.pop("browser", None), _open.pop("playwright", None)
    try:
        if browser is not None:
            browser.close()
    finally:
        if playwright is not None:
            playwright.stop()


def frames(page, count: int = 2) -> None:
    """Wait until the page has drawn ``count`` more animation frames: what a person sees after a
    change, without guessing a number of milliseconds."""
    page.evaluate("""(n) => new Promise(done => {
        const step = () => (--n <= 0 ? done() : requestAnimationFrame(step));
        requestAnimationFrame(step);
    })""", count)


@contextmanager
def still_fly(cube_file: Path, size: tuple[int, int] = (640, 480)) -> Iterator[Any]:
    """`fishgen fly`'s page of ``cube_file`` served, held still (no path): its session, closed after."""
    from fishgen.fly.assets import prepare_assets
    from fishgen.fly.session import FlyConfig, FlySession

    session = FlySession(prepare_assets([cube_file])[0], FlyConfig(size=size, warmup=0.1, path="still"))
    session.serve_in_background()
    try:
        yield session
    finally:
        session.close()
