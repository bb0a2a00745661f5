"""Play a fishgen fish as three.js, Blender and fishgen's own posing do, and measure what each shows.

Each client gives the posed positions of chosen points ("probes", matched by rest position) and,
where it can, of every vertex with its normal; the measures (tail peak-to-peak and frequency, fin
swing, bend curvature, normal error) are computed here alike for all. Shared by the engine tests
(tests/assembly/test_engine_clients.py) and benchmarks/engine.py.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fishgen.geometry.mesh import area_normals
from fishgen.scene.model import Primitive, Scene
from fishgen.scene.pose import deformed, pose

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent / "engine"
BPY = next((p for p in (os.environ.get("FISHGEN_BPY_PYTHON"), "/tmp/bpyvenv/bin/python")
            if p and Path(p).is_file()), None)


# -- what to look at ------------------------------------------------------------------------------

def _drawn_parts(scene: Scene) -> list[tuple[str, int, Primitive]]:
    """(part name, node, primitive) of what the default scene draws; a merged fish's primitives are
    named body and fins."""
    out = []
    for node, prim in scene.drawn():
        name = scene.nodes[node].name
        if scene.nodes[node].skin is not None:
            name = "fins" if scene.materials[prim.material].name.endswith("fins") else "body"
        out.append((name.split("_LOD")[0], node, prim))
    return out


def part_points(scene: Scene, name: str) -> np.ndarray:
    """Rest world positions of part ``name`` (body, or a fin such as pectoral_fin_left) in either layout."""
    posed = pose(scene)
    for part, node, prim in _drawn_parts(scene):
        points = deformed(scene, node, prim, posed)[0]
        if part == name:
            return points
        if part == "fins" and name != "body":
            skin = scene.skins[scene.nodes[node].skin]
            joints = [scene.nodes[j].name.split("_LOD")[0] for j in skin.joints]
            if name in joints:
                return points[np.asarray(prim.attributes["JOINTS_0"])[:, 0] == joints.index(name)]
    raise KeyError(name)


@dataclass(frozen=True)
class Probes:
    """Rest positions (glTF axes, metres) of the points every client is asked about."""

    tail: np.ndarray            # the tail fin's tip (the rearmost vertex)
    midline: np.ndarray         # (m, 3) the top vertex of each body ring, nose to tail
    fin_tip: np.ndarray         # the left pectoral fin's vertex farthest from its hinge
    fin_base: np.ndarray        # (2, 3) the ends of its base line (its hinge)
    length: float               # nose to tail tip

    def all(self) -> np.ndarray:
        return np.vstack([self.tail[None], self.midline, self.fin_tip[None], self.fin_base])

    def split(self, tracks: np.ndarray) -> dict[str, np.ndarray]:
        """(T, P, 3) tracks of :meth:`all`'s points, by probe."""
        m = len(self.midline)
        return {"tail": tracks[:, 0], "midline": tracks[:, 1:1 + m], "fin_tip": tracks[:, 1 + m],
                "fin_base": tracks[:, 2 + m:4 + m]}


def probes(scene: Scene) -> Probes:
    body = part_points(scene, "body")
    everything = np.concatenate([deformed(scene, n, p, pose(scene))[0] for _, n, p in _drawn_parts(scene)])
    tail = everything[np.argmin(everything[:, 2])]
    length = float(np.ptp(everything[:, 2]))
    midline = []
    for z in np.unique(np.round(body[:, 2], 7))[::-1]:        # each ring (and apex), nose first
        ring = body[np.abs(body[:, 2] - z) < 1e-6]
        midline.append(ring[np.argmax(ring[:, 1])])
    fin = part_points(scene, "pectoral_fin_left")
    # the hinge: the fin's points that lie on the body (its base line), first and last along it
    d = np.min(np.linalg.norm(fin[:, None] - body[None], axis=2), axis=1)
    base = fin[d < 1e-6 * length] if np.count_nonzero(d < 1e-6 * length) >= 2 else fin[np.argsort(d)[:2]]
    ends = base[[np.argmax(base[:, 1]), np.argmin(base[:, 1])]]
    tip = fin[np.argmax(np.linalg.norm(fin - ends[0], axis=1))]
    return Probes(tail, np.array(midline), tip, ends, length)


# -- measures -------------------------------------------------------------------------------------

def peak_to_peak(track: np.ndarray, length: float) -> float:
    """Lateral (glTF X) travel of a point, in body lengths."""
    return float(np.ptp(track[:, 0])) / length


def frequency(track: np.ndarray, times: np.ndarray) -> float:
    """Beats per second of a point's lateral motion (upward crossings of its mean)."""
    x = track[:, 0] - track[:, 0].mean()
    ups = np.count_nonzero((x[:-1] < 0) & (x[1:] >= 0))
    return ups / float(times[-1] - times[0])


def bend_curvature(midline: np.ndarray, length: float) -> np.ndarray:
    """Per time, the midline's mean curvature (radians per body length) between its first and last
    chords, counted positive when it bends to the fish's left (+X): the turn from the chord of rings
    1-2 to that of the last two rings, over the path between the chords' middles. All seen from
    above (the top line also rises and falls)."""
    m = midline[..., [0, 2]]                               # (T, points, [X, Z])
    a, b = m[:, 2] - m[:, 1], m[:, -1] - m[:, -2]
    cross = a[:, 1] * b[:, 0] - a[:, 0] * b[:, 1]
    angle = np.arctan2(cross, np.sum(a * b, axis=1))
    chords = np.linalg.norm(np.diff(m[:, 1:], axis=1), axis=2)   # ring 1 onwards
    path = chords[:, 1:-1].sum(axis=1) + 0.5 * (chords[:, 0] + chords[:, -1])
    return -angle / (path / length)


def fin_swing(tip: np.ndarray, base: np.ndarray) -> np.ndarray:
    """Per time, the fin's angle about its hinge in degrees, from its rest pose (the first time's hinge
    frame is rebuilt at each time from the posed hinge, so the body's motion under it does not count)."""
    axis = base[:, 1] - base[:, 0]
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    arm = tip - base[:, 0]
    arm -= np.sum(arm * axis, axis=1, keepdims=True) * axis
    arm /= np.linalg.norm(arm, axis=1, keepdims=True)
    ref = arm[0]
    cross = np.cross(ref, arm)
    return np.degrees(np.arctan2(np.sum(cross * axis, axis=1), np.sum(arm * ref, axis=1)))


def normal_error(positions: np.ndarray, faces: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Degrees between each vertex's client normal and the area-weighted normal of its posed triangles
    (0 for a vertex no triangle uses: nothing is shaded with it)."""
    ref = area_normals(positions, faces)
    ok = np.linalg.norm(ref, axis=1) > 0
    ref = ref[ok] / np.linalg.norm(ref[ok], axis=1, keepdims=True)
    n = normals[ok] / np.linalg.norm(normals[ok], axis=1, keepdims=True)
    out = np.zeros(len(positions))
    out[ok] = np.degrees(np.arccos(np.clip(np.sum(ref * n, axis=1), -1.0, 1.0)))
    return out


def worst_normal_error(played: Played, keep: dict[str, np.ndarray] | None = None) -> dict[str, float]:
    """Per mesh, the largest :func:`normal_error` over the played times (of the vertices ``keep``
    selects, by mesh, where given)."""
    out = {}
    for name, (faces, positions, normals) in played.meshes.items():
        errors = np.array([normal_error(positions[i], faces, normals[i]) for i in range(len(positions))])
        if keep is not None:
            errors = errors[:, keep[name]]
        out[name] = float(errors.max()) if errors.size else 0.0
    return out


# -- clients -------------------------------------------------------------------------------------

@dataclass
class Played:
    """One clip as one client played it: per drawn mesh, faces and (T, n, 3) positions and normals,
    and the probes' (T, P, 3) tracks."""

    times: np.ndarray
    meshes: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray | None]]
    probes: np.ndarray


def fishgen_play(scene: Scene, clip: str, times: np.ndarray, probe_points: np.ndarray) -> Played:
    """fishgen's own posing (fishgen.scene.pose), which the preview renders."""
    drawn = _drawn_parts(scene)
    rest = np.concatenate([deformed(scene, n, p, pose(scene))[0] for _, n, p in drawn])
    nearest = [int(np.argmin(np.linalg.norm(rest - p, axis=1))) for p in probe_points]
    meshes: dict[str, tuple[np.ndarray, list, list]] = {f"{name}#{k}": (np.asarray(p.indices), [], [])
                                                        for k, (name, _, p) in enumerate(drawn)}
    tracks = []
    for t in times:
        posed = pose(scene, float(t), clip)
        everything = []
        for k, (name, node, prim) in enumerate(drawn):
            pos, nrm = deformed(scene, node, prim, posed)
            meshes[f"{name}#{k}"][1].append(pos)
            meshes[f"{name}#{k}"][2].append(nrm)
            everything.append(pos)
        tracks.append(np.concatenate(everything)[nearest])
    arrays = {k: (f, np.array(p), np.array(n)) for k, (f, p, n) in meshes.items()}
    return Played(times, arrays, np.array(tracks))


class ThreeEngine:
    """three.js r0.187 in headless Chromium (the client matrix's browser), playing files from ``folder``."""

    def __init__(self, folder: Path):
        from tests.clients.matrix import THREE_DIR, LocalBrowser

        self.browser = LocalBrowser({"/three/": THREE_DIR, "/harness/": HERE, "/assets/": folder})
        page = self.browser.page
        self.errors: list[str] = []
        page.on("pageerror", lambda e: self.errors.append(str(e)))
        page.goto(f"{self.browser.base}/harness/harness.html")
        page.wait_for_function("window.harnessReady === true", timeout=30_000)

    def play(self, name: str, clip: str, times: np.ndarray, probe_points: np.ndarray) -> Played:
        url = f"{self.browser.base}/assets/{name}"
        # as JSON text: Playwright's own serialisation of the same numbers (every vertex at every
        # time) took a second a call, the page's JSON.stringify a tenth; both give the same floats
        result = json.loads(self.browser.page.evaluate(
            "async ([u, c, t]) => JSON.stringify(await window.poseTracks(u, c, t))",
            [url, clip, [float(t) for t in times]]))
        if "error" in result:
            raise AssertionError(f"three.js: {result['error']}")
        meshes = {}
        everything, rest = [], []
        for k, m in enumerate(result["meshes"]):
            positions = np.array(m["positions"], float).reshape(len(times), -1, 3)
            normals = np.array(m["normals"], float).reshape(len(times), -1, 3)
            meshes[f"{m['name']}#{k}"] = (np.array(m["index"]).reshape(-1, 3), positions, normals)
            everything.append(positions)
            rest.append(np.array(m["rest"], float).reshape(-1, 3))
        allp, allr = np.concatenate(everything, axis=1), np.concatenate(rest)
        nearest = [int(np.argmin(np.linalg.norm(allr - p, axis=1))) for p in probe_points]
        self.last = result
        return Played(times, meshes, allp[:, nearest])

    def rest(self, name: str, clip: str) -> np.ndarray:
        """Every drawn vertex at the clip's start (to match probes against)."""
        return self.play(name, clip, np.array([0.0]), np.zeros((0, 3))).meshes

    def frame_rate(self, name: str, frames: int = 30, size: tuple[int, int] = (960, 540)) -> dict:
        """Milliseconds a frame of the whole file's animation takes to play and draw (a fresh page each
        time: nothing of one file's run stays for the next)."""
        page = self.browser.page
        page.goto(f"{self.browser.base}/harness/harness.html")
        page.wait_for_function("window.harnessReady === true", timeout=30_000)
        result = self.browser.page.evaluate("([u, f, w, h]) => window.schoolFrameRate(u, f, w, h)",
                                            [f"{self.browser.base}/assets/{name}", frames, *size])
        if "error" in result:
            raise AssertionError(f"three.js: {result['error']}")
        return result

    def close(self) -> None:
        self.browser.close()


class BabylonEngine:
    """Babylon.js (the client matrix's npm build) in headless Chromium, playing files from ``folder``
    (tests/clients/babylon_harness.js, ``poseMeshes``)."""

    def __init__(self, folder: Path):
        from tests.clients.babylon import BabylonClient

        self.client = BabylonClient(folder)

    def play(self, name: str, clip: str, times: np.ndarray) -> Played:
        """Every drawn mesh's posed positions and normals, as Babylon's CPU skinning and morphing give
        them."""
        self.client._clear()
        url = f"{self.client.base}/assets/{name}"
        result = json.loads(self.client.page.evaluate(
            "async ([u, c, t]) => JSON.stringify(await window.poseMeshes(u, c, t))",
            [url, clip, [float(t) for t in times]]))
        if "error" in result:
            raise AssertionError(f"Babylon.js: {result['error']}")
        problems = self.client._problems()
        if problems:
            raise AssertionError(f"Babylon.js: {problems[:3]}")
        meshes = {}
        for k, m in enumerate(result["meshes"]):
            positions = np.array(m["positions"], float).reshape(len(times), -1, 3)
            normals = np.array(m["normals"], float).reshape(len(times), -1, 3)
            meshes[f"{m['path']}#{k}"] = (np.array(m["index"]).reshape(-1, 3), positions, normals)
        self.last = result
        return Played(times, meshes, np.zeros((len(times), 0, 3)))

    def close(self) -> None:
        self.client.close()


def godot_play(path: Path, clips: dict[str, np.ndarray], folder: Path,
               compress: tuple[bool, ...] = (True,)) -> dict[bool, dict[str, Played]]:
    """Godot 3 (godot3-server): ``path`` imported into a fresh project under ``folder``, each clip played
    by its AnimationPlayer (engine/godot_engine.gd), and every surface posed with what Godot left:
    its imported blend shapes mixed by the player's weights as Godot's blend shape modes say, then
    skinned by the player's bone poses times the skin's binds (linear blend, as Godot's shader does).
    Godot's front faces are clockwise, so its triangles are turned back to glTF's order here.
    ``compress``: the scene importer's `meshes/compress` settings to play the file under (Godot's
    default, on: normals in bytes), each a copy of the file with its own .import, all imported in one
    run of Godot; the clips as played, by setting."""
    from tests.clients.godot import GODOT, import_project, new_project

    if GODOT is None:
        raise RuntimeError("no godot3-server")
    project = new_project(folder, HERE / "godot_engine.gd", "fishgen_pose.gd")
    names = {c: f"{path.stem}{'' if c else '_uncompressed'}{path.suffix}" for c in compress}
    for c, name in names.items():
        shutil.copy(path, project / name)
        if not c:   # the import dock's Meshes > Compress, as its .import file keeps it
            (project / f"{name}.import").write_text(
                f'[remap]\n\nimporter="scene"\ntype="PackedScene"\n\n[deps]\n\nsource_file="res://{name}"\n\n'
                '[params]\n\nmeshes/compress=false\n')
    import_project(project, folder)
    return {c: _godot_pose(project, folder, name, clips) for c, name in names.items()}


def _godot_pose(project: Path, folder: Path, name: str, clips: dict[str, np.ndarray]) -> dict[str, Played]:
    """res://``name`` (imported) played by engine/godot_engine.gd, each clip at its times."""
    from tests.clients.godot import GODOT, _env

    assert GODOT is not None
    (project / "fishgen_pose.json").write_text(json.dumps(
        {"file": f"res://{name}", "clips": {k: [float(t) for t in v] for k, v in clips.items()}}))
    run = subprocess.run([GODOT, "--path", str(project), "-s", "res://fishgen_pose.gd"],
                         capture_output=True, text=True, env=_env(folder), timeout=600)
    line = next((x for x in run.stdout.splitlines() if x.startswith("FISHGEN_POSE ")), None)
    if run.returncode != 0 or line is None or "SCRIPT ERROR" in run.stdout + run.stderr:
        raise RuntimeError(f"godot3-server -s fishgen_pose.gd exited {run.returncode}: "
                           f"{(run.stdout + run.stderr).strip()[-800:]}")
    report = json.loads(line.split(" ", 1)[1])
    out = {}
    for clip, frames in report["clips"].items():
        meshes = {}
        for m, mesh in enumerate(report["meshes"]):
            for k, surf in enumerate(mesh["surfaces"]):
                faces = np.array(surf["index"], np.int64).reshape(-1, 3)[:, [0, 2, 1]]
                base = [np.array(surf[key], float).reshape(-1, 3) for key in ("vertices", "normals")]
                shapes = [[np.array(b[key], float).reshape(-1, 3) for b in surf["blend"]]
                          for key in ("vertices", "normals")]
                positions, normals = [], []
                for state in (f[m] for f in frames):
                    w = np.array(state["weights"], float)
                    posed = []
                    for b, sh in zip(base, shapes, strict=True):
                        mixed = b * (1.0 - w.sum()) if mesh["mode"] == 0 else b.copy()   # 0: NORMALIZED
                        for wk, shape in zip(w, sh, strict=True):
                            mixed += wk * shape
                        posed.append(mixed)
                    if surf["bones"] is not None and state["binds"]:
                        binds = np.array(state["binds"], float)
                        cols, origin = binds[:, :9].reshape(-1, 3, 3), binds[:, 9:]
                        bones = np.array(surf["bones"], np.int64).reshape(-1, 4)
                        weights = np.array(surf["weights"], float).reshape(-1, 4)
                        blend = np.einsum("vj,vjab->vab", weights, cols[bones])       # rows: the basis' axes
                        shift = np.einsum("vj,vjc->vc", weights, origin[bones])
                        posed = [np.einsum("va,vab->vb", posed[0], blend) + shift,
                                 np.einsum("va,vab->vb", posed[1], blend)]
                    positions.append(posed[0])
                    normals.append(posed[1])
                meshes[f"{mesh['path']}/{k}#{m}"] = (faces, np.array(positions), np.array(normals))
        out[clip] = Played(np.asarray(clips[clip], float), meshes, np.zeros((len(clips[clip]), 0, 3)))
    return out


def blender_play(path: Path, clips: dict[str, np.ndarray], probe_points: np.ndarray,
                 shading: bool = False) -> dict:
    """Blender's importer and its own evaluated meshes (tests/assembly/engine/blender_engine.py).
    With ``shading``, ``report["shading"]`` holds a :class:`Played` per clip (no probes), and one of
    the rest pose as ``__rest__``, and ``report["fins"]`` the fin vertices of each mesh."""
    if BPY is None:
        raise RuntimeError("no Python with bpy ($FISHGEN_BPY_PYTHON)")
    with tempfile.TemporaryDirectory() as tmp:
        spec = Path(tmp) / "spec.json"
        spec.write_text(json.dumps({"probes": probe_points.tolist(), "shading": shading,
                                    "clips": {k: [float(t) for t in v] for k, v in clips.items()}}))
        run = subprocess.run([BPY, str(HERE / "blender_engine.py"), str(path), str(spec)],
                             capture_output=True, text=True, timeout=1200)
    if run.returncode != 0:
        raise RuntimeError(run.stderr[-2000:])
    report = json.loads(next(line for line in run.stdout.splitlines() if line.startswith("{")))
    report["clips"] = {k: np.array(v, float) for k, v in report["clips"].items()}
    played = {}
    report["fins"] = {f"{m['name']}#{k}": np.array(m["fin"], bool)
                      for k, m in enumerate(report["shading"].get("__rest__", [[]])[0])}
    for clip, frames in report["shading"].items():
        meshes = {}
        for k, first in enumerate(frames[0]):
            meshes[f"{first['name']}#{k}"] = (
                np.array(first["faces"], np.int64).reshape(-1, 3),
                np.array([f[k]["positions"] for f in frames], float).reshape(len(frames), -1, 3),
                np.array([f[k]["normals"] for f in frames], float).reshape(len(frames), -1, 3))
        report["spread"] = max([report.get("spread", 0.0)] + [f[k]["corner_spread"] for f in frames
                                                               for k in range(len(f))])
        played[clip] = Played(clips.get(clip, np.zeros(1)), meshes, np.zeros((len(frames), 0, 3)))
    report["shading"] = played
    return report


# -- levels of detail -----------------------------------------------------------------------------

def level_scene(scene: Scene, level: int) -> Scene:
    """``scene`` as a client that switched to level ``level`` draws it: the MSFT_lod node's place taken
    by the level's node (a copy sharing everything else)."""
    from dataclasses import replace

    if level == 0:
        return scene
    finest = next(i for i in scene.reachable() if scene.nodes[i].lods is not None)
    coarse = scene.nodes[finest].lods.nodes[level - 1]  # type: ignore[union-attr]
    roots = [coarse if r == finest else r for r in scene.roots]
    return replace(scene, roots=roots, hidden_roots=[])


def silhouette(scene: Scene, size: tuple[int, int] = (1024, 512), t: float | None = None,
               clip: str | None = None, box: tuple[float, float, float, float] | None = None) -> np.ndarray:
    """The side view's silhouette (looking along -X, Z to the right, Y up): every drawn triangle
    filled, (H, W) bool. ``box``: (z0, z1, y0, y1) of the frame (default: the scene's own, padded)."""
    from PIL import Image, ImageDraw

    posed = pose(scene, t, clip)
    tris = [deformed(scene, n, p, posed)[0][np.asarray(p.indices)]
            for n, p in scene.drawn() if p.indices is not None]
    tri = np.concatenate(tris)[..., [2, 1]]
    if box is None:
        lo, hi = tri.reshape(-1, 2).min(0), tri.reshape(-1, 2).max(0)
        pad = 0.05 * (hi - lo)
        box = (lo[0] - pad[0], hi[0] + pad[0], lo[1] - pad[1], hi[1] + pad[1])
    w, h = size
    px = (tri[..., 0] - box[0]) / (box[1] - box[0]) * w
    py = (box[3] - tri[..., 1]) / (box[3] - box[2]) * h
    img = Image.new("1", size, 0)
    draw = ImageDraw.Draw(img)
    for a, b in zip(px, py, strict=True):
        draw.polygon(list(zip(a.tolist(), b.tolist(), strict=True)), fill=1)
    return np.asarray(img, bool)


def frame_of(scene: Scene, pad: float = 0.05) -> tuple[float, float, float, float]:
    """(z0, z1, y0, y1) around the scene's drawn triangles at rest, for silhouettes that share a frame."""
    points = np.concatenate([deformed(scene, n, p, pose(scene))[0] for n, p in scene.drawn()])
    lo, hi = points[:, [2, 1]].min(0), points[:, [2, 1]].max(0)
    d = pad * (hi - lo)
    return (lo[0] - d[0], hi[0] + d[0], lo[1] - d[1], hi[1] + d[1])


def iou(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.count_nonzero(a & b) / max(np.count_nonzero(a | b), 1))


def fin_gap(scene: Scene, clip: str, times: np.ndarray) -> float:
    """Largest distance from the posed body surface, over ``times``, of a fin vertex that touches the
    body at rest, in body lengths (trimesh's closest points)."""
    import trimesh

    parts = [(name, n, p) for name, n, p in _drawn_parts(scene)]
    rest = pose(scene)
    body = [(n, p) for name, n, p in parts if name == "body"]
    fins = [(n, p) for name, n, p in parts if name != "body"]
    faces = np.asarray(body[0][1].indices)
    body_rest = trimesh.Trimesh(deformed(scene, *body[0], rest)[0], faces, process=False)
    points = np.concatenate([deformed(scene, n, p, rest)[0] for n, p in scene.drawn()])
    length = float(np.ptp(points[:, 2]))
    touching = []
    for n, p in fins:
        _, d, _ = trimesh.proximity.closest_point(body_rest, deformed(scene, n, p, rest)[0])
        touching.append(np.flatnonzero(d < 1e-3 * length))
    worst = 0.0
    for t in times:
        posed = pose(scene, float(t), clip)
        surface = trimesh.Trimesh(deformed(scene, *body[0], posed)[0], faces, process=False)
        for (n, p), idx in zip(fins, touching, strict=True):
            if len(idx):
                _, d, _ = trimesh.proximity.closest_point(surface, deformed(scene, n, p, posed)[0][idx])
                worst = max(worst, float(d.max()))
    return worst / length
