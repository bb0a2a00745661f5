"""Fly headless: Chromium, driven by Playwright, opens the page and flies its seeded path.

The recipe that makes a frame's time measure drawing (docs/fly.md, "Measuring frames"):

* Chromium runs with vsync and the frame-rate limit off (``--disable-gpu-vsync``,
  ``--disable-frame-rate-limit``), and no background throttling, so requestAnimationFrame runs
  as fast as frames are drawn, not at the display's 60 Hz;
* the page reads one pixel back after each frame (``gl.readPixels``): the call returns only when
  the frame is drawn, so a frame's time is its drawing, not its queueing;
* the first ``warmup`` seconds are not counted (shaders compiled, buffers uploaded, first sorts);
* then frames are counted over a fixed wall time, and the report gives the median and the 5th
  percentile (and min, max) of the per-frame rate.

WebGL is software here (no GPU): SwiftShader (Chromium's own) or Mesa's llvmpipe through ANGLE's
OpenGL ES back end; the report names the one used (UNMASKED_RENDERER).
"""
from __future__ import annotations

import os
import shutil
import time
from pathlib import Path
from typing import Any

from fishgen.errors import FishgenError, MissingDependency, SystemFailure
from fishgen.fly.session import FlySession

COMMON = ["--headless=new", "--no-sandbox", "--disable-gpu-vsync", "--disable-frame-rate-limit",
          "--disable-background-timer-throttling", "--disable-renderer-backgrounding",
          "--disable-backgrounding-occluded-windows", "--no-first-run", "--disable-background-networking",
          "--disable-component-update", "--disable-sync", "--disable-quic", "--mute-audio"]
WEBGL = {
    "swiftshader": ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--disable-gpu"],
    "llvmpipe": ["--use-angle=gl-egl", "--use-gl=angle", "--ignore-gpu-blocklist"],
}
"""Software WebGL back ends: Chromium's SwiftShader (Vulkan), or Mesa's llvmpipe via ANGLE."""
LOAD_SECONDS = 180.0
"""Most seconds the page may take to load its assets (a thick sky on a busy machine: about 30)."""


def find_chromium() -> str | None:
    """A Chromium to drive: $FISHGEN_CHROMIUM, the system's, or None (then Playwright's own, if
    `playwright install chromium` put one there)."""
    for candidate in (os.environ.get("FISHGEN_CHROMIUM"), "/usr/bin/chromium", shutil.which("chromium"),
                      shutil.which("chromium-browser"), shutil.which("google-chrome")):
        if candidate and Path(candidate).is_file():
            return candidate
    return None


def check_headless() -> str | None:
    """Refuse now, in one line, if headless flying cannot work here; the Chromium to use."""
    from fishgen.extras import needs

    needs("playwright", "fly", "--headless")
    chromium = find_chromium()
    if chromium is None:
        try:
            from playwright._repo_version import version  # noqa: F401  (installed at all)
            from playwright.sync_api import sync_playwright

            with sync_playwright() as pw:
                own = pw.chromium.executable_path
        except Exception:  # noqa: BLE001 - any failure means no browser of its own
            own = None
        if not own or not Path(own).is_file():
            raise MissingDependency("--headless needs a Chromium, found none: install one with "
                                    "apt-get install chromium, or python -m playwright install chromium "
                                    "(or name it in FISHGEN_CHROMIUM)")
    return chromium


def run_headless(session: FlySession, *, webgl: str = "swiftshader", chromium: str | None = None,
                 extra_args: tuple[str, ...] = (),
                 screenshot: str | os.PathLike | None = None) -> dict[str, Any]:
    """Serve the session, fly its page in headless Chromium until it reports, and return the run's
    facts (the page's report is ``session.report``): the browser's version and its flags.
    ``screenshot``: a PNG of the page as it was when the time was up (the last frame)."""
    from playwright.sync_api import Error as PlaywrightError
    from playwright.sync_api import sync_playwright

    if webgl not in WEBGL:
        raise ValueError(f"webgl must be one of {sorted(WEBGL)}, not {webgl!r}")
    config = session.config
    if not config.timeout:
        raise ValueError("a headless flight needs a timeout")
    args = [*COMMON, *WEBGL[webgl], *extra_args]
    chromium = chromium or find_chromium()         # None: Playwright's own browser
    width, height = config.size or (800, 600)
    load_before = _load()
    session.serve_in_background()
    base = f"http://127.0.0.1:{session.server.port}/"
    errors: list[str] = []
    try:
        with sync_playwright() as pw:
            try:
                browser = pw.chromium.launch(executable_path=chromium, args=args)
            except PlaywrightError as err:
                raise SystemFailure(f"cannot start Chromium ({_first_line(err)})") from None
            try:
                page = browser.new_page(viewport={"width": width, "height": height})
                page.on("pageerror", lambda e: errors.append(str(e)))
                page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
                # nothing but the local server: the page never fetches anything else
                page.route("**/*", lambda r: r.continue_() if r.request.url.startswith(base) else r.abort())
                try:
                    page.goto(session.url())
                except PlaywrightError as err:     # e.g. a port Chromium never opens (6000, 10080)
                    # Chromium's reason, without the address (it holds the page's token)
                    found = _first_line(err).removeprefix("Page.goto: ").split(" at http", 1)[0]
                    raise SystemFailure(f"expected Chromium to open the page on port {session.server.port}, "
                                        f"found {found}; try another --port, or --port 0") from None
                allowed = LOAD_SECONDS + config.warmup + config.timeout * 3 + 30
                limit = time.monotonic() + allowed
                while not session.received.is_set():
                    if errors:
                        # a script error's first line: the stack under it names minified functions
                        found = _first_line(errors[0])
                        raise FishgenError(f"expected the page to fly, found an error: {found}")
                    if time.monotonic() > limit:
                        raise SystemFailure(f"the page did not report within {allowed:.0f} s")
                    page.wait_for_timeout(100)   # lets Playwright deliver the page's events; runs no script
                version = browser.version
                if screenshot is not None:
                    from fishgen.atomic import write_bytes

                    write_bytes(Path(screenshot), page.screenshot(type="png"))
            finally:
                browser.close()
    finally:
        session.close()
    return {"headless": True, "browser": f"Chromium {version}", "webgl": webgl, "flags": args,
            "cpus": os.cpu_count(), "load_average": [load_before, _load()]}


def _first_line(err: object) -> str:
    lines = str(err).strip().splitlines()
    return lines[0] if lines else type(err).__name__


def _load() -> float | None:
    """The system's 1-minute load average (None where there is none): how busy the CPUs that do the
    software rendering were, which the frame rate depends on."""
    try:
        return round(os.getloadavg()[0], 2)
    except (AttributeError, OSError):
        return None
