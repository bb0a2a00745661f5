#!/usr/bin/env python3
"""Time `fishgen preview` as a whole command (interpreter start to PNG on disk).

    python benchmarks/preview.py              # 7 runs per input, 800x600
    python benchmarks/preview.py --runs 15 params/bonybream.txt

Prints median / min / max wall-clock seconds per input, then an in-process
breakdown for the first input (load, GL context, render, encode). Exits 1 if
a species (.txt) median exceeds the 2 s budget of issue 3.
"""
from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BUDGET_SECONDS = 2.0


def whole_command(inp: str, out: Path, size: str) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "fishgen", "preview", inp, "-o", str(out), "--size", size],
                   cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def breakdown(inp: str, size: str) -> dict[str, float]:
    from PIL import Image

    from fishgen.preview.inputs import load_input
    from fishgen.preview.pipeline import PreviewOptions, encode, frame_scene, parse_size
    from fishgen.preview.render import Renderer

    w, h = parse_size(size)
    opts = PreviewOptions(width=w, height=h)
    t = [time.perf_counter()]
    scene = load_input(ROOT / inp)
    t.append(time.perf_counter())
    renderer = Renderer(w, h)
    t.append(time.perf_counter())
    cam = frame_scene(scene, opts.view, w / h)
    img = Image.fromarray(renderer.render(scene, cam, None, tuple(c / 255 for c in opts.background)))
    t.append(time.perf_counter())
    encode([img], Path("x.png"), 0)
    t.append(time.perf_counter())
    renderer.release()
    intervals = (b - a for a, b in zip(t, t[1:], strict=False))  # consecutive stamps: t[1:] is one shorter
    return dict(zip(("load+build", "gl context", "render", "png encode"), intervals, strict=True))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("inputs", nargs="*", help="default: params/*.txt and params/clouds/*.awn")
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--size", default="800x600")
    args = parser.parse_args()
    inputs = args.inputs or [str(p.relative_to(ROOT)) for p in sorted((ROOT / "params").glob("*.txt"))
                             + sorted((ROOT / "params" / "clouds").glob("*.awn"))]
    over = []
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "bench.png"
        whole_command(inputs[0], out, args.size)  # warm the file cache once
        print(f"fishgen preview INPUT -o out.png --size {args.size}: {args.runs} runs each")
        for inp in inputs:
            times = [whole_command(inp, out, args.size) for _ in range(args.runs)]
            med = statistics.median(times)
            print(f"  {inp:34s} median {med:.3f} s   min {min(times):.3f}   max {max(times):.3f}")
            if inp.endswith(".txt") and med > BUDGET_SECONDS:
                over.append(inp)
    parts = breakdown(inputs[0], args.size)
    print(f"in-process breakdown for {inputs[0]}: "
          + ", ".join(f"{k} {v * 1000:.0f} ms" for k, v in parts.items()))
    if over:
        print(f"over the {BUDGET_SECONDS} s budget: {', '.join(over)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
