"""`fishgen fly`: Pakawan's fly-through (RekAwan user manual, chapter 4) as a local three.js page.

    assets, read = prepare_assets([Path("params/clouds/table_4_4.awn")])   # glb bytes to fly
    session = FlySession(assets, FlyConfig(size=(800, 600), timeout=10, headless=True))
    report = run_headless(session)        # Chromium drives the page along a seeded path

The page (``app.js``, bundled by tools/bundle_viewer.py; three.js comes from the page kit) draws
clouds back to front, culls whole clouds, switches distant ones to their lower level (MSFT_lod) and
does Harris's second pass; it measures each frame honestly (``docs/fly.md``) and posts its report to
the session.
"""
from __future__ import annotations

from fishgen.lazy import lazy_exports

_API = {
    "Asset": "fishgen.fly.assets", "prepare_assets": "fishgen.fly.assets",
    "FlyConfig": "fishgen.fly.session", "FlySession": "fishgen.fly.session",
    "run_headless": "fishgen.fly.headless", "find_chromium": "fishgen.fly.headless",
    "check_report": "fishgen.fly.report", "write_report": "fishgen.fly.report",
}
__getattr__, __all__ = lazy_exports(__name__, _API)
