"""Wall time and peak memory of `fishgen build`, as a whole command, per species and per
level of detail; and of `fishgen --help`.

    python benchmarks/build.py [--repeat 5]

Targets (issue 2): BonyBream under 1 s as a whole command on a 2-core machine,
`fishgen --help` under 0.3 s. Prints medians over --repeat runs, one row each.
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def run(cmd: list[str]) -> tuple[float, float]:
    """(seconds, peak RSS in MiB) of one child process."""
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, cwd=ROOT)
    _, status, usage = os.wait4(proc.pid, 0)
    elapsed = time.perf_counter() - start
    if status != 0:
        raise SystemExit(f"failed: {' '.join(cmd)}\n{proc.stderr.read().decode()}")
    return elapsed, usage.ru_maxrss / 1024


def lod_species(folder: Path, bodies: int, circles: int) -> Path:
    """BonyBream's design at another level of detail, with Fixel-style texture points."""
    from fishgen.authoring.texture_points import project_texture_points
    from fishgen.species.parser import parse_species
    from fishgen.species.writer import format_species

    bony = parse_species((ROOT / "params" / "bonybream.txt").read_text(), "bonybream.txt")
    k = (bodies - 1) / (bony.body_sections - 1)
    c = circles / bony.circle_sections

    def sec(v):
        return min(bodies - 1, round(v * k))

    sp = replace(
        bony, name=f"bonybream{bodies}x{circles}", body_sections=bodies, circle_sections=circles,
        adipose=replace(bony.adipose, start_section=sec(13), end_section=sec(15)),
        dorsal=replace(bony.dorsal, start_section=sec(7), end_section=sec(10)),
        anal=replace(bony.anal, start_section=sec(12), end_section=sec(15)),
        pelvic=replace(bony.pelvic, start_circle=round(11 * c) % circles, start_section=sec(4),
                       end_section=sec(7)),
        pectoral=replace(bony.pectoral, start_section=sec(6), start_circle=round(2 * c),
                         triangles=max(1, round(3 * c))))
    sp = project_texture_points(sp)
    path = folder / f"bonybream_{bodies}x{circles}.txt"
    path.write_text(format_species(sp, "bonybream.png", "bonybream_mask.png"))
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    fishgen = [sys.executable, "-m", "fishgen"]
    tmp = Path(tempfile.mkdtemp(prefix="fishgen-bench-"))
    try:
        for tex in ("bonybream.png", "bonybream_mask.png"):
            shutil.copy(ROOT / "textures" / tex, tmp / tex)
        cases = [("fishgen --help", fishgen + ["--help"])]
        for species in sorted((ROOT / "params").glob("*.txt")):
            cases.append((f"build {species.stem}",
                          fishgen + ["build", str(species), "-o", str(tmp / "o.glb")]))
        for b, c in ((8, 6), (16, 12), (32, 24), (128, 96)):
            path = lod_species(tmp, b, c)
            cases.append((f"build LOD {b}x{c}", fishgen + ["build", str(path), "-o", str(tmp / "o.glb")]))
        print(f"{'case':28} {'median s':>9} {'min s':>7} {'peak MiB':>9}   ({args.repeat} runs, "
              f"{os.cpu_count()} cores, Python {sys.version.split()[0]})")
        for name, cmd in cases:
            runs = [run(cmd) for _ in range(args.repeat)]
            times = [t for t, _ in runs]
            print(f"{name:28} {statistics.median(times):9.3f} {min(times):7.3f} "
                  f"{max(m for _, m in runs):9.1f}")
    finally:
        shutil.rmtree(tmp)


if __name__ == "__main__":
    main()
