"""Speed of `fishgen batch`: 100 builds with -j 1 beside -j 2, and the rerun where nothing changed.

    python benchmarks/batch.py [--repeat 11] [--jobs 100] [--python PATH]

Targets (issue 11): on a 2-core machine 100 builds run at least 1.8x faster with -j 2 than with
-j 1; a rerun of 100 jobs with nothing changed takes under 1 s. Each figure is a whole command
(start-up, manifest, record, workers), the -j 1 and -j 2 runs alternating so that the machine's
noise falls on both alike; medians over --repeat runs. The jobs build the four shipped species in
turn, each to its own output, with --force so that every run builds all of them. Alternating
with them, two -j 1 batches run at once, each in a folder of its own: how much faster two
processes that share nothing finish twice the work is the most -j 2 can reach on this machine
(two busy cores of a VM run each other slower). fishgen's
bytecode is compiled first, as an installed package's is (pip compiles it; an editable checkout
under PYTHONDONTWRITEBYTECODE would otherwise compile every module from source in every run).
`--python` runs another interpreter's fishgen, e.g. a fresh virtualenv's `pip install .`, as a
user has it: no editable-install finder, no site-wide .pth files run at every start.
"""
from __future__ import annotations

import argparse
import compileall
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SPECIES = sorted((ROOT / "params").glob("*.txt"))


def manifest(folder: Path, jobs: int) -> Path:
    folder.mkdir()
    shutil.copytree(ROOT / "params", folder / "params")
    shutil.copytree(ROOT / "textures", folder / "textures", ignore=shutil.ignore_patterns("*.py"))
    path = folder / "params" / "bench.toml"
    path.write_text('out = "../out"\n' + "".join(
        f'[[build]]\ninput = "{SPECIES[i % len(SPECIES)].name}"\noutput = "fish/{i:03d}.glb"\n'
        for i in range(jobs)))
    return path


def run(python: str, folder: Path, *args: str) -> float:
    return run_at_once(python, [folder], *args)


def run_at_once(python: str, folders: list[Path], *args: str) -> float:
    """Seconds until the same batch has ended in each of ``folders``, all started together."""
    start = time.perf_counter()
    # run from the scratch folder: from the checkout, `-m fishgen` would import the source tree
    procs = [subprocess.Popen([python, "-m", "fishgen", "batch", *args, "--quiet"], cwd=folder,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for folder in folders]
    outs = [proc.communicate() for proc in procs]
    elapsed = time.perf_counter() - start
    for proc, (_, err) in zip(procs, outs, strict=True):
        if proc.returncode != 0:
            raise SystemExit(f"failed: fishgen batch {' '.join(args)}\n{err}")
    return elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=11,
                        help="runs of each -j value (default: 11; this machine spreads them by 10-20 %%)")
    parser.add_argument("--jobs", type=int, default=100)
    parser.add_argument("--python", default=sys.executable,
                        help="the interpreter whose fishgen runs (default: this one)")
    args = parser.parse_args()
    compileall.compile_dir(ROOT / "fishgen", quiet=1)
    load = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        folder, other = Path(tmp) / "a", Path(tmp) / "b"
        path = manifest(folder, args.jobs)
        manifest(other, args.jobs)
        run_at_once(args.python, [folder, other], str(path.relative_to(folder)), "-j", "2")  # warm the caches
        times: dict[str, list[float]] = {"-j 1": [], "-j 2": []}
        both: list[float] = []  # two -j 1 batches at once
        for _ in range(args.repeat):
            for workers in ("1", "2"):
                times[f"-j {workers}"].append(run(args.python, folder, str(path), "-j", workers, "--force"))
            both.append(run_at_once(args.python, [folder, other], str(path.relative_to(folder)), "-j", "1",
                                    "--force"))
        unchanged = [run(args.python, folder, str(path)) for _ in range(max(5, args.repeat))]
    print(f"fishgen batch: {args.jobs} builds of the 4 shipped species, {os.cpu_count()} cores, "
          f"{args.python}, median of {args.repeat} (min, max); load average before "
          f"{load[0]:.1f}, after {os.getloadavg()[0]:.1f} (other processes' share of the cores)")
    for label, runs in times.items():
        print(f"  {label}   {statistics.median(runs):7.2f} s   ({min(runs):.2f}, {max(runs):.2f})   "
              f"{args.jobs / statistics.median(runs):6.1f} jobs/s")
    ratio = statistics.median(times["-j 1"]) / statistics.median(times["-j 2"])
    best = min(times["-j 1"]) / min(times["-j 2"])
    # each -j 1 run beside the -j 2 run right after it: the machine's slower spells fall on both
    pairs = sorted(one / two for one, two in zip(times["-j 1"], times["-j 2"], strict=True))
    print(f"  -j 2 is {ratio:.2f}x -j 1 by medians, {best:.2f}x by the fastest runs, "
          f"{statistics.median(pairs):.2f}x by the median of the {len(pairs)} side-by-side pairs "
          f"({pairs[0]:.2f} to {pairs[-1]:.2f}) (target: at least 1.8x)")
    ceiling = sorted(2 * one / two for one, two in zip(times["-j 1"], both, strict=True))
    top = statistics.median(ceiling)
    print(f"  the machine's ceiling: two -j 1 batches at once did twice the work {top:.2f}x as fast as "
          f"one, median of the {len(ceiling)} pairs ({ceiling[0]:.2f} to {ceiling[-1]:.2f}); -j 2 reached "
          f"{statistics.median(pairs) / top:.0%} of it by pairs")
    print(f"  rerun with nothing changed, {args.jobs} jobs: {statistics.median(unchanged):.3f} s median of "
          f"{len(unchanged)} (target: under 1 s)")


if __name__ == "__main__":
    main()
