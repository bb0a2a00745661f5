"""Fish for game engines, measured (issue 24): levels of detail, two draw calls a fish, clips, shading,
compact keys.

    python benchmarks/engine.py [--repeat 5] [--count 1000] [--frames 300] [--fps-frames 30]
                                [--bpy-python PATH] [--keep DIR]

1. Levels: BonyBream at 32x24, 16x12 and 8x6, merged, every clip: per level its triangles, its side
   silhouette's IoU with the finest level's (at rest, and the least over the swim loop), the worst
   fin gap over every clip (fishgen's posing), its screen-coverage switch point, and the size of a
   glb holding that level alone; then the one glb holding all three.
2. Layouts, one BonyBream (swim clip): a node per part (today) against one merged skinned mesh:
   draw calls, file size, write time (scene -> glb bytes -> file, median), and what three.js and
   Blender play: the tail tip's peak-to-peak and the left pectoral fin's swing, against fishgen's posing.
3. A school of --count fish x --frames frames, baked in either layout (shared meshes, one node tree
   per fish: fishgen.assembly.instance), with and without --compact: size, write time, validator,
   the largest rotation error compact adds, and the frame rate three.js r0.187 draws it at in headless
   Chromium (software WebGL: compare the layouts, not the absolute numbers).
4. Clips: each clip's defining motion from fishgen's posing, and the worst normal error (fishgen and
   three.js) against the posed triangles' own normals.
"""
from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "benchmarks")]

from fishgen.assembly.clips import C_START_DEGREES, TURN_DEGREES  # noqa: E402
from fishgen.assembly.compact import compact_clips  # noqa: E402
from fishgen.assembly.fish import make_fish  # noqa: E402
from fishgen.exchange.gltf import glb_bytes  # noqa: E402
from fishgen.scene.model import Scene  # noqa: E402
from fishgen.species.parser import load_species  # noqa: E402
from tests.assembly import engine_clients as ec  # noqa: E402

SPECIES = ROOT / "params" / "bonybream.txt"
LODS = ((32, 24), (16, 12), (8, 6))
CLIPS = ("swim", "idle", "sprint", "turn_left", "turn_right", "burst")
ROUNDS = 6


def validator(*paths: Path) -> list[str]:
    import json

    proc = subprocess.run(["node", str(ROOT / "tools" / "validate_gltf.mjs"), *map(str, paths)], cwd=ROOT,
                          capture_output=True, text=True)
    if proc.returncode != 0 and not proc.stdout:
        return ["validator unavailable"] * len(paths)
    return [f"{r['numErrors']} errors, {r['numWarnings']} warnings" for r in json.loads(proc.stdout)]


def write_times(scenes: list[tuple[Scene, Path]], repeat: int) -> list[float]:
    """Median seconds to write each scene (glb bytes, then the file), the scenes taken in turn
    ``repeat`` times so that the machine's load falls on all of them alike."""
    runs: list[list[float]] = [[] for _ in scenes]
    for _ in range(repeat):
        for k, (scene, path) in enumerate(scenes):
            start = time.perf_counter()
            path.write_bytes(glb_bytes(scene))
            runs[k].append(time.perf_counter() - start)
    return [statistics.median(r) for r in runs]


# ---------------------------------------------------------------- 1. levels
def levels(folder: Path, species) -> None:
    fish = make_fish(species, lods=LODS, merge=True, clips=CLIPS)
    whole = folder / "levels.glb"
    whole.write_bytes(glb_bytes(fish.scene))
    box = ec.frame_of(fish.scene)
    finest = ec.silhouette(fish.scene, box=box)
    swim = fish.scene.clip("swim").duration
    print("1. levels of detail: BonyBream --lods 32x24,16x12,8x6 --merge --clips " + ",".join(CLIPS))
    print(f"{'level':>6} {'sections':>9} {'triangles':>10} {'IoU rest':>9} {'IoU swim':>9} {'fin gap':>8} "
          f"{'coverage':>9} {'alone, bytes':>13}")
    for k, lv in enumerate(fish.facts.levels):
        scene = ec.level_scene(fish.scene, k)
        rest = ec.iou(finest, ec.silhouette(scene, box=box))
        over = min(ec.iou(ec.silhouette(fish.scene, t=float(t), clip="swim", box=box),
                          ec.silhouette(scene, t=float(t), clip="swim", box=box))
                   for t in np.linspace(0, swim, 9))
        parts = make_fish(species, lods=LODS, clips=CLIPS)  # fin gaps: per part (the layouts pose alike)
        gap = max(ec.fin_gap(ec.level_scene(parts.scene, k), c,
                             np.linspace(0, parts.scene.clip(c).duration, 9))
                  for c in CLIPS)
        alone = make_fish(species, lods=[(lv.bodies, lv.circles)], merge=True, clips=CLIPS)
        path = folder / f"level{k}.glb"
        path.write_bytes(glb_bytes(alone.scene))
        print(f"{'LOD' + str(k):>6} {f'{lv.bodies}x{lv.circles}':>9} {lv.triangles:10,} "
              f"{rest:9.3f} {over:9.3f} {gap:8.2%} {lv.coverage:9.4f} {path.stat().st_size:13,}")
    print(f"all three levels in one glb: {whole.stat().st_size:,} bytes; validator: {validator(whole)[0]}")
    print()


# ---------------------------------------------------------------- 2. one fish, two layouts
def layouts(folder: Path, species, repeat: int, bpy: str | None) -> None:
    print("2. one BonyBream (swim clip): a node per part against one merged skinned mesh")
    print(f"{'layout':8} {'draws':>5} {'bytes':>9} {'write s':>8}  "
          f"{'tail p-p (fishgen / three.js / Blender)':40} "
          f"{'fin swing deg (fishgen / three.js / Blender)'}")
    three = None
    reason = None
    try:
        from tests.clients.matrix import three_unavailable

        reason = three_unavailable()
        if reason is None:
            three = ec.ThreeEngine(folder)
    except Exception as err:  # noqa: BLE001 - reported
        reason = str(err)
    made = {merge: make_fish(species, merge=merge) for merge in (False, True)}
    paths = {merge: folder / f"fish-{'merged' if merge else 'parts'}.glb" for merge in made}
    took = dict(zip(made, write_times([(made[m].scene, paths[m]) for m in made], repeat), strict=True))
    for merge, fish in made.items():
        name, path, seconds = paths[merge].name, paths[merge], took[merge]
        probes = ec.probes(fish.scene)
        times = np.linspace(0.0, fish.scene.clip("swim").duration, 193)
        cells = []
        tracks = [ec.fishgen_play(fish.scene, "swim", times, probes.all()).probes]
        if three is not None:
            tracks.append(three.play(name, "swim", times, probes.all()).probes)
        if bpy:
            ec.BPY = bpy
            tracks.append(ec.blender_play(path, {"swim": times}, probes.all())["clips"]["swim"])
        for track in tracks:
            p = probes.split(track)
            cells.append((ec.peak_to_peak(p["tail"], probes.length),
                          np.ptp(ec.fin_swing(p["fin_tip"], p["fin_base"]))))
        tails = " / ".join(f"{a:.3f}" for a, _ in cells)
        fins = " / ".join(f"{b:.2f}" for _, b in cells)
        print(f"{'merged' if merge else 'parts':8} {fish.facts.draw_calls:5} {path.stat().st_size:9,} "
              f"{seconds:8.4f}  {tails:40} {fins}   {validator(path)[0]}")
    if three is not None:
        three.close()
    elif reason:
        print(f"(three.js: {reason})")
    print()


# ---------------------------------------------------------------- 3. schools
def school_tracks(count: int, frames: int, length: float):
    from school import school_config

    from fishgen.school.model import Group
    from fishgen.school.simulate import simulate

    config = replace(school_config(count, frames), groups=(Group("bonybream", count, length, 1.0),))
    return simulate(config)


def schools(folder: Path, species, count: int, frames: int, repeat: int, fps_frames: int) -> None:
    from fishgen.school.bake import bake, bake_instanced

    print(f"3. a school of {count:,} BonyBream x {frames} frames (the species' own level, swim)")
    fish = {merge: make_fish(species, merge=merge) for merge in (False, True)}
    tracks = school_tracks(count, frames, fish[False].facts.body_length)
    lengths = fish[False].facts.body_length * np.asarray(tracks.scale, np.float64)
    rows = [("today (fishgen.school.bake)", bake([fish[False].scene], tracks, body_lengths=lengths), None)]
    for merge in (False, True):
        for compact in (False, True):
            scene = bake_instanced([fish[merge].scene], tracks, body_lengths=lengths)
            error = compact_clips(scene) if compact else None
            rows.append((f"{'merged' if merge else 'parts'}{' --compact' if compact else ''}", scene, error))
    three = None
    try:
        from tests.clients.matrix import three_unavailable

        if three_unavailable() is None:
            three = ec.ThreeEngine(folder)
    except Exception:  # noqa: BLE001
        three = None
    files = [(scene, folder / ("school-" + label.split(" ")[0].replace("(", "")
                               + ("-compact" if "compact" in label else "") + ".glb"))
             for label, scene, _ in rows]
    took = write_times(files, repeat)
    written = [(label, path, seconds, error)
               for (label, _, error), (_, path), seconds in zip(rows, files, took, strict=True)]
    rates: dict[str, list[tuple[float, float]]] = {}
    draws: dict[str, int] = {}
    timed = [w for w in written if w[0] in ("parts", "merged")]   # compact keys change no frame's work
    if three is not None:          # the layouts in turn: the machine's load falls on both alike
        for _ in range(ROUNDS):
            for label, path, _, _ in timed:
                rate = three.frame_rate(path.name, fps_frames)
                rates.setdefault(label, []).append((rate["medianMs"], rate["mixerMs"]))
                draws[label] = rate["drawCalls"]
        three.close()
    print(f"{'layout':28} {'bytes':>12} {'write s':>8} {'rot err deg':>11} {'draws':>6} {'ms/frame':>9} "
          f"{'best':>6} {'mixer':>6} {'fps':>6}  validator")
    for label, path, seconds, error in written:
        frame = [r[0] for r in rates.get(label, [])]
        ms = statistics.median(frame) if frame else float("nan")
        best = min(frame) if frame else float("nan")
        mixer = statistics.median([r[1] for r in rates[label]]) if frame else float("nan")
        err = f"{error:.4f}" if error is not None else ""
        print(f"{label:28} {path.stat().st_size:12,} {seconds:8.3f} {err:>11} {draws.get(label, 0):6} "
              f"{ms:9.1f} {best:6.1f} {mixer:6.1f} {1000.0 / ms:6.2f}  {validator(path)[0]}")
    if rates:
        print(f"(ms/frame: the median over {fps_frames} frames of playing (three.js AnimationMixer) "
              f"and drawing the school, then the median and the best of {ROUNDS} runs taken in turn, "
              f"each in a fresh page; mixer: the playing alone. three.js r0.187, headless Chromium, "
              f"SwiftShader WebGL at 960x540)")
    print()


# ---------------------------------------------------------------- 4. clips and shading
def clips(folder: Path, species) -> None:
    print("4. clips (BonyBream, merged, from fishgen's posing), and the worst normal error over each clip")
    fish = make_fish(species, merge=True, clips=CLIPS)
    name = "clips.glb"
    (folder / name).write_bytes(glb_bytes(fish.scene))
    probes = ec.probes(fish.scene)
    three = None
    try:
        from tests.clients.matrix import three_unavailable

        if three_unavailable() is None:
            three = ec.ThreeEngine(folder)
    except Exception:  # noqa: BLE001
        three = None
    print(f"{'clip':10} {'seconds':>7} {'loop':>5} {'tail Hz':>8} {'tail p-p':>9} {'bend deg/BL':>12} "
          f"{'normals: fishgen body/fins':>27} {'three.js body/fins':>19}")
    for c in fish.facts.clips:
        times = np.linspace(0.0, c.seconds, 512 if c.loop else 2001, endpoint=not c.loop)
        played = ec.fishgen_play(fish.scene, c.name, times, probes.all())
        p = probes.split(played.probes)
        curvature = ec.bend_curvature(p["midline"], probes.length)
        if c.name.startswith("turn"):
            # the wave averages out
            bend = ec.bend_curvature(p["midline"].mean(axis=0)[None], probes.length)[0]
        elif c.name == "burst":
            bend = curvature.max()
        else:
            bend = 0.0
        sample = np.linspace(0.0, c.seconds, 17)
        errors = []
        for who in ("fishgen", "three.js"):
            if who == "three.js" and three is None:
                errors.append("n/a")
                continue
            run = (ec.fishgen_play(fish.scene, c.name, sample, np.zeros((0, 3))) if who == "fishgen"
                   else three.play(name, c.name, sample, np.zeros((0, 3))))
            worst = [max(ec.normal_error(pos[i], faces, nrm[i]).max() for i in range(len(sample)))
                     for faces, pos, nrm in run.meshes.values()]
            errors.append(" / ".join(f"{w:.2f}" for w in worst))
        print(f"{c.name:10} {c.seconds:7.3f} {'yes' if c.loop else 'once':>5} "
              f"{ec.frequency(p['tail'], times):8.2f} {ec.peak_to_peak(p['tail'], probes.length):9.3f} "
              f"{np.degrees(bend):12.1f} {errors[0]:>27} {errors[1]:>19}")
    print(f"(design: turns {TURN_DEGREES:g} deg per body length, burst peak C {C_START_DEGREES:g} deg)")
    if three is not None:
        three.close()
    print()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--count", type=int, default=1000)
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--fps-frames", type=int, default=10)
    parser.add_argument("--bpy-python", default=None)
    parser.add_argument("--keep", type=Path, default=None, help="keep the files in this folder")
    parser.add_argument("--only", default="1234", help="which sections to run (default 1234)")
    args = parser.parse_args()
    species = load_species(SPECIES)
    with tempfile.TemporaryDirectory(prefix="fishgen-engine-") as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        if "1" in args.only:
            levels(folder, species)
        if "2" in args.only:
            layouts(folder, species, args.repeat, args.bpy_python)
        if "3" in args.only:
            schools(folder, species, args.count, args.frames, args.repeat, args.fps_frames)
        if "4" in args.only:
            clips(folder, species)


if __name__ == "__main__":
    main()
