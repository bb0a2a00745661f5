"""USD against glb for a school (issue 34, item 1): file size and write time of 1,000 BonyBream x
300 frames, as a node per fish in glb and as one PointInstancer in USD, side by side.

    python benchmarks/usd.py [--count 1000] [--frames 300] [--repeat 3] [--all]

Two measures, each the median of --repeat runs taken in turn (glb, usdc, glb, usdc, ...), so a busy
machine slows both alike:

- the whole command as a user runs it, in a subprocess: `fishgen school params/bonybream.txt
  --count N --frames F -o school.EXT` (start, imports, species, simulation, measures, bake, write);
- the bake and the write alone, in this process, from one simulation: what the output format
  changes (`bake` or `bake_prototypes`, then the writer).

`--all` adds .usda and .usdz rows. Needs usd-core (pip install 'fishgen[usd]'). A full run at the
default sizes takes about a minute.
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
sys.path.insert(0, str(ROOT))

SPECIES = ROOT / "params" / "bonybream.txt"


def command_seconds(output: Path, count: int, frames: int) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "fishgen", "school", str(SPECIES), "--count", str(count),
                    "--frames", str(frames), "-o", str(output), "-q"], cwd=ROOT, check=True)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=1000, help="fish [default: %(default)s]")
    parser.add_argument("--frames", type=int, default=300, help="frames [default: %(default)s]")
    parser.add_argument("--repeat", type=int, default=3, help="runs per row [default: %(default)s]")
    parser.add_argument("--all", action="store_true", help="also .usda and .usdz")
    args = parser.parse_args()

    from fishgen.exchange import export
    from fishgen.school.bake import bake, bake_prototypes
    from fishgen.school.run import plan_school, run_school
    from fishgen.school.scene_file import SceneFile, SpeciesEntry

    suffixes = [".glb", ".usdc"] + ([".usda", ".usdz"] if args.all else [])
    scene_file = SceneFile(species=(SpeciesEntry(SPECIES, args.count),), frames=args.frames)
    run = run_school(scene_file)             # one simulation for the bake rows...
    _, fishes, _ = plan_school(scene_file)   # ...and the species as it built them
    commands: dict[str, list[float]] = {s: [] for s in suffixes}
    writes: dict[str, list[float]] = {s: [] for s in suffixes}
    sizes: dict[str, int] = {}
    with tempfile.TemporaryDirectory(prefix="fishgen-usd-bench-") as tmp:
        folder = Path(tmp)
        for _ in range(args.repeat):
            for suffix in suffixes:
                target = folder / f"command{suffix}"
                commands[suffix].append(command_seconds(target, args.count, args.frames))
                sizes[suffix] = sum(p.stat().st_size for p in folder.glob("command*"))
                for p in folder.glob("command*"):
                    p.unlink()
                start = time.perf_counter()
                if suffix == ".glb":
                    scene = bake(fishes, run.tracks, seed=scene_file.seed, body_lengths=run.body_lengths)
                else:
                    scene = bake_prototypes(fishes, run.tracks, seed=scene_file.seed, fps=scene_file.fps)
                export(scene, folder / f"write{suffix}")
                writes[suffix].append(time.perf_counter() - start)
                for p in folder.glob("write*"):
                    p.unlink()
    print(f"fishgen school: {args.count:,} BonyBream x {args.frames} frames, medians of {args.repeat} "
          f"(runs taken in turn)")
    print(f"{'output':8} {'file MB':>9} {'command s':>10} {'bake+write s':>13}")
    for suffix in suffixes:
        print(f"{suffix:8} {sizes[suffix] / 1e6:9.2f} {statistics.median(commands[suffix]):10.2f} "
              f"{statistics.median(writes[suffix]):13.2f}")
    glb, usdc = ".glb", ".usdc"
    print(f"usdc / glb: size {sizes[usdc] / sizes[glb]:.2f}x, command "
          f"{statistics.median(commands[usdc]) / statistics.median(commands[glb]):.2f}x, bake+write "
          f"{statistics.median(writes[usdc]) / statistics.median(writes[glb]):.2f}x")
    print("(file MB: the asset and the files beside it: the texture PNG for USD; glb embeds it)")


if __name__ == "__main__":
    main()
