"""A school in the browser: one instanced mesh per species and material against a node per fish.

    python benchmarks/school_draw.py                   # 100 and 1,000 fish, 3 rounds (about 4 minutes)
    python benchmarks/school_draw.py --path fly        # fly's own loop through the school, fish culled
    python benchmarks/school_draw.py --counts 1000 --repeat 1 --seconds 4     # a quick look

Issue 34, item 3: `fishgen view` and `fishgen fly` draw a `fishgen school` of one species as one
InstancedMesh per material (fishgen/web/schools.js), so 1,000 fish are 1-2 draw calls instead of
one per fish and part. Each school is BonyBream, `fishgen school --count N --frames 300 --seed 0`
(default mask fins: body and fins, two materials), flown in `fishgen fly`'s page in headless
Chromium on software WebGL (SwiftShader by default), the camera turning round the school at a
distance where it fills the view (the orbit path of benchmarks/fly.py), measured as `fishgen fly
--headless` measures (docs/fly.md): a 2 s warm-up, then FPS over a fixed wall time. The two ways
are taken in turn within each round, so both see the same machine; the table gives the medians
over the rounds and their ratio, and the draw calls of one frame (three.js's
renderer.info.render.calls, read from the same page).
"""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fishgen.fly.assets import Asset  # noqa: E402
from fishgen.fly.headless import COMMON, WEBGL, find_chromium, run_headless  # noqa: E402
from fishgen.fly.session import FlyConfig, FlySession  # noqa: E402

WAYS = {"instanced": True, "node per fish": False}


def school_asset(count: int, frames: int, folder: Path) -> Asset:
    """`fishgen school` of BonyBream, as the CLI writes it."""
    out = folder / f"school{count}.glb"
    subprocess.run([sys.executable, "-m", "fishgen", "school", str(ROOT / "params" / "bonybream.txt"),
                    "--count", str(count), "--frames", str(frames), "--seed", "0", "-o", str(out), "-q"],
                   cwd=ROOT, check=True)
    return Asset(f"{count} BonyBream", out.read_bytes(), "glb")


def fps(asset: Asset, instancing: bool, seconds: float, webgl: str, size: tuple[int, int], path: str) -> dict:
    config = FlyConfig(size=size, timeout=seconds, warmup=2.0, path=path, report=True, instancing=instancing)
    session = FlySession([asset], config, title=asset.name)
    run_headless(session, webgl=webgl)
    assert session.report is not None
    return session.report


def draw_calls(asset: Asset, instancing: bool, webgl: str, size: tuple[int, int]) -> int:
    """One frame's draw calls of the school (fly's meshes, without its clouds' passes)."""
    from playwright.sync_api import sync_playwright

    session = FlySession([asset], FlyConfig(size=size, path="still", instancing=instancing), title=asset.name)
    session.serve_in_background()
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=find_chromium(), args=[*COMMON, *WEBGL[webgl]])
            try:
                page = browser.new_page(viewport={"width": size[0], "height": size[1]},
                                        bypass_csp=True)  # wait_for_function polls with eval
                page.goto(session.url())
                page.wait_for_function("window.fishgenFly.loaded || window.fishgenFly.error",
                                       timeout=180_000)
                error = page.evaluate("window.fishgenFly.error")
                if error:
                    raise SystemExit(f"the page failed: {error}")
                return int(page.evaluate("window.fishgenFly.meshCalls()"))
            finally:
                browser.close()
    finally:
        session.close()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--counts", default="100,1000", help="fish per school [default: %(default)s]")
    parser.add_argument("--frames", type=int, default=300, help="frames baked [default: %(default)s]")
    parser.add_argument("--repeat", type=int, default=3, help="rounds, both ways each [default: %(default)s]")
    parser.add_argument("--seconds", type=float, default=6.0,
                        help="seconds measured a run [default: %(default)s]")
    parser.add_argument("--path", choices=("orbit", "fly"), default="orbit",
                        help="orbit: the school held in view; fly: fly's seeded loop through it, fish out "
                             "of view culled [default: %(default)s]")
    parser.add_argument("--webgl", choices=sorted(WEBGL), default="swiftshader")
    parser.add_argument("--json", type=Path, help="also write the rows here")
    args = parser.parse_args()
    size = (800, 600)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for count in (int(c) for c in args.counts.split(",")):
            asset = school_asset(count, args.frames, Path(tmp))
            calls = {way: draw_calls(asset, on, args.webgl, size) for way, on in WAYS.items()}
            runs: dict[str, list[float]] = {way: [] for way in WAYS}
            for _ in range(args.repeat):
                for way, on in WAYS.items():
                    report = fps(asset, on, args.seconds, args.webgl, size, args.path)
                    runs[way].append(report["fps"]["median"])
                    print(f"  {count:>6,} fish, {way:>13}: {report['fps']['median']:6.1f} FPS median "
                          f"({report['frames']} frames, {report['renderer']})", flush=True)
            row = {"fish": count, "calls": calls, "fps": {w: statistics.median(v) for w, v in runs.items()},
                   "runs": runs, "webgl": args.webgl, "size": f"{size[0]}x{size[1]}", "path": args.path}
            rows.append(row)
    print(f"\nBonyBream school, {args.frames} frames, {size[0]}x{size[1]}, {args.webgl}, {args.path} path, "
          f"medians of {args.repeat} round(s) of {args.seconds:g} s:")
    print(f"{'fish':>6} | {'instanced FPS':>13} | {'node-per-fish FPS':>17} | {'ratio':>6} | "
          f"{'draw calls':>14}")
    for r in rows:
        a, b = r["fps"]["instanced"], r["fps"]["node per fish"]
        print(f"{r['fish']:>6,} | {a:13.1f} | {b:17.1f} | {a / b if b else float('inf'):5.1f}x | "
              f"{r['calls']['instanced']:>5} vs {r['calls']['node per fish']:>5}")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
