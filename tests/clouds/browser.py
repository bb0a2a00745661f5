"""three.js in headless Chromium for the cloud tests: a loopback server for node_modules/three,
this folder's pages and an asset folder, and one Playwright page (the system Chromium)."""
from __future__ import annotations

import base64
import threading
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import numpy as np

from tests.browser import browser as shared_browser
from tests.browser import unavailable as no_browser

ROOT = Path(__file__).resolve().parents[2]
THREE = ROOT / "node_modules" / "three"
PAGES = Path(__file__).resolve().parent / "threejs"


def unavailable() -> str | None:
    """Why three.js cannot run here, or None."""
    if not (THREE / "build" / "three.module.js").is_file():
        return "three.js not installed (npm ci)"
    return no_browser()


class _Handler(SimpleHTTPRequestHandler):
    mounts: dict[str, Path] = {}
    extensions_map = {**SimpleHTTPRequestHandler.extensions_map, ".js": "text/javascript"}

    def translate_path(self, path: str) -> str:
        from urllib.parse import unquote

        path = unquote(path.split("?", 1)[0].split("#", 1)[0])
        for prefix, base in self.mounts.items():
            if path.startswith(prefix):
                target = (base / path[len(prefix):]).resolve()
                if target == base or base in target.parents:
                    return str(target)
        return "/nonexistent"

    def log_message(self, format, *args) -> None:  # noqa: A002 - quiet
        pass


class ThreePage:
    """``page(name)`` opens PAGES/name; ``url(path)`` serves a file of ``assets``."""

    def __init__(self, assets: Path):
        handler = type("Handler", (_Handler,), {"mounts": {"/three/": THREE.resolve(),
                                                           "/page/": PAGES.resolve(),
                                                           "/assets/": assets.resolve()}})
        self.assets = assets.resolve()
        self.server = ThreadingHTTPServer(("127.0.0.1", 0), partial(handler))
        self.base = f"http://127.0.0.1:{self.server.server_address[1]}"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()
        self.page = shared_browser().new_page()
        self.errors: list[str] = []
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))
        self.page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.page.route("**/*", lambda r: (r.continue_()
                                           if r.request.url.startswith((self.base, "blob:", "data:"))
                                           else r.abort()))
        self.page.goto(f"{self.base}/page/coverage.html")
        self.page.wait_for_function("window.coveragePageReady === true", timeout=30_000)

    def url(self, path: Path) -> str:
        return f"{self.base}/assets/{Path(path).resolve().relative_to(self.assets).as_posix()}"

    def coverage(self, billboards: Path, points: Path, sides, pixels: bool = False) -> dict:
        result = self.page.evaluate("([b, p, s, o]) => window.coverage(b, p, s, o)",
                                    [self.url(billboards), self.url(points), list(sides), {"pixels": pixels}])
        if "error" in result:
            raise AssertionError(f"three.js: {result['error']}")
        return result

    def close(self) -> None:
        try:
            self.page.close()
        finally:
            self.server.shutdown()
            self.server.server_close()


def image(result: dict, width: int = 400, height: int = 300) -> np.ndarray:
    """The RGBA pixels a coverage call returned (``pixels=True``), top row first."""
    raw = np.frombuffer(base64.b64decode(result["pixels"]), np.uint8)
    return raw.reshape(height, width, 4)[::-1]
