"""Benchmark `fishgen clouds`: fill rate vs. a plain Python loop, lighting, whole command, peak memory.

    python benchmarks/clouds.py                 # full run (a few minutes)
    python benchmarks/clouds.py --quick         # smoke run, small sizes only
    python benchmarks/clouds.py --writers-only  # CSV vs PLY writer, 10^6 particles
    python benchmarks/clouds.py --light-only    # lighting vs fill, and lit vs unlit whole runs
    python benchmarks/clouds.py --cost          # issue 32: the whole command's marginal cost per
                                                # particle, lit, --no-light and with numpy's huge
                                                # pages on, against plain loops
    python benchmarks/clouds.py --cost --baseline /work/main   # the same, beside another checkout's
    python benchmarks/clouds.py --cost --settle 10   # each run on cold memory, as on an idle machine
    chrt -f 10 python benchmarks/clouds.py --light-only   # the same, ahead of everything else
                                                          # running (root; a busy shared machine)

The cloud shape is the report's Table 4.4 (23 cubes) with every cube's count
scaled so the total is N. The baseline is the report's algorithm (section 4.5,
Figure 4.2) written one particle at a time in plain Python, with the same
departures as fishgen (docs/decisions.md), so both do the same work.
It is run only up to --baseline-max particles; larger sizes are compared
against its rate at the largest measured size (the loop is linear), marked "*".
"""
from __future__ import annotations

import argparse
import functools
import math
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fishgen.clouds import Cube, CubeFile, Lighting, fill_cloud, light_cloud, load_cubes  # noqa: E402
from fishgen.clouds.light import incident_light  # noqa: E402
from fishgen.clouds.scene import cloud_scene  # noqa: E402
from fishgen.exchange.ply import write_ply as _write_ply  # noqa: E402
from fishgen.exchange.table import write_csv as _write_csv  # noqa: E402


def write_ply(cloud, path):
    return _write_ply(cloud_scene(cloud), Path(path))


def write_csv(cloud, path):
    return _write_csv(cloud_scene(cloud), Path(path))
from fishgen.clouds.fill import CLUMP  # noqa: E402

TABLE = ROOT / "params" / "clouds" / "table_4_4.awn"
REPORT = "report: 50,000 particles in ~90 ms on a 3.2 GHz Pentium IV (section 5.2)"


def scaled_cubes(n: int) -> CubeFile:
    """Table 4.4's cubes with counts scaled to a total of n (remainder to the base cube)."""
    cubes = load_cubes(TABLE).cubes
    total = sum(c.particles for c in cubes)
    counts = [c.particles * n // total for c in cubes]
    counts[0] += n - sum(counts)
    return CubeFile(f"table 4.4 x {n}", n, tuple(
        Cube(k, c.size, c.centre, c.max_radius, c.line) for k, c in zip(counts, cubes, strict=True)))


def write_awn(cube_file: CubeFile, path: Path) -> None:
    rows = [str(cube_file.total), str(len(cube_file.cubes))]
    rows += [", ".join(map(str, (c.particles, *c.size, *c.centre, c.max_radius)))
             for c in cube_file.cubes]
    path.write_text("\n".join(rows) + "\n")


def plain_fill(cube_file: CubeFile, seed: int) -> list[tuple]:
    """The report's algorithm, one particle at a time: the baseline."""
    rnd = random.Random(seed)
    half_pi, k, norm = math.pi / 2, CLUMP / math.pi, 1 + math.pi / 2 * math.sin(1)
    out = []
    for cube in cube_file.cubes:
        (cx, cy, cz), (sx, sy, sz) = cube.centre, cube.size
        for _ in range(cube.particles):
            while True:  # Figure 4.2: get a new particle until its centre is in the cube
                x, y, z = rnd.random() * 2 - 1, rnd.random() * 2 - 1, rnd.random() * 2 - 1
                px = half_pi * math.sin(half_pi * y)                  # eq. 4.5
                py = half_pi * math.sin(half_pi * x)
                pz = half_pi * math.sin(half_pi * z)
                px += math.pi * math.sin(px * half_pi * z)            # eq. 4.6
                py += math.pi * math.sin(py * half_pi * z)
                x, y, z = x + k * px, y + k * py, z + k * pz          # eq. 4.7
                if -1 <= x <= 1 and -1 <= y <= 1 and -1 <= z <= 1:
                    break
            u = 1 - rnd.random()
            radius = cube.max_radius * (u + half_pi * math.sin(u)) / norm  # eq. 4.9-4.12
            density = math.exp(-(x * x + y * y + z * z))
            out.append((cx + x * sx / 2, cy + y * sy / 2, cz + z * sz / 2, radius, density))
    return out


def plain_ply(cube_file: CubeFile, seed: int, path: str) -> None:
    """The plain loop as a whole program: the report's fill, then each particle packed into the
    PLY record `fishgen clouds --no-light` writes (centre, radius, density, sRGB white)."""
    import struct

    rows = plain_fill(cube_file, seed)
    pack = struct.Struct("<5f3B").pack
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {len(rows)}\n"
              + "".join(f"property float {n}\n" for n in ("x", "y", "z", "radius", "density"))
              + "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n")
    with open(path, "wb") as handle:
        handle.write(header.encode("ascii"))
        handle.write(b"".join(pack(*row, 255, 255, 255) for row in rows))


PLY_RECORD = 23
"""Bytes of one particle's PLY record (centre, radius, density: 5 float32; sRGB: 3 bytes)."""


def write_floor(n: int, path: str | Path) -> None:
    """Write and fsync as many bytes as n particles' PLY records, 8 MiB at a time, from one buffer:
    what any PLY writer pays the kernel for the file, with nothing computed."""
    block = bytes(1 << 23)
    left = n * PLY_RECORD
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    try:
        while left > 0:
            left -= os.write(fd, block[:min(left, len(block))])
        os.fsync(fd)
    finally:
        os.close(fd)


def median_time(run, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


COMMANDS = {
    "fishgen": lambda awn, ply: [sys.executable, "-m", "fishgen", "clouds", str(awn), "-o", str(ply)],
    "no-light": lambda awn, ply: [sys.executable, "-m", "fishgen", "clouds", str(awn), "-o", str(ply),
                                  "--no-light"],
    # the command as it ran before it turned numpy's huge pages off (docs/decisions.md)
    "huge-pages": lambda awn, ply: ["env", "NUMPY_MADVISE_HUGEPAGE=1", sys.executable, "-m", "fishgen",
                                    "clouds", str(awn), "-o", str(ply)],
    "unlit": lambda awn, ply: [sys.executable, __file__, "--run", "unlit", str(awn), str(ply)],
    "lit": lambda awn, ply: [sys.executable, __file__, "--run", "lit", str(awn), str(ply)],
    "plain": lambda awn, ply: [sys.executable, __file__, "--run", "plain", str(awn), str(ply)],
    "plain-ply": lambda awn, ply: [sys.executable, __file__, "--run", "plain-ply", str(awn), str(ply)],
    "write-floor": lambda awn, ply: [sys.executable, __file__, "--run", "write-floor", str(awn), str(ply)],
}
"""`fishgen clouds` as the command line runs it today (lit, and with --no-light), and the library
steps the command runs,
without and with lighting (load, fill, [light_cloud,] export), each a process of its own."""


def run(kind: str, awn: str, ply: str) -> None:
    """One whole run, as the `--run` child process: what `fishgen clouds AWN -o PLY` does."""
    from fishgen.clouds import export_cloud

    if kind == "plain":               # the fill only, as the baseline; nothing written
        plain_fill(load_cubes(awn), 0)
        Path(ply).write_bytes(b"\0" * 24 * len(load_cubes(awn).cubes))  # whole_command checks a file
        return
    if kind == "plain-ply":
        plain_ply(load_cubes(awn), 0, ply)
        return
    if kind == "write-floor":         # no fill, no light: the PLY's bytes alone, written and synced
        write_floor(sum(cube.particles for cube in load_cubes(awn).cubes), ply)
        return
    cloud = fill_cloud(load_cubes(awn), seed=0)
    if kind == "lit":
        cloud = light_cloud(cloud, Lighting())
    export_cloud(cloud, ply)


def whole_command(n: int, workdir: Path, repeats: int, kinds=("fishgen",), baseline: Path | None = None,
                  cpu: dict[str, float] | None = None, settle: float = 0.0) -> dict[str, tuple[float, int]]:
    """Per kind of COMMANDS: median wall time and peak RSS (bytes) of the whole run on a
    Table 4.4 cloud of n particles to PLY, the kinds interleaved run by run. A kind ``base:K`` is
    K run from ``baseline`` (another checkout: its fishgen, its benchmarks/clouds.py). ``cpu``, if
    given, gets each kind's median CPU seconds in user mode and in the kernel (all threads), as
    ``kind`` and ``kind:system``. ``settle``: seconds to wait before each run, so it starts on memory
    the kernel has let go cold, as a command run on an idle machine does (a run that follows
    another's exit within a second or two gets the pages that exit freed, and pays far less for
    its first touches)."""
    awn, ply = workdir / f"cloud_{n}.awn", workdir / f"cloud_{n}.ply"
    write_awn(scaled_cubes(n), awn)
    # Each measurement runs in its own wrapper so RUSAGE_CHILDREN sees only that command.
    probe = ("import resource, subprocess, sys, time\n"
             "t = time.perf_counter()\n"
             "subprocess.run(sys.argv[1:], check=True, stdout=subprocess.DEVNULL)\n"
             "u = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
             "print(time.perf_counter() - t, u.ru_maxrss, u.ru_utime, u.ru_stime)")
    times: dict[str, list[float]] = {k: [] for k in kinds}
    cpus: dict[str, list[float]] = {k: [] for k in kinds} | {f"{k}:system": [] for k in kinds}
    peaks: dict[str, list[int]] = {k: [] for k in kinds}
    for _ in range(repeats):
        for kind in kinds:
            time.sleep(settle)
            base = kind.startswith("base:")
            if base and baseline is None:
                raise ValueError(f"{kind} needs a baseline checkout")
            where = baseline if base else ROOT
            argv = COMMANDS[kind.removeprefix("base:")](awn, ply)
            if base and argv[1] == __file__:
                argv[1] = str(where / "benchmarks" / "clouds.py")
            env = {**os.environ, "PYTHONPATH": str(where)}
            out = subprocess.run([sys.executable, "-c", probe, *argv], cwd=where, env=env,
                                 capture_output=True, text=True, check=True).stdout.split()
            times[kind].append(float(out[0]))
            peaks[kind].append(int(out[1]) * 1024)  # ru_maxrss is in KiB on Linux
            cpus[kind].append(float(out[2]))
            cpus[f"{kind}:system"].append(float(out[3]))
            assert ply.stat().st_size >= (0 if kind.endswith("plain") else PLY_RECORD * n)
            ply.unlink()
    if cpu is not None:
        cpu.update({k: statistics.median(v) for k, v in cpus.items()})
    return {k: (statistics.median(times[k]), max(peaks[k])) for k in kinds}


def lighting(n: int, repeats: int) -> tuple[float, float]:
    """Median seconds of fill_cloud and of incident_light for one n-particle cloud, interleaved."""
    cubes = scaled_cubes(n)
    cloud = fill_cloud(cubes, seed=1)
    incident_light(cloud.centers, cloud.radii, cloud.density, Lighting())  # warm-up
    fills, lights = [], []
    for _ in range(repeats):
        start = time.perf_counter()
        fill_cloud(cubes, seed=1)
        fills.append(time.perf_counter() - start)
        start = time.perf_counter()
        incident_light(cloud.centers, cloud.radii, cloud.density, Lighting())
        lights.append(time.perf_counter() - start)
    return statistics.median(fills), statistics.median(lights)


def light_report(sizes: list[int], command_size: int, repeats: int, workdir: Path) -> None:
    """The lighting targets (issue 20): lighting <= 3x the fill; a lit whole run < 2x the unlit
    one; peak memory < 64 bytes per particle."""
    print("\n| particles | fill (median) | lighting (median) | lighting / fill |")
    print("|---:|---:|---:|---:|")
    for n in sizes:
        fill, light = lighting(n, repeats)
        print(f"| {n:,} | {fill * 1e3:,.1f} ms | {light * 1e3:,.1f} ms | {light / fill:.2f}x |")
    runs = whole_command(command_size, workdir, 3, ("fishgen", "no-light", "unlit", "lit"))
    print(f"\nwhole run, {command_size:,} particles to PLY, median of 3, interleaved:")
    for kind, label in (("fishgen", "`fishgen clouds` (lit, as shipped)"),
                        ("no-light", "`fishgen clouds --no-light`"), ("unlit", "library steps, unlit"),
                        ("lit", "library steps, lit")):
        wall, peak = runs[kind]
        print(f"  {label:34s} {wall:6.2f} s, peak {peak / 2**20:,.0f} MiB = "
              f"{peak / command_size:.1f} bytes/particle")
    print(f"  lit / unlit library steps: {runs['lit'][0] / runs['unlit'][0]:.2f}x (target < 2x)")
    print(f"  `fishgen clouds` / `--no-light`: {runs['fishgen'][0] / runs['no-light'][0]:.2f}x")


def cost_report(small: int, large: int, plain_size: int, repeats: int, workdir: Path,
                baseline: Path | None = None, settle: float = 0.0) -> None:
    """Issue 32, item 3: the whole command's marginal cost per particle between ``small`` and
    ``large`` particles, lit (as shipped) and --no-light, against the plain loops' cost per
    particle at ``plain_size`` (each a fresh process, so the loop's heap is its own): the fill
    alone (the issue's baseline) and the fill plus packing and writing the same PLY. Target: the
    lit command's marginal cost at least 50x below the plain fill's. With ``baseline`` (another
    checkout, e.g. main's), its two commands run interleaved with these. The CPU time (all
    threads) is given beside the wall time, in user mode (the steadier figure on a shared machine)
    and in the kernel (page faults of fresh arrays, the page cache, fsync: it varies 5x there)."""
    kinds = ("fishgen", "no-light", "huge-pages", *(("base:fishgen", "base:no-light") if baseline else ()),
             "write-floor")
    cpu_low: dict[str, float] = {}
    cpu_high: dict[str, float] = {}
    low = whole_command(small, workdir, repeats, kinds, baseline, cpu_low, settle)
    high = whole_command(large, workdir, repeats, kinds, baseline, cpu_high, settle)
    plain = whole_command(plain_size, workdir, repeats, ("plain", "plain-ply"), settle=settle)
    per = {k: plain[k][0] / plain_size for k in plain}   # start-up (~30 ms) left in: < 2 %
    print(f"\nwhole command, Table 4.4 cloud to PLY, medians of {repeats}, kinds interleaved run by run"
          f"{f'; base: {baseline}' if baseline else ''}"
          f"{f'; {settle:g} s idle before each' if settle else ''}:")
    print("| command | " + f"{small:,} | {large:,} | marginal per particle | plain fill / marginal "
          f"| plain fill+PLY / marginal | user CPU marginal | kernel CPU marginal | peak at {large:,} |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    labels = {"fishgen": "`fishgen clouds` (lit)", "no-light": "`fishgen clouds --no-light`",
              "huge-pages": "`fishgen clouds` (lit), numpy's huge pages on",
              "write-floor": f"writing {PLY_RECORD} bytes a particle alone (fsync'd, nothing computed)"}
    for kind in kinds:
        label = labels[kind.removeprefix("base:")] + (" (base)" if kind.startswith("base:") else "")
        marginal = (high[kind][0] - low[kind][0]) / (large - small)
        user, kernel = ((cpu_high[k] - cpu_low[k]) / (large - small) for k in (kind, f"{kind}:system"))
        print(f"| {label} | {low[kind][0]:.2f} s | {high[kind][0]:.2f} s | {marginal * 1e9:.0f} ns "
              f"| {per['plain'] / marginal:.1f}x | {per['plain-ply'] / marginal:.1f}x | {user * 1e9:.0f} ns "
              f"| {kernel * 1e9:.0f} ns "
              f"| {high[kind][1] / large:.1f} B/particle |")
    print(f"plain loops at {plain_size:,} particles, whole process: "
          f"fill {per['plain'] * 1e9:,.0f} ns a particle, fill + PLY {per['plain-ply'] * 1e9:,.0f} ns")
    print("target (issue 32): lit marginal cost >= 50x below the plain fill's; the last row is the floor "
          "of any PLY writer on this machine (the kernel's page cache and the disk)")


def writers(n: int, workdir: Path, repeats: int) -> None:
    """Median time of the CSV and PLY writers for one n-particle cloud, interleaved."""
    cloud = fill_cloud(scaled_cubes(n), seed=1)
    times: dict[str, list[float]] = {"csv": [], "ply": []}
    for _ in range(repeats):
        for ext, write in (("csv", write_csv), ("ply", write_ply)):
            start = time.perf_counter()
            write(cloud, workdir / f"cloud.{ext}")
            times[ext].append(time.perf_counter() - start)
    size = (workdir / "cloud.csv").stat().st_size
    print(f"\nwriters, {n:,} particles: CSV {statistics.median(times['csv']):.2f} s "
          f"({size / 1e6:.1f} MB), PLY {statistics.median(times['ply']):.2f} s, "
          f"median of {repeats}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="1e4,5e4,1e5,1e6,1e7",
                        help="particle counts to fill [default: %(default)s]")
    parser.add_argument("--baseline-max", type=float, default=1e6,
                        help="largest size run through the plain loop [default: %(default)s]")
    parser.add_argument("--repeats", type=int, default=5, help="timings per size [default: 5]")
    parser.add_argument("--command-size", type=float, default=1e7,
                        help="particles for the whole-command PLY run [default: %(default)s]")
    parser.add_argument("--quick", action="store_true", help="small sizes only (smoke test)")
    parser.add_argument("--writers-only", action="store_true",
                        help="only time the CSV and PLY writers at 10^6 particles")
    parser.add_argument("--light-only", action="store_true",
                        help="only the lighting figures: vs the fill at --light-sizes, "
                             "whole runs at --command-size")
    parser.add_argument("--light-sizes", default="1e5,1e6",
                        help="particle counts to light [default: %(default)s]")
    parser.add_argument("--cost", action="store_true",
                        help="only the whole command's marginal cost per particle against the plain loops")
    parser.add_argument("--baseline", type=Path, metavar="DIR",
                        help="with --cost: also run the commands of the checkout in DIR (e.g. main's), "
                             "interleaved with these [default: none]")
    parser.add_argument("--settle", type=float, default=0.0, metavar="SECONDS",
                        help="with --cost: wait this long before each run, so each starts on cold memory, "
                             "as a command run on an idle machine does (10 is enough here) [default: 0]")
    parser.add_argument("--run", nargs=3, metavar=("KIND", "AWN", "PLY"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.run:
        run(*args.run)
        return
    if args.cost:
        with tempfile.TemporaryDirectory(dir=ROOT / "out" if (ROOT / "out").is_dir() else None) as tmp:
            cost_report(10**6, int(args.command_size), 10**6, args.repeats if args.repeats != 5 else 3,
                        Path(tmp), args.baseline.resolve() if args.baseline else None, args.settle)
        return
    if args.light_only:
        with tempfile.TemporaryDirectory(dir=ROOT / "out" if (ROOT / "out").is_dir() else None) as tmp:
            light_report([int(float(v)) for v in args.light_sizes.split(",")], int(args.command_size),
                         args.repeats, Path(tmp))
        return
    if args.writers_only:
        with tempfile.TemporaryDirectory() as tmp:
            writers(10**6, Path(tmp), 3)
        return
    if args.quick:
        args.sizes, args.baseline_max, args.repeats, args.command_size = "1e4,1e5", 1e4, 3, 1e5
        args.light_sizes = "1e4,1e5"
    sizes = [int(float(s)) for s in args.sizes.split(",")]

    print(f"fishgen clouds benchmark on {os.cpu_count()} cores, Python {sys.version.split()[0]}")
    print(REPORT)
    print()
    print("| particles | fishgen (median) | fishgen particles/s | plain loop (median) "
          "| plain particles/s | speed-up |")
    print("|---:|---:|---:|---:|---:|---:|")
    fill_cloud(scaled_cubes(10_000), seed=0)  # warm-up: imports, thread pool, page cache
    plain_rate = None
    for n in sizes:
        cubes = scaled_cubes(n)
        fast = median_time(functools.partial(fill_cloud, cubes, seed=1), args.repeats if n < 10**7 else 3)
        if n <= args.baseline_max:
            reps = max(1, min(args.repeats, int(2e5 // n)))
            slow = median_time(functools.partial(plain_fill, cubes, 1), reps)
            plain_rate, mark = n / slow, ""
        else:
            if plain_rate is None:  # every size is above --baseline-max: measure the loop there once
                m = int(args.baseline_max)
                plain_rate = m / median_time(functools.partial(plain_fill, scaled_cubes(m), 1), 1)
            slow, mark = n / plain_rate, "*"
        print(f"| {n:,} | {fast * 1e3:,.1f} ms | {n / fast / 1e6:,.1f} M | "
              f"{slow * 1e3:,.0f} ms{mark} | {n / slow / 1e6:,.2f} M{mark} | {slow / fast:,.0f}x{mark} |")
    print("\n* extrapolated from the plain loop's rate at the largest size it ran, or at --baseline-max "
          "(it is linear).")

    n = int(args.command_size)
    with tempfile.TemporaryDirectory(dir=ROOT / "out" if (ROOT / "out").is_dir() else None) as tmp:
        wall, peak = whole_command(n, Path(tmp), 3)["fishgen"]
        _, idle = whole_command(1000, Path(tmp), 1)["fishgen"]
    print(f"\nwhole command, {n:,} particles to PLY: {wall:.2f} s median of 3 "
          f"({n / wall / 1e6:.1f} M particles/s end to end)")
    print(f"peak memory: {peak / 2**20:,.0f} MiB = {peak / n:.1f} bytes/particle "
          f"({(peak - idle) / n:.1f} bytes/particle above the {idle / 2**20:.0f} MiB "
          f"of a 1,000-particle run)")
    with tempfile.TemporaryDirectory() as tmp:
        writers(10**5 if args.quick else 10**6, Path(tmp), 3)
    with tempfile.TemporaryDirectory(dir=ROOT / "out" if (ROOT / "out").is_dir() else None) as tmp:
        light_report([int(float(v)) for v in args.light_sizes.split(",")], n, args.repeats, Path(tmp))


if __name__ == "__main__":
    main()
