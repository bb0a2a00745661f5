"""Speed of `fishgen school`: the simulation beside Mesa's boid flockers, a 10,000-fish run, the bake
and the whole command, in one run.

    python benchmarks/school.py [--repeat 3] [--quick] [--command-repeat 7]

Issue 23: the whole command as a user runs it (a subprocess: start, imports, species, simulation,
measures, bake, write) at 1,000 fish for 100 and for 600 frames, alternating, beside the
simulation alone at the same sizes and Mesa's boid flockers at 1,000 agents in the same run. The
target: the command's marginal cost per fish-frame, (T(600) - T(100)) / (1,000 x 500), is at most
1/50 of Mesa's cost per agent-step; the same through `fishgen batch` (one [[school]] job, -j 1).
Each stage's share of the 600-frame command is measured in a child process doing what the
command does.

Targets (issue 9, section 5): fishgen's boids at least 100x Mesa's fish-steps per second at 1,000
fish; 10,000 fish x 1,000 frames simulated in under 20 s on a 2-core machine; 1,000 fish x 300
frames with fins baked and written as glb in under 1 s, in under 10 MB. Issue 10: the same bake
with the body wave (every fish's four morph weights keyed every frame) under 1.5 s and 15 MB.
Prints medians over --repeat runs, one row each. A fish-step is one fish moved by one frame: a run
of F frames is F - 1 steps (frame 0 is the start layout). Mesa is a benchmark-only dependency:
pip install "mesa[network]>=3,<4". `--quick` is a smoke run with small sizes.

Mesa runs in two spaces. The target is judged in the issue's: the example's own 100 x 100 space
whatever the number of agents (Mesa's default width and height; this is the set-up in which it
"manages about 9 steps/s at 1,000 agents", as the issue says). The second keeps the example's
density (100 agents per 100 x 100, the space grown with N): each agent then sees about 3 others
instead of about 30, and Mesa runs faster. Both ratios are printed.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

BODY_LENGTH = 0.34   # metres, about BonyBream's
SPECIES = ROOT / "params" / "bonybream.txt"
MESA_HINT = "mesa: not installed (pip install 'mesa[network]>=3,<4')"
MESA_BUDGET = 60.0   # seconds: a Mesa size whose steps would take longer than this is skipped


def school_config(count: int, frames: int, model: str = "boids"):
    """One BonyBream-sized group in the region `fishgen school` gives it by default."""
    from fishgen.school.model import Group, SchoolConfig
    from fishgen.school.run import DEFAULT_BOUNDS_BODY_LENGTHS

    half = DEFAULT_BOUNDS_BODY_LENGTHS * BODY_LENGTH * max(1.0, count ** (1 / 3))
    return SchoolConfig(groups=(Group("bonybream", count, BODY_LENGTH, 1.0),), model=model,  # type: ignore[arg-type]
                        frames=frames, seed=1, bounds=((-half, -half / 3, -half), (half, half / 3, half)))


def time_fishgen(count: int, frames: int, model: str, repeat: int) -> list[float]:
    from fishgen.school.simulate import simulate

    config = school_config(count, frames, model)
    runs = []
    for _ in range(repeat):
        start = time.perf_counter()
        simulate(config)
        runs.append(time.perf_counter() - start)
    return runs


def mesa_model():
    try:
        from mesa.examples.basic.boid_flockers.model import BoidFlockers
    except ImportError:
        return None
    return BoidFlockers


MESA_SPACES = {"issue": "mesa, space 100", "density": "mesa, space grown"}  # row names


def mesa_width(count: int, space: str) -> float:
    """The side of Mesa's square space: the example's 100, or grown to keep its density."""
    return 100.0 if space == "issue" else 100 * (count / 100) ** 0.5


def time_mesa(model_class, count: int, steps: int, repeat: int, width: float) -> list[float] | None:
    """Seconds of `steps` steps (model construction not counted); None when over MESA_BUDGET."""
    runs = []
    for k in range(repeat):
        model = model_class(population_size=count, width=width, height=width, vision=10, seed=1)
        start = time.perf_counter()
        for s in range(steps):
            model.step()
            if k == 0 and s == 0 and (time.perf_counter() - start) * steps > MESA_BUDGET:
                return None
        runs.append(time.perf_counter() - start)
        if k == 0 and runs[0] * repeat > MESA_BUDGET:
            break  # one run is all the budget allows
    return runs


def big_run(count: int, frames: int) -> tuple[float, float, float]:
    """(simulate s, process wall s, peak RSS MiB) of one child process simulating count x frames."""
    code = (f"import sys, time; sys.path[:0] = [{str(ROOT)!r}, {str(ROOT / 'benchmarks')!r}]\n"
            "from school import school_config\n"
            "from fishgen.school.simulate import simulate\n"
            f"config = school_config({count}, {frames})\n"
            "start = time.perf_counter(); tracks = simulate(config)\n"
            "print(time.perf_counter() - start)\n")
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        start = time.perf_counter()
        proc = subprocess.Popen([sys.executable, "-c", code], stdout=out, stderr=err, cwd=ROOT)
        _, status, usage = os.wait4(proc.pid, 0)
        elapsed = time.perf_counter() - start
        out.seek(0)
        err.seek(0)
        if status != 0:
            raise SystemExit(f"failed: {count} x {frames} simulation\n{err.read().decode()}")
        simulated = float(out.read().decode().split()[-1])
    return simulated, elapsed, usage.ru_maxrss / 1024


def bake_run(count: int, frames: int, repeat: int, folder: Path, swim: str = "body"):
    """Median seconds of bake, glb_bytes and writing the file, and the file's size in bytes;
    ``swim``: `body` (the body wave and fins, the default) or `fins` (rigid bodies)."""
    import numpy as np

    from fishgen.assembly.fish import build_fish
    from fishgen.exchange.gltf import glb_bytes
    from fishgen.scene.pose import bounds
    from fishgen.school.bake import bake
    from fishgen.school.model import Group
    from fishgen.school.simulate import simulate
    from fishgen.species.parser import load_species

    fish = build_fish(load_species(SPECIES), swim=swim)
    lo, hi = bounds(fish)
    length = float(hi[2] - lo[2])
    config = replace(school_config(count, frames), groups=(Group("bonybream", count, length, 1.0),))
    tracks = simulate(config)
    lengths = np.full(count, length) * tracks.scale
    path = folder / "school.glb"
    bakes, encodes, writes = [], [], []
    for _ in range(repeat):
        start = time.perf_counter()
        scene = bake([fish], tracks, body_lengths=lengths)
        bakes.append(time.perf_counter() - start)
        start = time.perf_counter()
        data = glb_bytes(scene)
        encodes.append(time.perf_counter() - start)
        start = time.perf_counter()
        path.write_bytes(data)
        writes.append(time.perf_counter() - start)
    med = statistics.median
    return med(bakes), med(encodes), med(writes), path.stat().st_size


def command_run(count: int, repeat: int, folder: Path, frames: int | None) -> list[float]:
    cmd = [sys.executable, "-m", "fishgen", "school", str(SPECIES), "--count", str(count),
           "-o", str(folder / "x.glb")] + ([] if frames is None else ["--frames", str(frames)])
    runs = []
    for _ in range(repeat):
        start = time.perf_counter()
        proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, cwd=ROOT)
        runs.append(time.perf_counter() - start)
        if proc.returncode != 0:
            raise SystemExit(f"failed: {' '.join(cmd)}\n{proc.stderr.decode()}")
    return runs


COMMAND_FISH = 1000
COMMAND_FRAMES = (100, 600)


def command_pair(count: int, frames: tuple[int, int], repeat: int, folder: Path) -> dict[int, list[float]]:
    """`fishgen school` at both frame counts, alternating (so drift on a shared machine hits both)."""
    runs: dict[int, list[float]] = {f: [] for f in frames}
    for _ in range(repeat):
        for f in frames:
            runs[f] += command_run(count, 1, folder, f)
    return runs


def batch_pair(count: int, frames: tuple[int, int], repeat: int, folder: Path) -> dict[int, list[float]]:
    """The same school as a `fishgen batch` job (-j 1: in the command's own process; --force: every
    run builds it), at both frame counts, alternating."""
    runs: dict[int, list[float]] = {f: [] for f in frames}
    for f in frames:
        (folder / f"school{f}.toml").write_text(
            f'out = "out{f}"\n\n[[school]]\ninput = "{SPECIES.as_posix()}"\noutput = "school.glb"\n'
            f"count = {count}\nframes = {f}\nseed = 1\n", encoding="utf-8")
    for _ in range(repeat):
        for f in frames:
            cmd = [sys.executable, "-m", "fishgen", "batch", str(folder / f"school{f}.toml"), "-j", "1",
                   "--force", "--quiet"]
            start = time.perf_counter()
            proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, cwd=ROOT)
            runs[f].append(time.perf_counter() - start)
            if proc.returncode != 0:
                raise SystemExit(f"failed: {' '.join(cmd)}\n{proc.stderr.decode()}")
    return runs


def simulation_pair(count: int, frames: tuple[int, int], repeat: int) -> dict[int, list[float]]:
    """The simulation alone, as `fishgen school` sets it up (BonyBream's brain and length), in process."""
    from fishgen.school.run import plan_school
    from fishgen.school.scene_file import SceneFile, SpeciesEntry
    from fishgen.school.simulate import simulate

    runs: dict[int, list[float]] = {f: [] for f in frames}
    configs = {f: plan_school(SceneFile(species=(SpeciesEntry(SPECIES, count),), frames=f, seed=1),
                              swim="fins")[0] for f in frames}
    for _ in range(repeat):
        for f in frames:
            start = time.perf_counter()
            simulate(configs[f])
            runs[f].append(time.perf_counter() - start)
    return runs


STAGES_CODE = """
import sys, time, json
start = time.perf_counter()
from pathlib import Path
sys.path[:0] = [{root!r}]
from fishgen.school.run import plan_school, warmup_frames, EXTRAS_KEY
from fishgen.school.scene_file import SceneFile, SpeciesEntry
from fishgen.school.simulate import simulate
from fishgen.school.bake import bake
from fishgen.exchange import export
from fishgen.school.metrics import PRINTED, measures, summary_table, format_table
import numpy as np
marks = {{"start and imports": time.perf_counter()}}
scene = SceneFile(species=(SpeciesEntry(Path({species!r}), {count}),), frames={frames}, seed=1)
config, fishes, _ = plan_school(scene)
marks["species built"] = time.perf_counter()
tracks = simulate(config)
marks["simulation"] = time.perf_counter()
warm = warmup_frames(config.frames, config.fps)
per_frame = measures(tracks, [g.body_length for g in config.groups], start=warm, only=PRINTED)
table = format_table(summary_table(per_frame, warm, ["bonybream"]), "")
marks["measures and summary"] = time.perf_counter()
lengths = np.array([config.groups[g].body_length for g in tracks.group]) * tracks.scale
school = bake(fishes, tracks, body_lengths=lengths, seed=1)
marks["bake"] = time.perf_counter()
export(school, Path({out!r}))
marks["glb written"] = time.perf_counter()
print(json.dumps({{"start": start, "marks": marks}}))
"""


def stages(count: int, frames: int, folder: Path) -> list[tuple[str, float]]:
    """Seconds of each stage of a school's whole run, in a child process doing what the command does
    (the interpreter's own start-up is not counted: the command's wall time holds it)."""
    code = STAGES_CODE.format(root=str(ROOT), species=str(SPECIES), count=count, frames=frames,
                              out=str(folder / "stages.glb"))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, cwd=ROOT)
    if proc.returncode != 0:
        raise SystemExit(f"failed: stages\n{proc.stderr.decode()}")
    import json

    data = json.loads(proc.stdout.decode().splitlines()[-1])
    last, out = data["start"], []
    for name, when in data["marks"].items():
        out.append((name, when - last))
        last = when
    return out


def big_school_measures(count: int, frames: int) -> str:
    """Polarization, groups and overlaps of a default BonyBream school of `count` fish after its
    warm-up, as `fishgen school` would print them (a child process, as big_run)."""
    code = (f"import sys; sys.path[:0] = [{str(ROOT)!r}]\n"
            "from pathlib import Path\n"
            "from fishgen.school.run import plan_school, warmup_frames\n"
            "from fishgen.school.scene_file import SceneFile, SpeciesEntry\n"
            "from fishgen.school.simulate import simulate\n"
            "from fishgen.school.metrics import measures, summary\n"
            f"scene = SceneFile(species=(SpeciesEntry(Path({str(SPECIES)!r}), {count}),), frames={frames})\n"
            "config, _, _ = plan_school(scene, swim='fins')\n"
            "tracks = simulate(config)\n"
            "warm = warmup_frames(config.frames, config.fps)\n"
            "s = summary(measures(tracks, [config.groups[0].body_length], start=warm,\n"
            "            only=('polarization', 'groups', 'overlaps', 'nearest_neighbour')), warm)\n"
            "p, least = s['polarization'][0], s['polarization_least'][0]\n"
            "print(f'polarization mean {p:.2f} least {least:.2f}, '\n"
            "      f'groups at most {s[\"groups_peak\"][0]:.0f}, '\n"
            "      f'overlapping pairs at most {s[\"overlaps_peak\"]:.0f}, '\n"
            "      f'nearest neighbour {s[\"nearest_neighbour\"]:.2f} body lengths')\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, cwd=ROOT)
    if proc.returncode != 0:
        raise SystemExit(f"failed: {count}-fish measures\n{proc.stderr.decode()}")
    return proc.stdout.decode().strip()


def marginal(runs: dict[int, list[float]], count: int) -> float:
    """Seconds per fish-frame between the two frame counts, by medians."""
    (f0, r0), (f1, r1) = sorted(runs.items())
    return (statistics.median(r1) - statistics.median(r0)) / (count * (f1 - f0))


def verdict(ok: bool) -> str:
    return "met" if ok else "NOT met"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="smoke run: small sizes, under 20 s")
    parser.add_argument("--command-repeat", type=int, default=7,
                        help="runs of each whole command (and batch) per frame count  [default: 7]")
    args = parser.parse_args()
    repeat = max(1, args.repeat)
    if args.quick:
        sizes = ((100, 60, 20), (1000, 30, 3))          # (fish, fishgen frames, Mesa steps)
        big, baked, command, command_frames = (1000, 100), (100, 60), 20, 30
        whole_fish, whole_frames = 200, (20, 60)
    else:
        sizes = ((100, 300, 100), (1000, 300, 20), (10000, 100, 3))
        big, baked, command, command_frames = (10000, 1000), (1000, 300), 200, None
        whole_fish, whole_frames = COMMAND_FISH, COMMAND_FRAMES
    command_repeat = max(1, args.command_repeat if not args.quick else 1)

    import numpy
    import scipy

    BoidFlockers = mesa_model()
    versions = f"numpy {numpy.__version__}, scipy {scipy.__version__}"
    if BoidFlockers is not None:
        import mesa
        versions += f", mesa {mesa.__version__}"
    print(f"fishgen school benchmark{' (--quick)' if args.quick else ''}: {os.cpu_count()} cores, "
          f"Python {sys.version.split()[0]}, {versions}")
    print()
    print(f"{'simulation':24} {'fish':>6} {'steps':>6} {'median s':>9} {'min s':>7} {'runs':>4} "
          f"{'fish-steps/s':>13} {'boids/it':>8}")
    ratio_at: dict[tuple[int, str], float] = {}  # fishgen boids / Mesa, per (fish, Mesa's space)

    def row(name, count, steps, runs, rate, versus=""):
        print(f"{name:24} {count:6,} {steps:6,} {statistics.median(runs):9.3f} {min(runs):7.3f} "
              f"{len(runs):4} {rate:13,.0f} {versus:>8}")

    for count, frames, steps in sizes:
        fish = {model: time_fishgen(count, frames, model, repeat) for model in ("boids", "pso")}
        rates = {model: count * (frames - 1) / statistics.median(runs) for model, runs in fish.items()}
        for model, runs in fish.items():
            row(f"fishgen {model}", count, frames - 1, runs, rates[model])
        for space, name in MESA_SPACES.items():
            if BoidFlockers is None:
                print(f"{name:24} {count:6,}   " + MESA_HINT)
                continue
            mruns = time_mesa(BoidFlockers, count, steps, 1 if count >= 10000 else repeat,
                              mesa_width(count, space))
            if mruns is None:
                print(f"{name:24} {count:6,} {steps:6,}   skipped: {steps} steps over {MESA_BUDGET:.0f} s")
                continue
            mrate = count * steps / statistics.median(mruns)
            ratio_at[(count, space)] = rates["boids"] / mrate
            row(name, count, steps, mruns, mrate, f"{rates['boids'] / mrate:,.0f}x")

    mesa_step = None      # Mesa's seconds per agent-step at 1,000 agents in the space
    if BoidFlockers is not None and not args.quick:
        mruns = time_mesa(BoidFlockers, 1000, 20, repeat, mesa_width(1000, "issue"))
        mesa_step = None if mruns is None else statistics.median(mruns) / (1000 * 20)
    sim_s, wall_s, peak = big_run(*big)
    big_numbers = big_school_measures(big[0], 300 if not args.quick else 60)
    with tempfile.TemporaryDirectory(prefix="fishgen-bench-") as tmp:
        folder = Path(tmp)
        bake_s, glb_s, write_s, size = bake_run(*baked, repeat, folder, swim="fins")
        wave_bake_s, wave_glb_s, wave_write_s, wave_size = bake_run(*baked, repeat, folder, swim="body")
        cmd_runs = command_run(command, repeat, folder, command_frames)
        whole = command_pair(whole_fish, whole_frames, command_repeat, folder)
        batched = batch_pair(whole_fish, whole_frames, command_repeat, folder)
        alone = simulation_pair(whole_fish, whole_frames, command_repeat)
        shares = stages(whole_fish, whole_frames[1], folder)

    print()
    print(f"{big[0]:,} fish x {big[1]:,} frames (boids, child process): simulate {sim_s:.2f} s, "
          f"process {wall_s:.2f} s, peak RSS {peak:,.0f} MiB")
    print(f"{big[0]:,} BonyBream, default school of 300 frames, after the warm-up: {big_numbers}")
    for label, times, nbytes in (("with fins, rigid bodies", (bake_s, glb_s, write_s), size),
                                 ("with body wave and fins", (wave_bake_s, wave_glb_s, wave_write_s),
                                  wave_size)):
        print(f"bake {baked[0]:,} fish x {baked[1]:,} frames {label} (median of {repeat}): "
              f"bake {times[0]:.3f} s, glb_bytes {times[1]:.3f} s, write {times[2]:.3f} s, "
              f"together {sum(times):.3f} s, {nbytes / 1e6:.2f} MB")
    frames_note = "" if command_frames is None else f" --frames {command_frames}"
    print(f"fishgen school params/bonybream.txt --count {command}{frames_note}: median "
          f"{statistics.median(cmd_runs):.2f} s, min {min(cmd_runs):.2f} s ({len(cmd_runs)} runs)")

    print()
    print(f"whole command, {whole_fish:,} BonyBream (medians of {command_repeat} runs, the two sizes "
          "alternating; marginal cost between them):")
    print(f"{'':34} " + "  ".join(f"{f:>5} frames" for f in whole_frames)
          + "   per fish-frame    fish-frames/s")
    cost = {}
    for name, runs in (("fishgen school (subprocess)", whole), ("fishgen batch -j 1 (subprocess)", batched),
                       ("simulation alone (in process)", alone)):
        cost[name] = marginal(runs, whole_fish)
        cells = "  ".join(f"{statistics.median(runs[f]):6.2f} s  " for f in whole_frames)
        print(f"  {name:32} {cells} {cost[name] * 1e6:8.3f} us   {1 / cost[name]:14,.0f}")
    total = sum(sec for _, sec in shares)
    print(f"  stages of {whole_fish:,} x {whole_frames[1]} in one child process ({total:.2f} s): "
          + ", ".join(f"{name} {sec:.2f} s ({sec / total:.0%})" for name, sec in shares))
    if mesa_step is not None:
        print(f"  Mesa boid flockers, 1,000 agents, space 100: {mesa_step * 1e6:.1f} us per agent-step "
              f"({1 / mesa_step:,.0f} agent-steps/s)")

    print()
    print("targets (issue 9)" + (" -- --quick sizes, not the targets' sizes" if args.quick else ""))
    if (1000, "issue") in ratio_at:
        ratio = ratio_at[(1000, "issue")]
        other = ratio_at.get((1000, "density"))
        also = "" if other is None else f" (with Mesa's space grown to keep its density: {other:,.0f}x)"
        print(f"  boids >= 100x Mesa at 1,000 fish, Mesa in the issue's 100 x 100 space: "
              f"{ratio:,.0f}x  {verdict(ratio >= 100)}{also}")
    else:
        print("  boids >= 100x Mesa at 1,000 fish: not measured (" +
              ("mesa not installed)" if BoidFlockers is None else "Mesa skipped)"))
    print(f"  {big[0]:,} x {big[1]:,} simulated under 20 s: {sim_s:.2f} s  {verdict(sim_s < 20)}")
    written, together = glb_s + write_s, bake_s + glb_s + write_s
    print(f"  bake {baked[0]:,} x {baked[1]:,} written (glb_bytes + write) under 1 s: {written:.3f} s  "
          f"{verdict(written < 1)}; with bake {together:.3f} s  {verdict(together < 1)}")
    print(f"  bake under 10 MB: {size / 1e6:.2f} MB  {verdict(size < 10e6)}")
    wave_total = wave_bake_s + wave_glb_s + wave_write_s
    print("targets (issue 10)")
    print(f"  bake {baked[0]:,} x {baked[1]:,} with body wave and fins under 1.5 s: {wave_total:.3f} s  "
          f"{verdict(wave_total < 1.5)}; under 15 MB: {wave_size / 1e6:.2f} MB  {verdict(wave_size < 15e6)}")
    print("targets (issue 23)")
    if mesa_step is None:
        print("  whole command >= 50x Mesa per fish-frame: not measured (" +
              ("--quick)" if args.quick else "mesa not installed or skipped)"))
    else:
        for name in ("fishgen school (subprocess)", "fishgen batch -j 1 (subprocess)"):
            ratio = mesa_step / cost[name]
            print(f"  {name}: marginal cost per fish-frame {ratio:,.0f}x Mesa's per agent-step "
                  f"(target 50x)  {verdict(ratio >= 50)}")
        print(f"  (the simulation alone: {mesa_step / cost['simulation alone (in process)']:,.0f}x)")
    sim_share = dict(shares).get("simulation", 0.0)
    measure_share = dict(shares).get("measures and summary", 0.0)
    print(f"  per-frame measures cost less than the simulation: {measure_share:.2f} s vs {sim_share:.2f} s  "
          f"{verdict(measure_share < sim_share)}")


if __name__ == "__main__":
    main()
