#!/usr/bin/env python3
"""How fast `fishgen edit` shows an edit: the preview's refresh after a cube changes.

    python benchmarks/editor.py                    # 554, 5,000 and 50,000 particles
    python benchmarks/editor.py --sizes 50000 --edits 9 --runs 9

Target (issue 21): an edit refreshes the preview within 0.5 s for clouds up to 50,000 particles.
For each size, one run measures, side by side:

* **server**: the editor's fill route as the page calls it (POST /api/fill: parse back, fill,
  light, GLB), over loopback from Python, median of --runs;
* **page**: the whole refresh in the real page in headless Chromium (`fishgen edit` as a user runs
  it, the Particles field typed into), from the edit to the frame drawn with the new cloud, and its
  steps (request sent, answer in, preview built, frame read back), median of --edits. WebGL here is
  SwiftShader, a CPU renderer: the frame is what a GPU would draw in a millisecond or two;
* **baseline**: what seeing an edit took before the editor: `fishgen preview FILE -o x.png`, a whole
  command (fill, light, render), median of --runs.

The clouds are Table 4.3 with every count scaled to the size and every radius by the cube root of
the inverse, so the cloud keeps its shape and optical thickness.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
TARGET_MS = 500


def scaled_table(size: int, path: Path) -> Path:
    from fishgen.clouds.parser import load_cubes
    from fishgen.editor.document import EditCube, cube_text

    table = load_cubes(ROOT / "params" / "clouds" / "table_4_3.awn")
    k = size / table.total
    cubes = [EditCube(round(c.particles * k), c.size, c.centre, round(c.max_radius * k ** (-1 / 3), 4))
             for c in table.cubes]
    path.write_text(cube_text(cubes, "particles"))
    return path


def server_ms(file: Path, runs: int) -> list[float]:
    from fishgen.editor.session import Session
    from tests.editor.client import Client

    server = Session(file).server(0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    client = Client(server)
    try:
        doc = client.get("/api/document").json()
        body = {"name": file.name, "mode": "particles", "cubes": doc["cubes"], "seed": 0}
        times = []
        for k in range(runs + 1):
            body["cubes"][0]["particles"] += 1 if k % 2 else -1  # an edit each time, as the page sends
            start = time.perf_counter()
            answer = client.post("/api/fill", body)
            times.append((time.perf_counter() - start) * 1000)
            assert answer.status == 200, answer.body
        return times[1:]  # the first pays for imports
    finally:
        server.shutdown()
        server.server_close()


def page_ms(browser, file: Path, edits: int, viewport) -> tuple[list[int], list[list[int]], list[int]]:
    from tests.editor.browser import EditorPage

    ed = EditorPage(browser, file, viewport=viewport)
    try:
        ed.button("Preview").click()
        ed.settle()
        ed.page.get_by_label("Cube", exact=True).select_option("0")
        start = int(ed.field("Particles").input_value())
        latencies, steps = [], []
        for k in range(edits):
            ed.field("Particles").fill(str(start + (1 if k % 2 == 0 else 0)))
            ed.settle()
            latencies.append(ed.state("fill.latency"))
            steps.append(ed.state("fill.steps"))
        draws = [ed.state("drawMs()") for _ in range(3)]
        return latencies, steps, draws
    finally:
        ed.close()


def baseline_ms(file: Path, runs: int) -> list[float]:
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(runs):
            start = time.perf_counter()
            subprocess.run([sys.executable, "-m", "fishgen", "preview", str(file), "-o", f"{tmp}/x.png"],
                           cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
            times.append((time.perf_counter() - start) * 1000)
    return times


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="554,5000,50000")
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--edits", type=int, default=7)
    parser.add_argument("--viewport", default="1280x800")
    parser.add_argument("--json", type=Path, help="also write the figures here")
    args = parser.parse_args()
    from tests.editor import browser as harness
    from tests.editor.browser import chromium

    harness.TIMEOUT_MS = 600_000  # a software-rendered frame of a big cloud takes long

    viewport = tuple(int(v) for v in args.viewport.split("x"))
    print(f"fishgen edit: edit -> preview refreshed, on {os.cpu_count()} cores, "
          f"Python {sys.version.split()[0]}, headless Chromium (SwiftShader) at {args.viewport}; "
          f"load average {os.getloadavg()[0]:.1f}")
    print(f"target: {TARGET_MS} ms up to 50,000 particles\n")
    print("| particles | server fill route | page: edit to frame drawn | "
          "page steps (sent / answered / built / drawn) | one frame drawn | baseline: fishgen preview | "
          "page vs target |")
    print("|---:|---:|---:|---|---:|---:|---|")
    figures = []
    with tempfile.TemporaryDirectory() as tmp, chromium() as browser:
        for size in (int(s) for s in args.sizes.split(",")):
            file = scaled_table(size, Path(tmp) / f"cloud_{size}.awn")
            server = server_ms(file, args.runs)
            latencies, steps, draws = page_ms(browser, file, args.edits, viewport)
            base = baseline_ms(file, args.runs)
            med_steps = [int(statistics.median(s[i] for s in steps)) for i in range(4)]
            page = statistics.median(latencies)
            verdict = "met" if page <= TARGET_MS else f"missed ({page / TARGET_MS:.1f}x)"
            print(f"| {size:,} | {statistics.median(server):.0f} ms | {page:.0f} ms | "
                  f"{' / '.join(str(v) for v in med_steps)} ms | {statistics.median(draws):.0f} ms | "
                  f"{statistics.median(base):.0f} ms | {verdict} |",
                  flush=True)
            figures.append({"particles": size, "server_ms": server, "page_ms": latencies, "page_steps": steps,
                            "draw_ms": draws,
                            "baseline_ms": base})
    print(f"\nmedians of {args.runs} (server, baseline) and {args.edits} (page) runs; load average after: "
          f"{os.getloadavg()[0]:.1f}")
    if args.json:
        args.json.write_text(json.dumps(figures, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
