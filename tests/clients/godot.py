"""Godot 3 in the client matrix: every asset imported into one project, then inspected by GDScript.

Debian bookworm ships Godot 3.2.3 as `godot3` (X11 editor), `godot3-runner` (X11 game
runtime) and `godot3-server` (headless, and built with the editor's tools, importers
included). The matrix uses `godot3-server` only, so it needs no display:

1. **Import.** Every asset's folder is copied into one project (one editor start for
   all of them keeps CI time low) and `godot3-server --path P --export-pack
   import-only P.pck` imports every file, packs only project.godot, and exits.
   `--editor --quit` is not used: in 3.2.3 it either hangs or quits before the import
   is done (godotengine/godot#42839, #42746; 4.x added `--import` for this).
2. **Inspect.** `godot3-server --path P -s res://fishgen_inspect.gd` loads each file as
   a game does (`load()`, `instance()`) and prints one JSON line per file: meshes and
   surfaces, counts, bounds of the vertices and of every blend shape, materials and
   textures, animations with their tracks, whether each track's node and property
   exist, and the range of the keys (godot/inspect.gd).

Each cell then checks: it imported and loaded with no error of its own (the lines
Godot prints for any file, listed in GODOT_NOISE with the reason, excepted); every
texture arrived; the counts match fishgen's; the clip is there with a track for every
channel and morph target, each bound to a node; and the bounds match fishgen's
(tests/clients/bounds.py): Godot 3.2 reads some valid glTF wrong without a word.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

from tests.clients.bounds import (
    ClipBounds,
    ClipTruth,
    as_box,
    box_close,
    clip_bounds,
    expect_same_keys,
    key_errors,
    pair_primitives,
    show,
    tolerance,
)
from tests.clients.matrix import HERE, Asset, CellFailure, expect, expect_counts

TEMPLATE = HERE / "godot"
GODOT = next((p for p in (os.environ.get("FISHGEN_GODOT"), shutil.which("godot3-server"))
              if p and Path(p).is_file()), None)
GODOT_FORMATS = ("glb", "gltf", "obj")      # Godot 3 has no PLY, CSV or NPY importer
IMPORT_TIMEOUT = 300                        # seconds; the matrix's files take about 4 s
TRACK_VALUE, TRACK_TRANSFORM = 0, 1         # Animation.TYPE_*
PRIMITIVE_POINTS, PRIMITIVE_TRIANGLES = 0, 4
CULL_DISABLED = 2

# What Godot 3.2.3 prints while importing or loading files that are fine, and why it is not a failure.
GODOT_NOISE: tuple[tuple[str, str], ...] = (
    ('free_static: Condition "p_ptr == __null" is true',
     "Debian's 3.2.3 build prints it once per glTF node (+1) for any glTF, "
     "a hand-written one-triangle file too"),
    ('store_buffer: Condition "!p_src" is true',
     "the scene importer saving an empty array (godotengine/godot#35637)"),
    ("Couldn't open MTL file",
     "the OBJ importer opens `mtllib` relative to the working folder first, then beside the .obj, "
     "which works"),
    ("Ambient light for material",
     "a warning: Godot's PBR materials have no ambient colour (fishgen writes `Ka 0 0 0`)"),
)


def godot_unavailable() -> str | None:
    if GODOT is None:
        return "no godot3-server (apt-get install godot3-server)"
    return None


def _env(home: Path) -> dict[str, str]:
    """Godot's settings and caches go under ``home``, never the user's; a locale it knows (it rejects 'C')."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("LC_")}
    env.update(LANG="en_US.UTF-8", XDG_CONFIG_HOME=str(home / "config"), XDG_DATA_HOME=str(home / "data"),
               XDG_CACHE_HOME=str(home / "cache"))
    return env


def is_noise(message: str) -> bool:
    return any(pattern in message for pattern, _ in GODOT_NOISE)


def _messages(log: str) -> dict[str, list[str]]:
    """Godot's ERROR/WARNING lines, keyed by the file being imported or loaded when it printed them
    (the basename from `reimport: step N: NAME`, the res:// path from FISHGEN_BEGIN; '' before any)."""
    out: dict[str, list[str]] = {}
    current = ""
    for line in log.splitlines():
        if line.startswith("Godot Engine v"):  # a new run of Godot
            current = ""
        elif m := re.match(r"\s*reimport: step \d+: (.+)$", line):
            current = m[1].strip()
        elif line.startswith("FISHGEN_BEGIN "):
            current = line.split(" ", 1)[1].strip()
        elif line.startswith(("ERROR:", "WARNING:", "SCRIPT ERROR:")):
            out.setdefault(current, []).append(line.strip())
    return out


def new_project(folder: Path, script: Path, name: str) -> Path:
    """A fresh Godot project at ``folder``/project (``folder`` emptied first), with ``script`` as res://``name``."""
    project = folder / "project"
    if folder.exists():
        shutil.rmtree(folder)
    project.mkdir(parents=True)
    for template in ("project.godot", "export_presets.cfg"):
        shutil.copy(TEMPLATE / template, project / template)
    shutil.copy(script, project / name)
    return project


def import_project(project: Path, folder: Path) -> str:
    """Import every file of ``project`` (settings and caches under ``folder``); Godot's log."""
    assert GODOT is not None, godot_unavailable()
    imported = subprocess.run([GODOT, "--path", str(project), "--export-pack", "import-only",
                               str(folder / "import-only.pck")],
                              capture_output=True, text=True, env=_env(folder), timeout=IMPORT_TIMEOUT)
    log = imported.stdout + imported.stderr
    if imported.returncode != 0:
        raise RuntimeError(f"godot3-server --export-pack exited {imported.returncode}: {log.strip()[-500:]}")
    return log


@dataclass
class GodotRun:
    """One import of all the files into one project, and what Godot made of each."""

    project: Path
    files: dict[str, str]                       # asset label -> res:// path
    assets: dict[str, Asset]
    results: dict[str, dict] = field(default_factory=dict)      # res:// path -> inspect.gd's JSON
    messages: dict[str, list[str]] = field(default_factory=dict)
    import_seconds: float = 0.0
    inspect_seconds: float = 0.0
    version: str = ""

    @classmethod
    def start(cls, folder: Path, assets: dict[str, Asset]) -> GodotRun:
        """Copy each asset's folder into a fresh project under ``folder``; import and inspect them all."""
        import time

        assert GODOT is not None, godot_unavailable()

        project = new_project(folder, TEMPLATE / "inspect.gd", "fishgen_inspect.gd")
        files = {}
        for label, asset in assets.items():  # each folder once: assets may share one
            where = asset.path.parent.name
            if not (project / where).exists():
                shutil.copytree(asset.path.parent, project / where)
            files[label] = f"res://{where}/{asset.path.name}"
        (project / "fishgen_files.txt").write_text("\n".join(files.values()) + "\n", encoding="utf-8")
        run = cls(project, files, assets)
        env = _env(folder)
        start = time.perf_counter()
        log = import_project(project, folder)
        run.import_seconds = time.perf_counter() - start
        start = time.perf_counter()
        inspected = subprocess.run([GODOT, "--path", str(project), "-s", "res://fishgen_inspect.gd"],
                                   capture_output=True, text=True, env=env, timeout=IMPORT_TIMEOUT)
        run.inspect_seconds = time.perf_counter() - start
        (folder / "godot.log").write_text(log + inspected.stdout + inspected.stderr, encoding="utf-8")
        run.messages = _messages(log)
        for where, found in _messages(inspected.stdout + inspected.stderr).items():
            run.messages.setdefault(where, []).extend(found)
        for line in inspected.stdout.splitlines():
            if line.startswith("FISHGEN_JSON "):
                result = json.loads(line.split(" ", 1)[1])
                run.results[result["file"]] = result
        if inspected.returncode != 0 or len(run.results) != len(files):
            raise RuntimeError(f"godot3-server -s fishgen_inspect.gd exited {inspected.returncode} with "
                               f"{len(run.results)} of {len(files)} results: "
                               f"{(inspected.stdout + inspected.stderr).strip()[-500:]}")
        run.version = log.splitlines()[0].replace("Godot Engine ", "").split(" - ")[0] if log else "?"
        return run

    def problems(self, asset: Asset) -> list[str]:
        """Godot's messages about this asset's files (import and load), less the noise every file gets."""
        res = self.files[asset.label]
        keys = [*asset.files, res, ""]   # '' : before any file, e.g. the project failing to open
        return [m for k in keys for m in self.messages.get(k, []) if not is_noise(m)]

    def check(self, asset: Asset) -> str:
        result = self.results[self.files[asset.label]]
        expect("error" not in result, f"Godot: {result.get('error')}")
        problems = self.problems(asset)
        expect(not problems, "; ".join(problems[:2]))
        return judge(asset, result)


def judge(asset: Asset, r: dict) -> str:
    """Compare inspect.gd's report of one file with what fishgen made (module docstring).

    Counts, bounds and the clip come first, materials last: a known limit of Godot's
    materials (KNOWN_LIMITS) must not hide a wrong number.
    """
    notes: list[str] = []
    surfaces = [(m, s) for m in r["meshes"] for s in m["surfaces"]]
    expect(bool(surfaces), "no mesh surfaces")
    limits: list[str] = []    # what a client cannot do, said last: it must not hide a wrong number
    if asset.engine is not None:  # Godot 3 knows no MSFT_lod: the finest level is checked, the rest noted
        engine = asset.engine
        coarse = sorted({m["name"] for m, _ in surfaces
                         if engine.level(m["name"]) > 0 and m.get("visible", True)})
        if coarse:
            limits.append(f"coarser levels imported visible ({len(coarse)} meshes, {coarse[0]} first)")
        surfaces = [(m, s) for m, s in surfaces if engine.level(m["name"]) == 0]
    triangles = [s for _, s in surfaces if s["primitive"] == PRIMITIVE_TRIANGLES]
    points = [s for _, s in surfaces if s["primitive"] == PRIMITIVE_POINTS]
    counts = {"triangles": sum((s["indices"] or s["vertices"]) // 3 for s in triangles),
              "particles": sum(s["vertices"] for s in points)}
    vertices = sum(s["vertices"] for s in triangles)
    if asset.fmt.ext == "obj":  # the importer indexes each distinct v/vt/vn: the file's sharing differs
        notes.append(f"re-indexed ({vertices} vertices)")
    else:
        counts["vertices"] = vertices
    expect_counts(counts, asset.expected)
    if "quads" in asset.expected:
        expect(counts["triangles"] == 2 * asset.expected["quads"], "quads != particles")
    if points:
        notes.append("drops _RADIUS/_DENSITY/_CUBE")

    # bounds: every surface is one of fishgen's primitives, at rest, and so is every blend shape
    expected = asset.bounds
    assert expected is not None
    pairs = pair_primitives([as_box(s["world_aabb"]) for _, s in surfaces], expected)
    tol = tolerance(expected)
    for (mesh, s), j in zip(surfaces, pairs, strict=True):
        want = expected.primitives[j].targets
        if asset.fmt.ext == "obj":
            continue  # OBJ holds the rest pose only
        found = [as_box(b) for b in s["blend_aabbs"]]
        expect(len(found) == len(want),
               f"{mesh['name']}: {len(found)} blend shapes, fishgen made {len(want)}")
        for k, (a, b) in enumerate(zip(found, want, strict=True)):
            expect(box_close(a, b, tol),
                   f"{mesh['name']}: blend shape {k} bounds {show(a)}, fishgen's {show(b)}")
    if asset.clip:
        if asset.engine is not None:
            limits += _judge_engine(asset, r)
            assert expected.scene is not None
            for name in asset.engine.clips:
                notes += _judge_clip(asset, r["animations"], tol, clip_bounds(expected.scene, name))
        else:
            notes += _judge_clip(asset, r["animations"], tol)

    # every texture arrives, and the materials say what fishgen's say
    textured = asset.fmt.kind in ("fish", "school") or "--billboards" in asset.fmt.flags
    for mesh, s in surfaces:
        mat = s["material"]
        if textured:
            expect(mat is not None, f"{mesh['name']}: no material")
            tex = mat.get("albedo_texture")
            expect(bool(tex) and tex["width"] > 0,
                   f"{mesh['name']}: material {mat.get('name')} has no albedo texture")
        if asset.fmt.kind == "cloud":  # COLOR_0 is each particle's colour; glTF multiplies it in
            expect(s["has_color"], f"{mesh['name']}: particle colours missing")
            shown = [] if mat and mat["vertex_color_use_as_albedo"] else ["COLOR_0 imported but not shown"]
            if "--billboards" in asset.fmt.flags and not mat["unshaded"]:
                shown.append("KHR_materials_unlit ignored")
            expect(not shown, f"{mesh['name']}: {', '.join(shown)}")
    fins = [s["material"] for _, s in surfaces if s["material"] and s["material"]["name"].endswith("_fins")]
    if asset.fmt.kind in ("fish", "school"):
        expect(bool(fins), "no fins material")
        if asset.fmt.ext == "obj":  # the mask png is named by map_d
            expect(all(m["alpha_scissor"] or m["transparent"] for m in fins),
                   "map_d mask not used: fins are opaque (and culled one side)")
        else:
            expect(all(m["alpha_scissor"] and abs(m["alpha_scissor_threshold"] - 0.5) < 1e-6
                       and m["cull_mode"] == CULL_DISABLED for m in fins), "fins lost MASK 0.5/double-sided")
    expect(not limits, "; ".join(limits))
    return "; ".join(dict.fromkeys(notes))


def _judge_engine(asset: Asset, r: dict) -> list[str]:
    """An engine row's skin and blend shapes: each finest-level mesh on a Skeleton, its skin's
    binds the skin's joints, its blend shapes named as fishgen's. Returns what Godot gets wrong
    without an error: the fish of a school bound to one fish's bones."""
    engine = asset.engine
    assert engine is not None
    meshes = [m for m in r["meshes"] if engine.level(m["name"]) == 0]
    for m in meshes:
        expect(m.get("skeleton") is not None, f"{m['name']}: not on a Skeleton")
        expect(engine.same_joints(m["bones"]), f"{m['name']}: bones {m['bones']}, the skin's joints are "
                                               f"{list(engine.joints)}")
        expect(m["blend_shape_names"] == list(engine.targets),
               f"{m['name']}: blend shapes {m['blend_shape_names']}, fishgen's {list(engine.targets)}")
    binds = {tuple(m["bones"]) for m in meshes}
    if len(binds) < len(meshes):  # one skin a fish in the file, each on its own joints
        return [f"{len(meshes)} fish's skins bind {len(binds)} set of bones: every fish drawn on "
                f"{meshes[0]['bones'][0]}'s"]
    return []


def _judge_clip(asset: Asset, animations: list[dict], tol: float,
                clip: ClipBounds | None = None) -> list[str]:
    """The clip is there, each glTF channel became its tracks, every track is bound, and every key
    Godot kept is fishgen's clip at that time."""
    assert asset.clip is not None and asset.bounds is not None and asset.bounds.clip is not None
    clip = clip or asset.bounds.clip
    name = clip.name
    found = [a for a in animations if a["name"] == name]
    expect(bool(found), f"no animation named {name} (found {[a['name'] for a in animations]})")
    anim = found[0]
    transform = [t for t in anim["tracks"] if t["type"] == TRACK_TRANSFORM]
    value = [t for t in anim["tracks"] if t["type"] == TRACK_VALUE]
    expect(len(transform) == clip.trs_nodes and len(value) == clip.weight_tracks,
           f"{name}: {len(transform)} transform and {len(value)} blend shape tracks, expected "
           f"{clip.trs_nodes} and {clip.weight_tracks} "
           f"({clip.weight_channels} weights channels x their targets)")
    unbound = [t["path"] for t in anim["tracks"] if not t["bound"] or t.get("property_exists") is False]
    expect(not unbound, f"tracks target nothing: {unbound[:3]}")
    expect(abs(anim["length"] - clip.duration) < 1e-3,
           f"{name} lasts {anim['length']} s, fishgen's {clip.duration:.4f} s")
    assert asset.bounds.scene is not None
    truth = ClipTruth(asset.bounds.scene, name)
    keys = [{"node": _transform_node(truth, t, i, clip), "kind": "trs", "keys": t["keys"]}
            for i, t in enumerate(transform)]
    for t in value:
        node, prop = t["path"].split(":", 1)
        keys.append({"node": node, "kind": "weight", "target": _target_index(truth, t["path"], node, prop),
                     "keys": t["keys"]})
    expect_same_keys(key_errors(truth, keys), tol)
    # as the player plays it: Godot's importer resamples node tracks at 15 fps and drops keys
    # its optimizer finds redundant, so between its keys it may differ (a note, with the figure)
    played = key_errors(truth, [{**k, "keys": t["played"]}
                                for k, t in zip(keys, transform + value, strict=True)])
    notes = []
    if played.translation > 1e-4 or played.rotation > 0.1:
        notes.append(f"plays node keys resampled at 15 fps: within {played.translation * 1000:.1f} mm, "
                     f"{played.rotation:.1f}°")
    expect(played.weight < 1e-3,
           f"plays blend shape weights off by {played.weight:.3g} ({played.worst['weight']})")
    if not anim["loop"]:
        notes.append(f"`{name}` imports unlooped")
    return notes


# --------------------------------------------------------------------------- self-tests and extra files

def read_glb(path: Path) -> tuple[dict, bytes]:
    import struct

    data = path.read_bytes()
    magic, _, _ = struct.unpack_from("<4sII", data)
    assert magic == b"glTF"
    (json_len, _), offset = struct.unpack_from("<II", data, 12), 20
    doc = json.loads(data[offset:offset + json_len])
    offset += json_len
    blob = (data[offset + 8:offset + 8 + struct.unpack_from("<I", data, offset)[0]]
            if offset < len(data) else b"")
    return doc, blob


def write_glb(path: Path, doc: dict, blob: bytes) -> None:
    import struct

    blob += b"\0" * (-len(blob) % 4)
    doc["buffers"][0]["byteLength"] = len(blob)
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(blob), 0x004E4942) + blob
    path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)


def quantize_positions(src: Path, dst: Path) -> None:
    """Copy a one-mesh .glb with its positions stored the KHR_mesh_quantization way: normalized
    16-bit integers, scaled back to metres by the node. Valid glTF, the same points; Godot 3.2
    reads the integers as they are (±32767) and says nothing."""
    import numpy as np

    doc, blob = read_glb(src)
    (node,) = [n for n in doc["nodes"] if "mesh" in n]
    prim = doc["meshes"][node["mesh"]]["primitives"][0]
    acc = doc["accessors"][prim["attributes"]["POSITION"]]
    view = doc["bufferViews"][acc["bufferView"]]
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    p = np.frombuffer(blob, np.float32, acc["count"] * 3, start).reshape(-1, 3)
    scale = float(np.abs(p).max())
    q = np.zeros((len(p), 4), np.int16)   # 8-byte stride: vertex attributes align to 4 bytes
    q[:, :3] = np.round(p / scale * 32767)
    offset = len(blob) + (-len(blob) % 4)
    blob = blob + b"\0" * (offset - len(blob)) + q.tobytes()
    doc["bufferViews"].append({"buffer": 0, "byteOffset": offset, "byteLength": q.nbytes, "byteStride": 8,
                               "target": 34962})
    acc.update(bufferView=len(doc["bufferViews"]) - 1, byteOffset=0, componentType=5122, normalized=True,
               min=[int(v) for v in q[:, :3].min(0)], max=[int(v) for v in q[:, :3].max(0)])
    node["scale"] = [scale, scale, scale]
    for key in ("extensionsUsed", "extensionsRequired"):
        doc[key] = sorted({*doc.get(key, []), "KHR_mesh_quantization"})
    dst.parent.mkdir(parents=True, exist_ok=True)
    write_glb(dst, doc, blob)


def spoil_weight_key(gltf: Path) -> None:
    """Change one morph weight key of a .gltf's first clip in its .bin (0.5, or 0.25 if it was 0.5):
    the counts stay right, so only a comparison of the keys notices."""
    import numpy as np

    doc = json.loads(gltf.read_text())
    clip = doc["animations"][0]
    channel = next(c for c in clip["channels"] if c["target"]["path"] == "weights")
    acc = doc["accessors"][clip["samplers"][channel["sampler"]]["output"]]
    view = doc["bufferViews"][acc["bufferView"]]
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0) + 4 * 2  # the third value
    binary = gltf.parent / doc["buffers"][view["buffer"]]["uri"]
    blob = bytearray(binary.read_bytes())
    old = float(np.frombuffer(blob, np.float32, 1, start)[0])
    blob[start:start + 4] = np.float32(0.25 if old == 0.5 else 0.5).tobytes()
    binary.write_bytes(bytes(blob))


SELFTEST_QUANTIZED = "selftest quantized points"
SELFTEST_KEY = "selftest spoilt weight key"
TWO_SPECIES = ("two species: bonybream", "two species: centroberyx")


def extra_assets(assets: dict[str, Asset], folder: Path) -> dict[str, Asset]:
    """Files only the Godot tests use, imported in the same run as the matrix's:

    - the cloud points with quantized positions (the bounds check must catch Godot's misreading);
    - the fish .gltf with one morph weight key changed (the key check must catch it);
    - two species built into one folder, as a user exports a set (each must keep its own materials).
    """

    from tests.cli_runner import run_cli_process
    from tests.clients.matrix import FISH_SOURCE, PARAMS, Format

    if folder.exists():
        shutil.rmtree(folder)
    points = assets["cloud glb points"]
    fmt = Format(SELFTEST_QUANTIZED, "cloud", points.fmt.filename)
    quantize_positions(points.path, folder / fmt.slug / fmt.filename)
    extra = {fmt.label: Asset(fmt, folder / fmt.slug / fmt.filename, [fmt.filename], points.summary,
                              dict(points.reported), dict(points.expected), None, points.bounds)}
    fish = assets["fish gltf"]
    fmt = Format(SELFTEST_KEY, "fish", fish.fmt.filename)
    shutil.copytree(fish.path.parent, folder / fmt.slug)
    spoil_weight_key(folder / fmt.slug / fmt.filename)
    extra[fmt.label] = Asset(fmt, folder / fmt.slug / fmt.filename, list(fish.files), fish.summary,
                             dict(fish.reported), dict(fish.expected), fish.clip, fish.bounds)
    both = folder / "two-species"
    sources = [FISH_SOURCE, PARAMS / "centroberyx.txt"]
    result = run_cli_process("build", *sources, "-o", f"{both}/", "--format", "glb")
    if result.returncode != 0:
        raise RuntimeError(f"fishgen build of two species failed: {result.stderr.strip()}")
    for label, source in zip(TWO_SPECIES, sources, strict=True):
        name = source.stem + ".glb"
        extra[label] = Asset(Format(label, "fish", name), both / name, [name], "", {}, {})
    return extra


def render(run: GodotRun, folder: Path) -> str | None:
    """Draw every file of ``run`` as Godot 3 renders it (godot/render.gd), into ``folder``;
    None when done, else why not. Needs the X11 editor `godot3` and `xvfb-run`, not in CI."""
    godot, xvfb = shutil.which("godot3"), shutil.which("xvfb-run")
    if godot is None or xvfb is None:
        return "needs `godot3` and `xvfb-run` (apt-get install godot3 xvfb)"
    shutil.copy(TEMPLATE / "render.gd", run.project / "fishgen_render.gd")
    env = {**_env(run.project.parent), "FISHGEN_LOOK": str(folder.resolve())}
    done = subprocess.run([xvfb, "-a", "-s", "-screen 0 480x360x24", godot, "--resolution", "480x360",
                           "--path", str(run.project), "-s", "res://fishgen_render.gd"],
                          capture_output=True, text=True, env=env, timeout=IMPORT_TIMEOUT)
    return None if done.returncode == 0 else f"godot3 exited {done.returncode}: {done.stderr.strip()[-300:]}"


def _target_index(truth: ClipTruth, path: str, node: str, prop: str) -> int:
    """The morph target a blend-shape track drives: Godot names a blend shape after the mesh's
    ``extras.targetNames`` when the file has them, else ``morph_N``."""
    m = re.fullmatch(r"blend_shapes/(.+)", prop)
    if m is None:
        raise CellFailure(f"{path}: not a blend shape track")
    numbered = re.fullmatch(r"morph_(\d+)", m[1])
    if numbered is not None:
        return int(numbered[1])
    index = truth.node(node)
    mesh = truth.scene.nodes[index].mesh if index is not None else None
    names = truth.scene.meshes[mesh].target_names if mesh is not None else []
    if m[1] not in names:
        raise CellFailure(f"{path}: a blend shape the file's targetNames do not name")
    return list(names).index(m[1])


def _transform_node(truth: ClipTruth, track: dict, index: int, clip: ClipBounds) -> str:
    """The node path of fishgen's that a transform track drives. A node track names it; a bone
    track (``Skeleton:bone``, its keys made rest * pose by inspect.gd) names a bone Godot renamed
    to be unique in a skeleton that may hold several skins' joints, so it is the ``index``-th of
    the clip's animated nodes in file order, the order the importer makes tracks in (checked
    against the bone's name, less Godot's numbers and case)."""
    if "bone" not in track:
        return track["path"]
    scene = truth.scene
    animated = sorted({node for node, path in truth.channels if path != "weights"})
    expect(len(animated) == clip.trs_nodes and index < len(animated),
           f"{track['path']}: no animated node {index}")
    node = animated[index]

    def plain(name: str) -> str:
        return re.sub(r"[\d_]", "", name).lower()

    name = scene.nodes[node].name
    expect(plain(track["bone"]) == plain(name), f"{track['path']}: bone {track['bone']} for node {name}")
    return next(path for path, i in truth.paths.items() if i == node)
