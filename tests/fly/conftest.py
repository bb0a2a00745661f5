"""Fly tests drive the system Chromium (apt-get install chromium) with Playwright (the test extra)."""
from __future__ import annotations

import pytest

from fishgen.fly.headless import find_chromium

CHROMIUM = find_chromium()
needs_chromium = pytest.mark.skipif(CHROMIUM is None,
                                    reason="chromium is not installed (apt-get install chromium)")


def page_report(**changes) -> dict:
    """A report as the page posts it (two seconds flown)."""
    report = {
        "window": {"width": 800, "height": 600}, "seconds": 2.0, "warmup": 2.0, "frames": 40,
        "fps": {"median": 20.0, "p5": 15.0, "min": 12.0, "max": 30.0},
        "scene": {"particles": 615, "billboards": 0, "distant_particles": 77, "distant_billboards": 0,
                  "clouds": 1, "meshes": 0},
        "drawn": {"particles": 615.0, "billboards": 0.0, "clouds": 1.0},
        "split": {"update": 0.5, "submit": 1.0, "wait": 40.0},
        "renderer": "ANGLE (Google, Vulkan 1.3.0 (SwiftShader Device (Subzero)), SwiftShader driver)",
        "path": "fly", "seed": 0, "sorts": 12,
        "impostors": {"on": True, "angle": 0.125, "budget": 8, "shown": 0.5, "redraws": 0.25,
                      "particles": 150.0, "error": 1.5, "redraw_share": 0.1, "textures": 1},
        "per_second": [{"second": 0, "frames": 21, "fps": 21.0, "particles": 615.0, "billboards": 0.0},
                       {"second": 1, "frames": 19, "fps": 19.0, "particles": 600.0, "billboards": 0.0}],
    }
    report.update(changes)
    return report
