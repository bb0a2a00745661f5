"""The body wave exported two ways, measured side by side: four morph targets (what fishgen ships)
against a skin (a chain of spine joints, the body weighted to its two nearest joints, the fins
parented to joints, rotation keys per joint).

    python benchmarks/swim_export.py [--repeat 3] [--joints 8] [--bpy-python PATH] [--keep DIR]

For one BonyBream and for a 1,000-fish x 300-frame school it prints, per variant: file size, write
time (scene -> glb bytes -> file, median), whether the file is validator-clean, how far any fin
vertex that touches the body at rest strays from the body over the clip (fishgen's posing, which
does both morphs and skins), and the tail tip's peak-to-peak amplitude against the wave's. With
--bpy-python (a Python with Blender's `bpy`, see docs/clients.md) Blender imports each single-fish
file and the tail tip is measured from Blender's own evaluated mesh over the clip.
The skin variant lives here only: it is the road not taken (docs/decisions.md).
"""
from __future__ import annotations

import argparse
import json
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

from fishgen.assembly.fish import build_fish  # noqa: E402
from fishgen.exchange.gltf import glb_bytes  # noqa: E402
from fishgen.geometry.body_wave import BodyWave, integrate_phase  # noqa: E402
from fishgen.scene.model import Channel, Node, Sampler, Scene, Skin  # noqa: E402
from fishgen.scene.pose import bounds, deformed, pose  # noqa: E402
from fishgen.species.parser import load_species  # noqa: E402

SPECIES = ROOT / "params" / "bonybream.txt"
WAVE = BodyWave()


# ---------------------------------------------------------------- the skin variant
def _strip_morphs(scene: Scene) -> None:
    for mesh in scene.meshes:
        mesh.weights = []
        for prim in mesh.primitives:
            prim.targets = []
    for clip in scene.clips:
        clip.channels = [c for c in clip.channels if c.path != "weights"]


def _skin_weights(local_z: np.ndarray, nose: float, length: float,
                  joints: int) -> tuple[np.ndarray, np.ndarray]:
    """JOINTS_0 and WEIGHTS_0 blending each vertex between the two joints around it."""
    x = np.clip((nose - local_z) / length, 0.0, 1.0) * joints - 0.5
    lower = np.clip(np.floor(x), 0, joints - 1).astype(np.int64)
    upper = np.minimum(lower + 1, joints - 1)
    t = np.clip(x - lower, 0.0, 1.0)
    single = lower == upper
    joints_0 = np.zeros((len(x), 4), np.uint8)
    weights_0 = np.zeros((len(x), 4), np.float32)
    weights_0[:, 0], weights_0[:, 1] = np.where(single, 1.0, 1.0 - t), np.where(single, 0.0, t)
    joints_0[:, 0], joints_0[:, 1] = lower, np.where(weights_0[:, 1] > 0, upper, 0)
    return joints_0, weights_0


def skinned_fish(scene: Scene, joints: int, fish_root: int, phase: np.ndarray, times: np.ndarray,
                 length: float, weighted: set[int]) -> None:
    """Turn one fish (its root node ``fish_root``) into a skinned fish in place: a joint chain under
    the root; every part that does not swing on its own (body, dorsal, anal, tail fin) moved to the
    scene's roots with a skin (glTF ignores a skinned mesh's own transform; the validator wants it
    at the root), weighted to the two joints around each vertex; swinging fins parented to the joint
    ahead of their pivot. ``phase``/``times``: the wave's phase keys. ``weighted``: meshes already
    given joints (shared by the fish of a school)."""
    clip = scene.clips[0]
    swinging = {c.node for c in clip.channels if c.path == "rotation"}
    parts = list(scene.nodes[fish_root].children)

    def local(node: int) -> np.ndarray:
        """Rest positions in the fish's frame (fishgen's parts are only translated at rest)."""
        prim = scene.meshes[scene.nodes[node].mesh].primitives[0]
        return prim.positions.astype(np.float64) + np.asarray(scene.nodes[node].translation)

    nose = max(float(local(p)[:, 2].max()) for p in parts)
    stations = np.linspace(0.0, 1.0, joints + 1)
    joint_z = nose - (stations[:-1] + 0.5 / joints) * length    # a joint in the middle of its segment
    chain, parent, above = [], fish_root, 0.0
    for j in range(joints):
        chain.append(scene.add_node(Node(name=f"spine{j}", translation=(0.0, 0.0, joint_z[j] - above)),
                                    parent=parent))
        parent, above = chain[-1], joint_z[j]
    ibm = np.tile(np.eye(4), (joints, 1, 1))
    ibm[:, 2, 3] = -joint_z
    scene.skins.append(Skin(f"spine_{fish_root}", chain, ibm, skeleton=chain[0]))
    skin = len(scene.skins) - 1
    kept = [chain[0]]
    for part in parts:
        node = scene.nodes[part]
        if part in swinging:                      # under the joint whose segment holds the pivot
            z = node.translation[2]
            j = int(np.clip(np.searchsorted(-joint_z, -z) , 0, joints - 1))
            scene.nodes[chain[j]].children.append(part)
            scene.nodes[part] = replace(node, translation=(node.translation[0], node.translation[1],
                                                           z - joint_z[j]))
            continue
        prim = scene.meshes[node.mesh].primitives[0]
        if node.mesh not in weighted:
            prim.attributes["JOINTS_0"], prim.attributes["WEIGHTS_0"] = _skin_weights(
                local(part)[:, 2], nose, length, joints)
            weighted.add(node.mesh)
        scene.nodes[part] = replace(node, skin=skin, translation=(0.0, 0.0, 0.0))
        scene.roots.append(part)
    scene.nodes[fish_root].children = kept
    # joint angles that put each joint, and the tail tip, on the wave's midline
    along = np.append(nose - joint_z, length) / length                       # joints' x, then the tip
    h = WAVE.displacement(along[None, :], phase[:, None]) * length          # (K, J + 1)
    absolute = -np.arctan2(np.diff(h, axis=1), np.diff(along)[None, :] * length)
    relative = np.diff(np.concatenate([np.zeros((len(phase), 1)), absolute], axis=1), axis=1)
    quats = np.zeros((len(phase), joints, 4), np.float32)
    quats[..., 1], quats[..., 3] = np.sin(relative / 2), np.cos(relative / 2)
    first = np.zeros((len(phase), 3), np.float32)
    first[:, 0] = h[:, 0]
    first[:, 2] = joint_z[0]
    keys = times.astype(np.float32)
    clip.channels.append(Channel(chain[0], "translation", Sampler(keys, first)))
    for j in range(joints):
        clip.channels.append(Channel(chain[j], "rotation", Sampler(keys, quats[:, j])))


def single_fish(variant: str, joints: int) -> Scene:
    fish = build_fish(load_species(SPECIES))
    if variant == "skin":
        swim = fish.clip("swim")
        weights = next(c for c in swim.channels if c.path == "weights").sampler
        w = np.asarray(weights.values, np.float64)
        phase = np.unwrap(np.arctan2(w[:, 3] - w[:, 2], w[:, 0] - w[:, 1]))
        lo, hi = bounds(fish)
        _strip_morphs(fish)
        skinned_fish(fish, joints, fish.roots[0], phase, np.asarray(weights.times, np.float64),
                     float(hi[2] - lo[2]), set())
    return fish


def school(variant: str, joints: int, count: int, frames: int) -> Scene:
    from school import school_config

    from fishgen.school.bake import bake
    from fishgen.school.model import Group
    from fishgen.school.simulate import simulate

    fish = build_fish(load_species(SPECIES))
    lo, hi = bounds(fish)
    length = float(hi[2] - lo[2])
    config = replace(school_config(count, frames), groups=(Group("bonybream", count, length, 1.0),))
    tracks = simulate(config)
    lengths = np.full(count, length) * tracks.scale
    scene = bake([fish], tracks, body_lengths=lengths)
    if variant == "skin":
        times = np.asarray(tracks.times, np.float64)
        speed = np.linalg.norm(tracks.velocities, axis=2) / lengths[None]
        phases = integrate_phase(WAVE.frequency(speed), float(times[1] - times[0]),
                                 np.random.default_rng(0).uniform(0, 2 * np.pi, count))
        _strip_morphs(scene)
        weighted: set[int] = set()
        for i, root in enumerate(list(scene.roots)):
            skinned_fish(scene, joints, root, phases[:, i], times, float(lengths[i]), weighted)
    return scene


# ---------------------------------------------------------------- measures
def fin_gap(scene: Scene, samples: int = 49) -> float:
    """Largest distance (fraction of the body length) from the body surface of a fin vertex that
    touches the body at rest, over the clip, for the first fish."""
    import trimesh

    drawn = dict(scene.drawn())
    names = {i: n.name for i, n in enumerate(scene.nodes)}
    body = next(i for i in drawn if names[i] == "body")
    fins = [i for i in drawn if names[i] != "body"][:8]
    lo, hi = bounds(scene)
    length = float(hi[2] - lo[2])
    rest = pose(scene)
    rest_body = trimesh.Trimesh(deformed(scene, body, drawn[body], rest)[0], drawn[body].indices,
                                process=False)
    touching = {}
    for f in fins:
        _, d, _ = trimesh.proximity.closest_point(rest_body, deformed(scene, f, drawn[f], rest)[0])
        touching[f] = np.flatnonzero(d < 1e-3 * length)
    clip = scene.clips[0]
    worst = 0.0
    for t in np.linspace(0.0, min(clip.duration, 3.2), samples):
        posed = pose(scene, float(t), clip)
        surface = trimesh.Trimesh(deformed(scene, body, drawn[body], posed)[0], drawn[body].indices,
                                  process=False)
        for f, idx in touching.items():
            if len(idx):
                _, d, _ = trimesh.proximity.closest_point(surface,
                                                          deformed(scene, f, drawn[f], posed)[0][idx])
                worst = max(worst, float(d.max()))
    return worst / length


def tail_amplitude(scene: Scene, samples: int = 200) -> float:
    """Peak-to-peak lateral travel of the tail tip over one loop, in body lengths (fishgen's posing)."""
    drawn = dict(scene.drawn())
    lo, hi = bounds(scene)
    length = float(hi[2] - lo[2])
    clip = scene.clips[0]
    xs = []
    for t in np.linspace(0.0, clip.duration, samples):
        posed = pose(scene, float(t), clip)
        points = np.concatenate([deformed(scene, n, p, posed)[0] for n, p in drawn.items()])
        xs.append(points[np.argmin(points[:, 2]), 0])
    return float(np.ptp(xs)) / length


def write_time(scene: Scene, path: Path, repeat: int) -> float:
    runs = []
    for _ in range(repeat):
        start = time.perf_counter()
        path.write_bytes(glb_bytes(scene))
        runs.append(time.perf_counter() - start)
    return statistics.median(runs)


def validator(path: Path) -> str:
    proc = subprocess.run(["node", str(ROOT / "tools" / "validate_gltf.mjs"), str(path)], cwd=ROOT,
                          capture_output=True, text=True)
    if proc.returncode != 0 and not proc.stdout:
        return "validator unavailable"
    report = json.loads(proc.stdout)[0]
    return f"{report['numErrors']} errors, {report['numWarnings']} warnings"


def blender_tail(bpy_python: str, path: Path) -> str:
    proc = subprocess.run([bpy_python, str(ROOT / "tools" / "blender_tail.py"), str(path)],
                          capture_output=True, text=True, timeout=600)
    if proc.returncode != 0:
        return f"blender failed: {proc.stderr.strip().splitlines()[-1:]}"
    return proc.stdout.strip().splitlines()[-1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--joints", type=int, default=8)
    parser.add_argument("--count", type=int, default=1000)
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--bpy-python", default=None)
    parser.add_argument("--keep", type=Path, default=None, help="keep the files in this folder")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="fishgen-swim-") as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        print(f"body wave export, morph targets vs a skin of {args.joints} joints (median of {args.repeat})")
        print(f"expected tail peak-to-peak: {WAVE.tail_peak_to_peak:.3f} body lengths")
        print()
        print(f"{'variant':8} {'file':28} {'size':>10} {'write s':>8} {'fin gap':>8} "
              f"{'tail p-p':>9}  validator")
        for variant in ("morph", "skin"):
            fish = single_fish(variant, args.joints)
            path = folder / f"fish-{variant}.glb"
            seconds = write_time(fish, path, args.repeat)
            print(f"{variant:8} {'one BonyBream':28} {path.stat().st_size:10,} {seconds:8.3f} "
                  f"{fin_gap(fish):8.2%} {tail_amplitude(fish):9.3f}  {validator(path)}")
            if args.bpy_python:
                print(f"{'':8} Blender: {blender_tail(args.bpy_python, path)}")
        for variant in ("morph", "skin"):
            scene = school(variant, args.joints, args.count, args.frames)
            path = folder / f"school-{variant}.glb"
            seconds = write_time(scene, path, args.repeat)
            label = f"{args.count:,} fish x {args.frames} frames"
            print(f"{variant:8} {label:28} {path.stat().st_size:10,} {seconds:8.3f} "
                  f"{fin_gap(scene, 13):8.2%} {'':>9}  {validator(path)}")


if __name__ == "__main__":
    main()
