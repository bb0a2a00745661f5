"""One fly-through: its page and assets on the shared local server, and the report the page posts.

Routes (every request carries the run's token; fishgen.web.server checks it):

* ``GET /``: the page (fishgen/web/page.py: three.js and the app inlined, the run's settings as JSON);
* ``GET /asset/K``: the K-th asset's glb bytes;
* ``POST /report``: the page's report at its time-out, checked (a bad one is a 422), kept, written
  to the report file if one was asked for, and ``received`` is set.
"""
from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from fishgen.fly.assets import Asset
from fishgen.web.server import LocalServer, Request, Response, Route

MAX_REPORT_BYTES = 4 << 20
"""A day of per-second rows is about 8 MB of JSON; an hour fits well within this."""


@dataclass(frozen=True)
class FlyConfig:
    """How the page flies: the window size (None: the browser window's), seconds measured after
    ``warmup`` (None: fly until stopped), a seeded ``path`` ("fly": a loop through the sky; "orbit":
    round the scene, as chapter 5's test; "around": a seeded loop round the scene, 2.2 to 4 of its
    radii out, the view wandering over it; "still": where the keys start; None: Pakawan's keys and
    the mouse), ``cloud_scale``: the
    clouds are drawn into a buffer of this share of the window's width and height (1: on the window
    itself), ``baseline``: plain unsorted three.js Points instead (benchmarks/fly.py); ``instancing``:
    a school drawn one instanced mesh per species and material (fishgen/web/schools.js), else fish by
    fish; and the impostors (docs/fly.md): on or off, the redraw angle in degrees, the most particles
    redrawn a frame, and the distance in cloud radii within which clouds are drawn directly."""

    size: tuple[int, int] | None = (800, 600)
    timeout: float | None = None
    warmup: float = 2.0
    path: str | None = None
    seed: int = 0
    report: bool = False
    baseline: bool = False
    background: str = "#8cadcc"
    cloud_scale: float = 0.5
    instancing: bool = True
    impostors: bool = True
    impostor_angle: float = 0.125
    impostor_budget: int = 5_000
    impostor_near: float = 1.0

    def page_settings(self, assets: Sequence[Asset]) -> dict[str, Any]:
        from fishgen import __version__

        return {"assets": [{"name": a.name, "url": f"asset/{k}"} for k, a in enumerate(assets)],
                "size": list(self.size) if self.size else None, "timeout": self.timeout,
                "warmup": self.warmup, "path": self.path, "seed": self.seed % 2**32, "report": self.report,
                "baseline": self.baseline, "background": self.background, "cloudScale": self.cloud_scale,
                "instancing": self.instancing,
                "impostors": {"on": self.impostors and not self.baseline, "angle": self.impostor_angle,
                              "budget": self.impostor_budget, "near": self.impostor_near},
                "version": __version__}


def page_html(assets: Sequence[Asset], config: FlyConfig, title: str) -> str:
    """The page (fishgen/web/page.py) with the run's settings as JSON."""
    from fishgen.web import page

    return page.page_html("fly", title, ("fishgen-fly", config.page_settings(assets)))


class FlySession:
    """The server of one fly-through and what its page reported."""

    def __init__(self, assets: Sequence[Asset], config: FlyConfig, *, port: int = 0, title: str = "fly",
                 on_report: Callable[[dict[str, Any]], None] | None = None):
        from fishgen.fly.report import check_report

        self.assets = list(assets)
        self.config = config
        self.page = page_html(self.assets, config, title).encode("utf-8")
        self.report: dict[str, Any] | None = None
        self.received = threading.Event()
        self._check = check_report
        self._on_report = on_report
        routes: dict[tuple[str, str], Route] = {("GET", "/"): self._page, ("POST", "/report"): self._receive}
        for k in range(len(self.assets)):
            routes[("GET", f"/asset/{k}")] = self._asset(k)
        self.server = LocalServer(routes, port, max_body=MAX_REPORT_BYTES)

    def url(self) -> str:
        return self.server.url("/")

    def _page(self, request: Request) -> Response:
        return Response(200, self.page, "text/html; charset=utf-8")

    def _asset(self, k: int) -> Callable[[Request], Response]:
        return lambda request: Response(200, self.assets[k].data, "model/gltf-binary")

    def _receive(self, request: Request) -> Response:
        report = self._check(request.json())
        if self._on_report is not None:
            self._on_report(report)    # writes the file: a failure is the page's 422, the report kept out
        self.report = report
        self.received.set()
        return Response.of_json({"ok": True})

    def serve_in_background(self) -> threading.Thread:
        thread = threading.Thread(target=self.server.serve_forever, daemon=True, name="fishgen fly")
        thread.start()
        return thread

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()
