"""Benchmark clouds as volumes (`fishgen clouds -o cloud.nvdb / cloud.vdb`): splat, write, size.

    python benchmarks/volumes.py              # full run (3 to 4 minutes on 2 busy cores)
    python benchmarks/volumes.py --quick      # smoke run: Table 4.4 only, one repeat
    python benchmarks/volumes.py --repeats 9  # more repeats per figure (medians)

For each cloud (the report's Tables 4.4 and 4.2, and Table 4.4 with every cube's count scaled to
20,000 particles: the splat's cost is the particles' footprints, sum of (2.4 radius / voxel)^3) at
a voxel size: the particles' fill and light (what every output pays first),
the splat into density and light grids, then writing .nvdb and .vdb, each beside writing the same
cloud's .ply in the same run (the baseline: the particle file fishgen wrote before). Times are
medians of --repeats runs; files go to a temporary folder.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fishgen.clouds import Cube, CubeFile, Lighting, fill_cloud, light_cloud, load_cubes  # noqa: E402
from fishgen.clouds.scene import cloud_scene  # noqa: E402
from fishgen.clouds.volume import particle_volume  # noqa: E402
from fishgen.exchange.nanovdb import write_nvdb  # noqa: E402
from fishgen.exchange.openvdb import write_vdb  # noqa: E402
from fishgen.exchange.ply import write_ply  # noqa: E402

PARAMS = ROOT / "params" / "clouds"


def scaled(path: Path, n: int) -> CubeFile:
    """A cube file's cubes with counts scaled to a total of n (remainder to the first cube)."""
    cubes = load_cubes(path).cubes
    total = sum(c.particles for c in cubes)
    counts = [c.particles * n // total for c in cubes]
    counts[0] += n - sum(counts)
    return CubeFile(f"{path.stem} x {n}", n, tuple(Cube(k, c.size, c.centre, c.max_radius, c.line)
                                                   for k, c in zip(counts, cubes, strict=True)))


def median_time(work, repeats: int) -> tuple[float, object]:
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = work()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def run(name: str, cubes: CubeFile, voxel_size: float, repeats: int, folder: Path) -> None:
    fill_s, cloud = median_time(lambda: light_cloud(fill_cloud(cubes, seed=0)), repeats)
    scene = cloud_scene(cloud)
    extinction = Lighting().extinction
    splat_s, volume = median_time(lambda: particle_volume(cloud.centers, cloud.radii, cloud.density,
                                                          cloud.light, extinction, voxel_size), repeats)
    rows = []
    for ext, write in ((".ply", lambda p: write_ply(scene, p)),
                       (".nvdb", lambda p: write_nvdb(scene, p, voxel_size)),
                       (".vdb", lambda p: write_vdb(scene, p, voxel_size))):
        path = folder / f"{name}{ext}"
        seconds, _ = median_time(lambda write=write, path=path: write(path), repeats)
        rows.append((ext, seconds, path.stat().st_size))
    ply_s, ply_bytes = rows[0][1], rows[0][2]
    print(f"\n{name}: {len(cloud):,} particles, voxel {voxel_size:g}: {len(volume.origins):,} leaves, "
          f"{volume.voxel_count:,} active voxels")
    print(f"  fill + light {fill_s * 1e3:9.1f} ms   splat (density + light grids) {splat_s * 1e3:9.1f} ms")
    print(f"  {'format':7} {'write ms':>10} {'x .ply':>8} {'bytes':>14} {'x .ply':>8}   "
          "(a volume's write includes its splat)")
    for ext, seconds, size in rows:
        print(f"  {ext:7} {seconds * 1e3:10.1f} {seconds / ply_s:8.1f} {size:14,} {size / ply_bytes:8.1f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="Table 4.4 at the default voxel only, one repeat")
    parser.add_argument("--repeats", type=int, default=5, help="runs per figure (their median is shown)")
    args = parser.parse_args()
    repeats = 1 if args.quick else args.repeats
    cases = [("table_4_4", load_cubes(PARAMS / "table_4_4.awn"), 0.2)]
    if not args.quick:
        cases += [("table_4_4", load_cubes(PARAMS / "table_4_4.awn"), 0.1),
                  ("table_4_2", load_cubes(PARAMS / "table_4_2.awn"), 0.2),
                  ("table_4_4_2e4", scaled(PARAMS / "table_4_4.awn", 20_000), 0.2)]
    print(f"medians of {repeats} run(s)")
    with tempfile.TemporaryDirectory() as folder:
        for name, cubes, size in cases:
            run(f"{name}_{size:g}", cubes, size, repeats, Path(folder))


if __name__ == "__main__":
    main()
