"""Speed of `fishgen preview school.glb -o school.gif`: the whole command, as a user runs it.

    python benchmarks/preview_school.py [--repeat 3] [--baseline REV [--baseline-repeat 1]] [--count 200]

Issue 23, section 4: a 200-fish school previewed at the default size (800x600) and frame count
(48: 4 s at 12 fps) in under 10 s, the whole command (a subprocess: start, imports, reading the
glb, framing, rendering, GIF encoding, writing). Two schools are timed: params/bait-ball.toml (a
milling torus) and BonyBream --count N (a polarized school). Prints the median of --repeat runs
beside the target. With --baseline REV, the same command from that git revision of fishgen (an
archive of its `fishgen/` folder imported in place of this checkout's) runs alternately in the same loop, so
both see the same machine load, and the ratio is printed. CPU seconds (user + system of the
command's process and its Mesa threads) are printed beside: on a machine shared with other work
they show the cost when wall time only shows the load.
"""
from __future__ import annotations

import argparse
import resource
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET = 10.0


# `python -m fishgen` with fishgen imported from another folder: an editable install's import hook
# comes before sys.path (PYTHONPATH alone would still run this checkout), so it is removed first.
_FROM = """import runpy, sys
base = sys.argv.pop(1)
sys.meta_path[:] = [f for f in sys.meta_path if not type(f).__module__.startswith("__editable__")]
sys.path.insert(0, base)
import fishgen
assert fishgen.__file__.startswith(base), fishgen.__file__
runpy.run_module("fishgen", run_name="__main__", alter_sys=True)
"""


def _fishgen(*args: object, pythonpath: Path | None = None) -> tuple[float, float]:
    """Wall and CPU seconds (user + system, all threads) the command takes, with fishgen imported
    from ``pythonpath`` if given; it must succeed."""
    command = [sys.executable, "-m", "fishgen"] if pythonpath is None else \
        [sys.executable, "-c", _FROM, str(pythonpath)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    result = subprocess.run([*command, *map(str, args)], cwd=ROOT, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if result.returncode:
        sys.exit(f"fishgen {' '.join(map(str, args))} failed:\n{result.stderr}")
    return seconds, (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)


def _checkout(rev: str, into: Path) -> Path:
    """The `fishgen/` package of ``rev``, unpacked under ``into``."""
    archive = into / "base.tar"
    subprocess.run(["git", "archive", "-o", str(archive), rev, "fishgen"], cwd=ROOT, check=True)
    with tarfile.open(archive) as tar:
        tar.extractall(into / "base", filter="data")
    return into / "base"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3, help="runs per school (median)")
    parser.add_argument("--count", type=int, default=200, help="fish in the BonyBream school")
    parser.add_argument("--baseline", metavar="REV", help="also time this git revision, alternately")
    parser.add_argument("--baseline-repeat", type=int, default=1,
                        help="runs of the baseline per school (it may take over a minute each)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        schools = {"bait ball (params/bait-ball.toml)": folder / "ball.glb",
                   f"BonyBream --count {args.count}": folder / "bream.glb"}
        _fishgen("school", "params/bait-ball.toml", "-o", schools["bait ball (params/bait-ball.toml)"],
                 "--quiet")
        _fishgen("school", "params/bonybream.txt", "--count", args.count, "-o",
                 schools[f"BonyBream --count {args.count}"], "--quiet")
        base = _checkout(args.baseline, folder) if args.baseline else None
        print(f"fishgen preview SCHOOL.glb -o SCHOOL.gif (800x600, 48 frames), median of {args.repeat}"
              + (f" ({args.baseline}: of {min(args.repeat, args.baseline_repeat)})" if base else "")
              + f"; target under {TARGET:.0f} s")
        for name, glb in schools.items():
            now, before = [], []
            for k in range(args.repeat):
                now.append(_fishgen("preview", glb, "-o", folder / f"now{k}.gif", "--quiet"))
                if base is not None and k < args.baseline_repeat:
                    before.append(_fishgen("preview", glb, "-o", folder / f"base{k}.gif", "--quiet",
                                           pythonpath=base))
            median = statistics.median(w for w, _ in now)
            cpu = statistics.median(c for _, c in now)
            line = (f"  {name:<34} {median:6.2f} s (CPU {cpu:5.2f} s)  "
                    f"{'meets' if median < TARGET else 'MISSES'} the target")
            if before:
                old = statistics.median(w for w, _ in before)
                old_cpu = statistics.median(c for _, c in before)
                line += (f"   {args.baseline}: {old:6.2f} s (CPU {old_cpu:5.2f} s)   "
                         f"{old / median:4.1f}x faster (CPU {old_cpu / cpu:4.1f}x)")
            print(line)


if __name__ == "__main__":
    main()
