"""The client matrix: every fishgen output format, loaded by every client that can run here.

Shared by the pytest cells (tests/clients/test_clients.py) and the command-line
report (tools/check_clients.py). Assets are made by the real `fishgen` command
line, one folder each, and each cell checks: it loads, nothing failed (console
errors, failed or 4xx/5xx requests), every texture the file names arrives, the
counts match the summary line fishgen printed, and the `swim` clip is there
where the format and the client hold animation. The Godot 3 and Babylon.js
cells also compare bounds with fishgen's (tests/clients/bounds.py): a client can
read the right number of wrong values.

A few cells fail because of what a client cannot do; those are listed in
KNOWN_LIMITS with the reason, reported as "✗ known: …" and xfail (strict) in
pytest: if a client starts to manage it, the cell fails until the entry goes.
"""
from __future__ import annotations

import json
import re
import shutil
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import TYPE_CHECKING

from tests.browser import CHROMIUM
from tests.browser import browser as shared_browser
from tests.cli_runner import run_cli_process
from tests.clients.bounds import Bounds, ClipBounds, merged, scene_bounds

if TYPE_CHECKING:
    from fishgen.scene.model import Scene
    from tests.clients.babylon import BabylonClient
    from tests.clients.godot import GodotRun

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
PARAMS = ROOT / "params"
FISH_SOURCE = PARAMS / "bonybream.txt"
CLOUD_SOURCE = PARAMS / "clouds" / "table_4_4.awn"
SWIM_TRACKS = 13  # 4 fin swings (pectoral, pelvic) + the body wave's weights on the body and 8 fins
SCHOOL_FISH, SCHOOL_FRAMES = 10, 30
SCHOOL_TRACKS = 2 + SWIM_TRACKS  # each fish: its path (translation, rotation) and its own swim
CLOUD_COLUMNS = ("x", "y", "z", "radius", "density", "red", "green", "blue")
# The engine rows (issue 24): levels of detail, one skinned mesh a level, every clip
ENGINE_LODS = ((16, 12), (8, 6))
ENGINE_CLIPS = ("swim", "idle", "sprint", "turn_left", "turn_right", "burst")
ENGINE_FLAGS = ("--lods", ",".join(f"{b}x{c}" for b, c in ENGINE_LODS), "--merge")


@dataclass(frozen=True)
class Format:
    label: str          # row of the table
    kind: str           # "fish", "school" or "cloud"
    filename: str
    flags: tuple[str, ...] = ()

    @property
    def ext(self) -> str:
        return self.filename.rsplit(".", 1)[1]

    @property
    def slug(self) -> str:
        return self.label.replace(" ", "-")

    @property
    def engine(self) -> bool:
        return "--merge" in self.flags


FORMATS = (
    Format("fish glb", "fish", "fish.glb"),
    Format("fish gltf", "fish", "fish.gltf"),
    Format("fish obj", "fish", "fish.obj"),
    Format("fish ply", "fish", "fish.ply"),
    Format("school glb", "school", "school.glb",
           ("--count", str(SCHOOL_FISH), "--frames", str(SCHOOL_FRAMES))),
    Format("engine fish glb", "fish", "engine.glb", (*ENGINE_FLAGS, "--clips", ",".join(ENGINE_CLIPS))),
    Format("engine school glb", "school", "engine_school.glb",
           ("--count", str(SCHOOL_FISH), "--frames", str(SCHOOL_FRAMES), *ENGINE_FLAGS)),
    Format("cloud ply", "cloud", "cloud.ply"),
    Format("cloud glb points", "cloud", "points.glb"),
    Format("cloud glb billboards", "cloud", "billboards.glb", ("--billboards",)),
    Format("cloud csv", "cloud", "cloud.csv"),
    Format("cloud npy", "cloud", "cloud.npy"),
)
CLIENTS = ("three.js", "Babylon.js", "Godot 3", "trimesh", "pygltflib", "plyfile", "numpy")
APPLIES = {  # Godot 3 has no PLY importer; Babylon.js reads PLY through its splat loader
    "glb": ("three.js", "Babylon.js", "Godot 3", "trimesh", "pygltflib"),
    "gltf": ("three.js", "Babylon.js", "Godot 3", "trimesh", "pygltflib"),
    "obj": ("three.js", "Babylon.js", "Godot 3", "trimesh"),
    "ply": ("three.js", "Babylon.js", "trimesh", "plyfile"),
    "csv": ("numpy",),
    "npy": ("numpy",),
}

# (format label, client) -> (substring of the failure it must show, short reason for the table)
KNOWN_LIMITS: dict[tuple[str, str], tuple[str, str]] = {
    ("fish ply", "three.js"): ("never requested", "PLYLoader ignores `comment TextureFile`: no texture"),
    ("fish ply", "Babylon.js"): ("material has no texture",
                                 "the splat loader's PLY mesh ignores `comment TextureFile` and s/t: "
                                 "no texture"),
    ("fish obj", "Godot 3"): ("map_d", "the OBJ importer ignores `map_d`: fins opaque and one-sided"),
    ("cloud glb points", "Godot 3"): ("COLOR_0 imported but not shown",
                                      "COLOR_0 kept but not shown (the importer uses vertex colours only for "
                                      "materials named `…-vcol`): particles white"),
    ("cloud glb billboards", "Godot 3"): ("COLOR_0 imported but not shown, KHR_materials_unlit ignored",
                                          "COLOR_0 not shown, KHR_materials_unlit ignored: "
                                          "particles white and lit"),
    ("fish obj", "trimesh"): ("map_d", "trimesh ignores map_d (fins keep the skin png's alpha)"),
    # Babylon's MSFT_lod loader disposes a replaced level's materials when no mesh of the *scene* uses
    # them; a container's meshes are not the scene's yet, so the levels' shared materials go with LOD1
    # (AppendSceneAsync keeps them: test_babylon_appends_the_engine_fish_textured)
    ("engine fish glb", "Babylon.js"): ("material has no texture",
                                        "LoadAssetContainerAsync + MSFT_lod dispose the levels' shared "
                                        "materials: LOD0 untextured (AppendSceneAsync is right)"),
    ("engine school glb", "Babylon.js"): ("material has no texture",
                                          "as the engine fish: LOD0 untextured in an asset container"),
    ("engine fish glb", "Godot 3"): ("coarser levels imported visible",
                                     "MSFT_lod ignored: LOD1 imported as a second visible mesh over LOD0"),
    # the fish of a school share one mesh, so their skins' bind poses are equal; Godot 3.2.3 keeps one
    # such skin and binds every fish to the first fish's bones (the bones and tracks are all there)
    ("engine school glb", "Godot 3"): ("first); 10 fish's skins bind 1 set of bones",
                                       "LOD1 visible too, and the importer keeps one of the fish's equal "
                                       "skins: all 10 fish drawn on the first fish's bones"),
}


# The order cells run in: Godot's last, since its import runs in the background meanwhile.
RUN_ORDER = ("three.js", "Babylon.js", "trimesh", "pygltflib", "plyfile", "numpy", "Godot 3")


def cells() -> list[tuple[str, str]]:
    return [(f.label, c) for c in RUN_ORDER for f in FORMATS if c in APPLIES[f.ext]]


# --------------------------------------------------------------------------- assets

@dataclass(frozen=True)
class Engine:
    """What an engine row's file holds beyond the plain fish's (issue 24), from fishgen's own scene."""

    clips: tuple[str, ...]          # every clip, by name
    levels: tuple[str, ...]         # one fish's mesh node a level, finest first ("bonybream_LOD0", ...)
    joints: tuple[str, ...]         # the finest level's skin joints, by node name
    targets: tuple[str, ...]        # blend shape names (the meshes' extras.targetNames)
    primitives: int                 # primitives of one level's mesh (body, fins)

    @classmethod
    def of(cls, scene: Scene) -> Engine:
        """From a scene fishgen built, or read back from the file (whose reader keeps the coarser
        levels as nodes outside the scene, named ``<name>_LOD1``, ...)."""
        meshed = [n for n in scene.nodes if n.mesh is not None]
        node = meshed[0]
        assert node.mesh is not None and node.skin is not None, "an engine row's fish is one skinned mesh"
        stem = re.sub(r"_LOD0$", "", node.name)
        levels = tuple(n.name for n in meshed if re.fullmatch(rf"{re.escape(stem)}_LOD\d+", n.name))
        mesh = scene.meshes[node.mesh]
        joints = tuple(scene.nodes[j].name for j in scene.skins[node.skin].joints)
        return cls(tuple(c.name for c in scene.clips), levels, joints, tuple(mesh.target_names),
                   len(mesh.primitives))

    def client_tracks(self, clip: ClipBounds) -> int:
        """Tracks of ``clip`` in a client that splits a weights channel per primitive (three.js)."""
        return clip.rotation_channels + clip.translation_channels + clip.scale_channels \
            + clip.weight_channels * self.primitives

    def same_joints(self, names: list[str]) -> bool:
        """A client's bones are the skin's joints, in order, up to the numbers clients (and a school's
        fish) append to repeated names: ``pectoral_fin_left_1``, ``bonybream_00003``."""
        def plain(name: str) -> str:
            return re.sub(r"(_\d+)+$", "", name)
        return [plain(n) for n in names] == [plain(n) for n in self.joints]

    def level(self, name: str) -> int:
        """The level a node or mesh named ``name`` belongs to (0 unless it ends in _LODn, n > 0)."""
        m = re.search(r"_LOD(\d+)(?:_\d+)?$", name)
        return int(m[1]) if m else 0


@dataclass
class Asset:
    fmt: Format
    path: Path
    files: list[str]            # every file fishgen wrote for it (the main file first)
    summary: str                # the one line fishgen printed
    reported: dict[str, int]    # counts from that line
    expected: dict[str, int]    # vertices / triangles / particles a loader must find
    clip: tuple[str, int] | None = None     # the clip's name and glTF channels, where the format holds it
    bounds: Bounds | None = None            # fishgen's bounds (tests/clients/bounds.py)
    engine: Engine | None = None            # the engine rows' levels, skin, blend shapes and clips

    @property
    def label(self) -> str:
        return self.fmt.label

    @property
    def side_files(self) -> list[str]:
        return self.files[1:]


def _summary_counts(line: str) -> dict[str, int]:
    found = {k: int(m[1]) for k in ("triangles", "particles", "frames")
             if (m := re.search(rf"(\d+) {k}\b", line))}
    if m := re.search(r": (\d+) \w+;", line):  # a school: "school.glb: 10 bonybream; 30 frames (1.0 s), ..."
        found["fish"] = int(m[1])
    return found


def _scenes() -> dict[str, Scene]:
    """The scenes fishgen builds in-process for the fish and cloud rows, as the CLI builds them
    (the summary line has no vertex count, and the bounds come from these)."""
    import fishgen
    from fishgen.assembly.fish import make_fish
    from fishgen.clouds import fill_cloud, load_cubes
    from fishgen.clouds.scene import cloud_scene

    cloud = fill_cloud(load_cubes(CLOUD_SOURCE), seed=0)
    species = fishgen.load_species(FISH_SOURCE)
    return {"fish": fishgen.build_fish(species),
            "engine": make_fish(species, lods=ENGINE_LODS, merge=True, clips=ENGINE_CLIPS).scene,
            "points": cloud_scene(cloud), "billboards": cloud_scene(cloud, billboards=True)}


def make_assets(folder: Path) -> dict[str, Asset]:
    """Run the real CLI once per format (in parallel), each into its own folder."""
    folder.mkdir(parents=True, exist_ok=True)

    def build(fmt: Format) -> Asset:
        out_dir = folder / fmt.slug
        if out_dir.exists():
            shutil.rmtree(out_dir)
        out_dir.mkdir()
        out = out_dir / fmt.filename
        command = {"fish": "build", "school": "school", "cloud": "clouds"}[fmt.kind]
        source = CLOUD_SOURCE if fmt.kind == "cloud" else FISH_SOURCE
        result = run_cli_process(command, source, "-o", out, *fmt.flags)  # from a thread pool: a process each
        if result.returncode != 0:
            raise RuntimeError(f"fishgen {command} -o {fmt.filename} failed: {result.stderr.strip()}")
        lines = result.stdout.strip().splitlines()
        # one summary line; a school's is followed by its table of measures
        if len(lines) != 1 and fmt.kind != "school":
            raise RuntimeError(f"fishgen printed {len(lines)} lines, expected one summary line: "
                               f"{result.stdout!r}")
        files = [fmt.filename] + sorted(p.name for p in out_dir.iterdir() if p.name != fmt.filename)
        return Asset(fmt, out, files, lines[0], _summary_counts(lines[0]), {})

    with ThreadPoolExecutor(4) as pool:
        jobs = [pool.submit(build, fmt) for fmt in FORMATS]
        scenes = _scenes()
        assets = {a.label: a for a in (job.result() for job in jobs)}
    points = scenes["points"].counts()
    for a in assets.values():
        fish_scene = scenes["engine" if a.fmt.engine else "fish"]   # a school's fish: the same levels
        fish = fish_scene.counts()
        if a.fmt.kind == "fish":
            if a.reported.get("triangles") != fish["triangles"]:
                raise RuntimeError(f"{a.label}: fishgen printed {a.summary!r}, "
                                   f"the scene has {fish['triangles']} triangles")
            a.expected = {"vertices": fish["vertices"], "triangles": a.reported["triangles"], "particles": 0}
            a.bounds = scene_bounds(fish_scene)
            if a.fmt.ext == "ply":  # one mesh of every part
                a.bounds = merged(a.bounds, "fish")
            if a.fmt.engine:
                a.engine = Engine.of(fish_scene)
                assert a.bounds.clip is not None
                a.clip = ("swim", a.bounds.clip.rotation_channels + a.bounds.clip.weight_channels)
            elif a.fmt.ext in ("glb", "gltf"):
                a.clip = ("swim", SWIM_TRACKS)
        elif a.fmt.kind == "school":
            n = a.reported.get("fish")
            if n != SCHOOL_FISH or a.reported.get("frames") != SCHOOL_FRAMES:
                raise RuntimeError(f"{a.label}: fishgen printed {a.summary!r}, asked for {SCHOOL_FISH} fish "
                                   f"and {SCHOOL_FRAMES} frames")
            a.expected = {"vertices": n * fish["vertices"], "triangles": n * fish["triangles"],
                          "particles": 0, "fish": n}
            from fishgen.exchange.gltf_reader import read_gltf

            school = read_gltf(a.path)
            a.bounds = scene_bounds(school)
            if a.fmt.engine:  # each fish: its path, 4 fin joints and one weights channel a level
                a.engine = Engine.of(school)
                a.clip = ("school", n * (2 + 5 * len(ENGINE_LODS)))
            else:
                a.clip = ("school", n * SCHOOL_TRACKS)
        else:
            n = a.reported["particles"]
            if n != points["particles"]:
                raise RuntimeError(f"{a.label}: fishgen printed {a.summary!r}, "
                                   f"fill_cloud made {points['particles']}")
            if "--billboards" in a.fmt.flags:  # QUADS crossed quads (4 vertices, 2 triangles each) a particle
                from fishgen.clouds.scene import QUADS

                a.expected = {"vertices": 4 * QUADS * n, "triangles": 2 * QUADS * n, "particles": 0,
                              "quads": QUADS * n}
                a.bounds = scene_bounds(scenes["billboards"])
            else:
                a.expected = {"vertices": 0, "triangles": 0, "particles": n}
                a.bounds = scene_bounds(scenes["points"])
    return assets


# --------------------------------------------------------------------------- cells

class CellFailure(AssertionError):
    pass


@dataclass
class Cell:
    label: str
    client: str
    status: str                 # pass, fail, known, skip
    reason: str = ""
    details: dict = field(default_factory=dict)
    seconds: float = 0.0

    @property
    def mark(self) -> str:
        return {"pass": "✓", "fail": "✗", "known": "✗", "skip": "–"}[self.status]

    @property
    def text(self) -> str:
        if self.status == "known":
            return f"✗ known: {self.reason}"
        return f"{self.mark} {self.reason}".strip()


def expect(condition: bool, message: str) -> None:
    if not condition:
        raise CellFailure(message)


def expect_counts(found: dict[str, int], expected: dict[str, int], what: str = "") -> None:
    for key, value in found.items():
        if key in expected and value != expected[key]:
            raise CellFailure(f"{what}{key}: found {value}, fishgen made {expected[key]}")


# ---- Python clients

def _image_ok(img) -> bool:
    return img is not None and getattr(img, "size", (0, 0))[0] > 0


def check_trimesh(asset: Asset) -> str:
    import numpy as np
    import trimesh

    loaded = trimesh.load(asset.path)               # what people call: default processing
    raw = trimesh.load(asset.path, process=False)   # the file's own vertices
    notes = []

    def instances(scene_or_geom):
        if isinstance(scene_or_geom, trimesh.Scene):
            return [scene_or_geom.geometry[g] for _, g in
                    (scene_or_geom.graph[n] for n in scene_or_geom.graph.nodes_geometry)]
        return [scene_or_geom]

    geoms, raw_geoms = instances(loaded), instances(raw)
    meshes = [g for g in geoms if isinstance(g, trimesh.Trimesh)]
    clouds = [g for g in geoms if isinstance(g, trimesh.PointCloud)]
    counts = {"triangles": sum(len(g.faces) for g in meshes),
              "particles": sum(len(g.vertices) for g in clouds),
              "vertices": sum(len(g.vertices) for g in raw_geoms if isinstance(g, trimesh.Trimesh))}
    expect_counts(counts, asset.expected)
    merged = counts["vertices"] - sum(len(g.vertices) for g in meshes)
    if merged:
        notes.append(f"default load merges {merged} duplicate vertex{'es' if merged > 1 else ''}")

    if asset.fmt.kind in ("fish", "school") or "--billboards" in asset.fmt.flags:
        for g in meshes:
            mat = getattr(g.visual, "material", None)
            expect(mat is not None, f"{g.metadata.get('name', 'mesh')}: no material")
            img = getattr(mat, "image", None) or getattr(mat, "baseColorTexture", None)
            expect(_image_ok(img), f"{g.metadata.get('name', 'mesh')}: texture did not arrive")
        if asset.fmt.ext == "obj":
            masked = [g for g in loaded.geometry.values()
                      if "map_d" in getattr(g.visual.material, "kwargs", {})]
            expect(not masked, "map_d mask png named in the .mtl is not loaded (only kept as text)")
    if "--billboards" in asset.fmt.flags:
        expect(counts["triangles"] == 2 * asset.expected["quads"], "quads != particles")
    if clouds:
        for g in clouds:
            expect(g.colors is not None and len(g.colors) == len(g.vertices), "particle colours missing")
        if asset.fmt.ext == "ply":
            raw_ply = loaded.metadata.get("_ply_raw", {}).get("vertex", {}).get("data")
            names = raw_ply.dtype.names if raw_ply is not None else ()
            expect({"radius", "density"} <= set(names or ()), "radius/density not kept")
            notes.append("radius/density only in metadata['_ply_raw']")
        else:
            attrs = set()
            for g in clouds:
                attrs |= set(getattr(g, "vertex_attributes", {}) or {})
            if not attrs & {"_RADIUS", "_radius"}:
                notes.append("drops _RADIUS/_DENSITY/_CUBE")
    if asset.clip:
        notes.append("no animation support")
    _ = np
    return "; ".join(notes)


def check_pygltflib(asset: Asset) -> str:
    import io

    import pygltflib
    from PIL import Image

    g = pygltflib.GLTF2().load(str(asset.path))
    blob = g.binary_blob() if asset.fmt.ext == "glb" else None
    counts = {"vertices": 0, "triangles": 0, "particles": 0}
    attrs_seen: set[str] = set()

    def walk(i):
        node = g.nodes[i]
        if node.mesh is not None:
            for prim in g.meshes[node.mesh].primitives:
                mode = 4 if prim.mode is None else prim.mode
                pos = g.accessors[prim.attributes.POSITION].count
                attrs_seen.update(k for k, v in prim.attributes.__dict__.items() if v is not None)
                attrs_seen.update(getattr(prim.attributes, "__pydantic_extra__", None) or {})
                if mode == 0:
                    counts["particles"] += pos
                elif mode == 4:
                    counts["vertices"] += pos
                    n = g.accessors[prim.indices].count if prim.indices is not None else pos
                    counts["triangles"] += n // 3
        for c in node.children or []:
            walk(c)

    for root in g.scenes[g.scene or 0].nodes:
        walk(root)
    expect_counts(counts, asset.expected)
    if asset.fmt.kind == "cloud" and "--billboards" not in asset.fmt.flags:
        raw = json.loads(g.to_json())
        prim_attrs = raw["meshes"][0]["primitives"][0]["attributes"]
        missing = {"POSITION", "COLOR_0", "_RADIUS", "_DENSITY", "_CUBE"} - set(prim_attrs)
        expect(not missing, f"attributes missing: {sorted(missing)}")
        bad = [k for k, v in prim_attrs.items() if g.accessors[v].count != asset.expected["particles"]]
        expect(not bad, f"attribute counts differ: {bad}")

    for i, image in enumerate(g.images or []):
        if image.uri:
            p = asset.path.parent / image.uri
            expect(p.is_file(), f"image {image.uri} missing")
            data = p.read_bytes()
        else:
            bv = g.bufferViews[image.bufferView]
            expect(blob is not None, f"image {i}: bufferView image outside a glb")
            data = blob[(bv.byteOffset or 0):(bv.byteOffset or 0) + bv.byteLength]
        expect(Image.open(io.BytesIO(data)).size[0] > 0, f"image {i} does not decode")
    for buf in g.buffers:
        if buf.uri and not buf.uri.startswith("data:"):
            expect((asset.path.parent / buf.uri).is_file(), f"buffer {buf.uri} missing")
    if asset.fmt.kind in ("fish", "school"):
        expect(bool(g.images), "no images")
        _check_clip(asset, [(a.name, len(a.channels)) for a in g.animations or []])
    return ""


def _check_clip(asset: Asset, clips: list[tuple[str, int]]) -> None:
    """The asset's clip is there with a track for each of its glTF channels."""
    if asset.clip is None:
        return
    name, channels = asset.clip
    found = [n for clip, n in clips if clip == name]
    expect(bool(found), f"no clip named {name} (found {[c for c, _ in clips]})")
    expect(found[0] == channels, f"{name} has {found[0]} tracks, expected {channels}")


def check_plyfile(asset: Asset) -> str:
    from PIL import Image
    from plyfile import PlyData

    ply = PlyData.read(str(asset.path))
    vertex = ply["vertex"]
    if asset.fmt.kind == "fish":
        faces = ply["face"].data["vertex_indices"]
        expect(all(len(f) == 3 for f in faces), "faces that are not triangles")
        expect_counts({"vertices": vertex.count, "triangles": ply["face"].count}, asset.expected)
        names = [c.split(None, 1)[1] for c in ply.comments if c.startswith("TextureFile")]
        expect(bool(names), "no `comment TextureFile`")
        for name in names:
            p = asset.path.parent / name
            expect(p.is_file(), f"TextureFile {name} missing")
            expect(Image.open(p).size[0] > 0, f"TextureFile {name} does not decode")
        expect({"s", "t"} <= {p.name for p in vertex.properties}, "no s/t texture coordinates")
    else:
        expect_counts({"particles": vertex.count}, asset.expected)
        props = tuple(p.name for p in vertex.properties)
        expect(props == CLOUD_COLUMNS, f"vertex properties {props}")
    return ""


def check_numpy(asset: Asset) -> str:
    import numpy as np

    if asset.fmt.ext == "npy":
        data = np.load(asset.path, allow_pickle=False)
    else:
        data = np.genfromtxt(asset.path, delimiter=",", names=True, dtype=None, encoding="utf-8")
    expect(data.dtype.names is not None, "not a table with named columns")
    expect(set(CLOUD_COLUMNS) <= set(data.dtype.names), f"columns {data.dtype.names}")
    expect_counts({"particles": len(data)}, asset.expected)
    expect(bool(np.isfinite(data["radius"]).all() and (data["radius"] > 0).all()),
           "radius not positive finite")
    return ""


PY_CHECKS: dict[str, Callable[[Asset], str]] = {
    "trimesh": check_trimesh, "pygltflib": check_pygltflib, "plyfile": check_plyfile, "numpy": check_numpy}


# ---- three.js in headless Chromium

THREE_DIR = ROOT / "node_modules" / "three"


def three_unavailable() -> str | None:
    if CHROMIUM is None:
        return "no chromium (apt-get install chromium)"
    if not (THREE_DIR / "build" / "three.module.js").is_file():
        return "three.js not installed (npm ci)"
    try:
        import playwright  # noqa: F401
    except ImportError:
        return "playwright not installed"
    return None


class _Handler(SimpleHTTPRequestHandler):
    """/three/ -> node_modules/three, /harness/ -> tests/clients, /assets/ -> the asset folder."""

    mounts: dict[str, Path] = {}
    log: list[tuple[str, int]] = []

    def translate_path(self, path: str) -> str:
        path = path.split("?", 1)[0].split("#", 1)[0]
        from urllib.parse import unquote

        path = unquote(path)
        for prefix, base in self.mounts.items():
            if path.startswith(prefix):
                target = (base / path[len(prefix):]).resolve()
                if target == base or base in target.parents:
                    return str(target)
        return str(Path("/nonexistent") / path.lstrip("/"))

    def end_headers(self) -> None:
        self.send_header("Cache-Control", "no-store")
        super().end_headers()

    def log_request(self, code="-", size="-") -> None:  # noqa: ARG002
        self.log.append((self.path, int(code) if str(code).isdigit() else 0))

    def log_message(self, format, *args) -> None:  # noqa: A002
        pass


class LocalBrowser:
    """A local HTTP server for ``mounts`` (URL prefix -> folder) on loopback, and one headless
    Chromium page of its own (in the process's shared Chromium); ``close()`` stops both."""

    def __init__(self, mounts: dict[str, Path]):
        handler = type("Handler", (_Handler,), {"mounts": {k: v.resolve() for k, v in mounts.items()},
                                                "log": []})
        handler.extensions_map = {**SimpleHTTPRequestHandler.extensions_map, ".js": "text/javascript"}
        self.handler = handler
        self.server = ThreadingHTTPServer(("127.0.0.1", 0), handler)
        self.base = f"http://127.0.0.1:{self.server.server_address[1]}"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()
        try:
            self.browser = shared_browser()
        except Exception:
            self.server.shutdown()
            self.server.server_close()
            raise
        self.context = self.browser.new_context()
        self.page = self.context.new_page()

    def close(self) -> None:
        try:
            self.context.close()
        finally:
            self.server.shutdown()
            self.server.server_close()


class HarnessPage(LocalBrowser):
    """A harness page (under tests/clients, served at /harness/) in the shared Chromium, with every
    console error, page error and request recorded, and nothing fetched from outside 127.0.0.1."""

    def __init__(self, mounts: dict[str, Path], page: str):
        super().__init__({**mounts, "/harness/": HERE})
        self.console: list[str] = []
        self.requests: list[tuple[str, int | str]] = []
        self.outside: list[str] = []
        self.page.on("console",
                     lambda m: self.console.append(f"{m.type}: {m.text}") if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.console.append(f"pageerror: {e}"))
        self.page.on("response", lambda r: self.requests.append((r.url, r.status)))
        self.page.on("requestfailed", lambda r: self.requests.append((r.url, f"failed {r.failure}")))
        self.inflight: set = set()
        self.page.on("request", lambda r: self.inflight.add(r))
        self.page.on("requestfinished", lambda r: self.inflight.discard(r))
        self.page.on("requestfailed", lambda r: self.inflight.discard(r))
        self.page.route("**/*", self._route)
        self.page.goto(f"{self.base}/harness/{page}")
        self.page.wait_for_function("window.harnessReady === true", timeout=60_000)
        problems = self._problems()
        if problems:
            raise RuntimeError(f"the harness page did not load cleanly: {problems}")

    def _route(self, route) -> None:
        url = route.request.url
        if url.startswith(self.base) or url.startswith(("blob:", "data:")):
            route.continue_()
        else:  # never the internet
            self.outside.append(url)
            route.abort()

    def _problems(self) -> list[str]:
        out = list(self.console)
        # FileLoader re-streams a body for progress events; Chromium then often reports the
        # original request as net::ERR_ABORTED after its complete 200 response: not a failure.
        answered = {u for u, s in self.requests if s == 200}
        out += [f"{u} -> {s}" for u, s in self.requests if not (isinstance(s, int) and s < 400)
                and not (s == "failed net::ERR_ABORTED" and u in answered)]
        out += [f"outside request {u}" for u in self.outside]
        return out

    def _settle(self) -> None:
        """Wait (up to 10 s) until every request the page made has ended, its response recorded."""
        deadline = time.monotonic() + 10
        while self.inflight and time.monotonic() < deadline:
            self.page.wait_for_timeout(20)

    def _clear(self) -> None:
        """Forget what was recorded, once every request the page made has ended: a response that came
        after the last check (a broken asset's 404, under load) would otherwise count against the next."""
        self._settle()
        self.console.clear()
        self.requests.clear()
        self.outside.clear()

    def _never_fetched(self, asset: Asset) -> list[str]:
        """Files fishgen wrote for ``asset`` that the page never fetched (with a 200)."""
        fetched = {u.rsplit("/", 1)[1] for u, s in self.requests if s == 200}
        return [f for f in asset.files if f not in fetched]


class ThreeClient(HarnessPage):
    """One local HTTP server, one Chromium, one harness page for all the three.js cells."""

    def __init__(self, asset_dir: Path):
        super().__init__({"/three/": THREE_DIR, "/assets/": asset_dir}, "harness.html")

    def check(self, asset: Asset) -> str:
        self._clear()
        loader = {"glb": "gltf", "gltf": "gltf", "obj": "obj", "ply": "ply"}[asset.fmt.ext]
        url = f"{self.base}/assets/{asset.fmt.slug}/{asset.fmt.filename}"
        options = {}
        if loader == "ply" and asset.fmt.kind == "cloud":  # what an app must ask for to keep them
            options = {"customProperties": {"radius": ["radius"], "density": ["density"]}}
        result = self.page.evaluate("([l, u, o]) => window.inspectAsset(l, u, o)", [loader, url, options])
        self._settle()  # a texture's 404 may end the harness's wait for it before Playwright is told
        self.page.wait_for_timeout(50)  # let late console messages and responses land
        expect("error" not in result, f"loader error: {result.get('error')}")
        problems = self._problems()
        expect(not problems, "; ".join(problems[:3]))
        return self._judge(asset, result)

    def tail_track(self, relative: str, times: list[float]) -> dict:
        """The tail tip as three.js plays the file at /assets/RELATIVE (harness.js tailTrack)."""
        self._clear()
        result = self.page.evaluate("([u, t]) => window.tailTrack(u, t)",
                                    [f"{self.base}/assets/{relative}", times])
        expect("error" not in result, f"three.js: {result.get('error')}")
        expect(not self._problems(), "; ".join(self._problems()[:3]))
        return result

    def _judge(self, asset: Asset, r: dict) -> str:
        notes = []
        objects = r["objects"]
        meshes = [o for o in objects if o["type"] == "Mesh"]
        points = [o for o in objects if o["type"] == "Points"]
        expect(bool(objects), "nothing loaded")
        indexed = all(o["indexed"] for o in meshes)
        counts = {"triangles": int(sum(o["triangles"] for o in meshes)),
                  "particles": sum(o["positions"] for o in points)}
        if indexed:
            counts["vertices"] = sum(o["positions"] for o in meshes)
        else:  # OBJLoader de-indexes: three positions per triangle, the file's sharing is gone
            positions = sum(o["positions"] for o in meshes)
            expect(positions == 3 * counts["triangles"],
                   f"{positions} positions for {counts['triangles']} triangles")
            notes.append(f"non-indexed ({positions} positions)")
        expect_counts(counts, asset.expected)
        if "--billboards" in asset.fmt.flags:
            expect(counts["triangles"] / 2 == asset.expected["quads"], "quads != particles")
        # every file fishgen wrote is fetched, once or more, and every texture arrives
        never = self._never_fetched(asset)
        expect(not never, f"{', '.join(never)} never requested")
        for o in meshes:
            for m in o["materials"]:
                expect(m["map"] is not None, f"{o['name'] or 'mesh'}: material has no map")
                for key in ("map", "alphaMap"):
                    if m[key] is not None:
                        expect(m[key]["arrived"], f"{o['name']}: {key} did not arrive")
        if asset.fmt.ext == "obj":
            fins = [m for o in meshes for m in o["materials"] if m["name"].endswith("_fins")]
            expect(bool(fins) and all(m["alphaMap"] and m["alphaMap"]["arrived"] for m in fins),
                   "fins material has no alphaMap")
        if asset.engine is not None:
            notes += _judge_three_engine(asset, r, meshes)
        elif asset.clip:
            clips = r["clips"]
            _check_clip(asset, [(c["name"], len(c["tracks"])) for c in clips])
            unbound = [t["name"] for c in clips for t in c["tracks"] if not t["bound"]]
            expect(not unbound, f"tracks target no node: {unbound}")
        if asset.clip:
            fins = [m for o in meshes for m in o["materials"] if m["name"].endswith("_fins")]
            expect(all(m["alphaTest"] == 0.5 and m["side"] == 2 for m in fins), "fins lost MASK/double-sided")
        if asset.fmt.kind == "cloud" and asset.fmt.ext == "glb":  # COLOR_0 shown; billboards unlit
            materials = [m for o in objects for m in o["materials"]]
            expect(all(m["vertexColors"] for m in materials), "particle colours (COLOR_0) not used")
            if "--billboards" in asset.fmt.flags:
                expect(all(m["type"] == "MeshBasicMaterial" for m in materials),
                       "KHR_materials_unlit ignored")
        if points:
            want = ({"color", "_radius", "_density", "_cube"} if asset.fmt.ext == "glb"
                    else {"color", "radius", "density"})
            have = set().union(*(o["attributes"] for o in points))
            expect(want <= have, f"attributes missing: {sorted(want - have)}")
            if asset.fmt.ext == "ply":
                notes.append("radius/density need setCustomPropertyNameMapping")
        return "; ".join(notes)


def _judge_three_engine(asset: Asset, r: dict, meshes: list[dict]) -> list[str]:
    """An engine row in three.js: the finest level only (GLTFLoader knows no MSFT_lod and loads the
    default scene), each primitive a SkinnedMesh on the skin's joints with every blend shape by name,
    the bounds fishgen's, and every clip by name with a track per channel and primitive, bound to a
    node but the coarser levels' morph weights (their meshes are not loaded)."""
    from tests.clients.bounds import as_box, clip_bounds, pair_primitives

    engine, bounds = asset.engine, asset.bounds
    assert engine is not None and bounds is not None and bounds.scene is not None
    coarse = sorted({o["name"] for o in meshes if engine.level(o["name"]) > 0})
    expect(not coarse, f"coarser levels shown: {coarse[:3]}")
    pair_primitives([as_box(o["world"]) for o in meshes], bounds, "mesh")
    for o in meshes:
        expect(o["bones"] is not None, f"{o['name']}: not a SkinnedMesh")
        expect(engine.same_joints(o["bones"]), f"{o['name']}: bones {o['bones']}, the skin's joints are "
                                               f"{list(engine.joints)}")
        expect(o["morphNames"] == list(engine.targets), f"{o['name']}: blend shapes {o['morphNames']}, "
                                                          f"fishgen's {list(engine.targets)}")
    clips = {c["name"]: c for c in r["clips"]}
    missing = [c for c in engine.clips if c not in clips]
    expect(not missing, f"clips missing: {missing} (found {sorted(clips)})")
    hidden = 0
    for name in engine.clips:
        clip = clip_bounds(bounds.scene, name)
        found = clips[name]
        want = engine.client_tracks(clip)
        expect(len(found["tracks"]) == want, f"{name} has {len(found['tracks'])} tracks, expected {want}")
        expect(abs(found["duration"] - clip.duration) < 1e-3, f"{name} lasts {found['duration']:.4f} s, "
                                                               f"fishgen's {clip.duration:.4f} s")
        unbound = [t["name"] for t in found["tracks"] if not t["bound"]]
        wrong = [t for t in unbound
                 if not (engine.level(t.split(".")[0]) > 0 and t.endswith(".morphTargetInfluences"))]
        expect(not wrong, f"{name}: tracks target no node: {wrong[:3]}")
        hidden = max(hidden, len(unbound))
    if len(engine.levels) < 2:
        return []
    return [f"LOD0 only (no MSFT_lod){f'; {hidden} weight tracks of LOD1+ unbound' if hidden else ''}"]


# --------------------------------------------------------------------------- running

class Matrix:
    def __init__(self, asset_dir: Path, godot_now: bool = True):
        self.asset_dir = asset_dir
        self.assets = make_assets(asset_dir)
        self.results: dict[tuple[str, str], Cell] = {}
        self._three: ThreeClient | None = None
        self._three_error: str | None = None
        self._babylon: BabylonClient | None = None
        self._babylon_error: str | None = None
        self._godot: GodotRun | None = None
        self._godot_error: str | None = None        # not installed: the cells are skipped
        self._godot_failure: str | None = None      # the import or the inspection failed: the cells fail
        self._godot_thread: threading.Thread | None = None
        if godot_now:  # Godot imports in its own process while the other clients run
            self._godot_thread = threading.Thread(target=self._start_godot, daemon=True)
            self._godot_thread.start()

    def three(self) -> ThreeClient | None:
        if self._three is None and self._three_error is None:
            self._three_error = three_unavailable()
            if self._three_error is None:
                self._three = ThreeClient(self.asset_dir)
        return self._three

    def babylon(self) -> BabylonClient | None:
        if self._babylon is None and self._babylon_error is None:
            from tests.clients.babylon import BabylonClient, babylon_unavailable

            self._babylon_error = babylon_unavailable()
            if self._babylon_error is None:
                self._babylon = BabylonClient(self.asset_dir)
        return self._babylon

    def godot(self) -> GodotRun | None:
        """Every file Godot reads, and the extra files of the Godot tests, imported in one run."""
        if self._godot_thread is not None:
            self._godot_thread.join()
        elif self._godot is None and self._godot_error is None and self._godot_failure is None:
            self._start_godot()
        return self._godot

    def _start_godot(self) -> None:
        from tests.clients.godot import GodotRun, extra_assets, godot_unavailable

        self._godot_error = godot_unavailable()
        if self._godot_error is not None:
            return
        try:
            chosen = {label: a for label, a in self.assets.items() if "Godot 3" in APPLIES[a.fmt.ext]}
            chosen.update(extra_assets(self.assets, self.asset_dir / "godot-extra"))
            self._godot = GodotRun.start(self.asset_dir / "godot", chosen)
        except Exception as err:  # noqa: BLE001 - the Godot cells fail with it, the rest run
            self._godot_failure = f"{type(err).__name__}: {err}"

    def _check(self, client: str) -> tuple[Callable[[Asset], str] | None, str]:
        """The client's check, or None and why it cannot run here."""
        if client == "three.js":
            three = self.three()
            return (three.check if three else None), self._three_error or ""
        if client == "Babylon.js":
            babylon = self.babylon()
            return (babylon.check if babylon else None), self._babylon_error or ""
        if client == "Godot 3":
            godot = self.godot()
            if self._godot_failure is not None:
                return partial(_raise, RuntimeError(self._godot_failure)), ""
            return (godot.check if godot else None), self._godot_error or ""
        return PY_CHECKS[client], ""

    def run(self, label: str, client: str) -> Cell:
        if (label, client) in self.results:
            return self.results[(label, client)]
        asset = self.assets[label]
        start = time.perf_counter()
        check, why = self._check(client)
        if check is None:
            cell = Cell(label, client, "skip", why or "unavailable")
        else:
            cell = _judge_known(label, client, partial(check, asset))
        cell.seconds = time.perf_counter() - start
        self.results[(label, client)] = cell
        return cell

    def run_all(self) -> list[Cell]:
        return [self.run(label, client) for label, client in cells()]

    def close(self) -> None:
        if self._godot_thread is not None:  # leave no Godot behind
            self._godot_thread.join()
        for client in (self._three, self._babylon):
            if client is not None:
                client.close()
        self._three = self._babylon = None


def _raise(err: Exception, *_) -> str:
    raise err


def _judge_known(label: str, client: str, check: Callable[[], str]) -> Cell:
    known = KNOWN_LIMITS.get((label, client))
    try:
        note = check()
    except Exception as e:  # noqa: BLE001 - every failure is a cell's reason
        reason = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        if not isinstance(e, AssertionError):
            reason = f"{type(e).__name__}: {reason}"
        if known and known[0] in reason:
            return Cell(label, client, "known", known[1], {"error": reason})
        return Cell(label, client, "fail", reason[:160])
    if known:
        return Cell(label, client, "fail", f"listed as known ({known[1]}) but passes: update KNOWN_LIMITS")
    return Cell(label, client, "pass", note)


def table(results: dict[tuple[str, str], Cell], clients: tuple[str, ...] = CLIENTS) -> str:
    """Markdown: one row per format, one column per client; '' where a client does not read it."""
    lines = ["| format | " + " | ".join(clients) + " |", "|---|" + "---|" * len(clients)]
    for fmt in FORMATS:
        row = []
        for c in clients:
            cell = results.get((fmt.label, c))
            row.append(cell.text.replace("|", "\\|") if cell else "")
        lines.append(f"| {fmt.label} | " + " | ".join(row) + " |")
    return "\n".join(lines)


def write_report(results: dict[tuple[str, str], Cell], path: Path, seconds: float | None = None) -> str:
    text = "# fishgen client matrix\n\n" + table(results) + "\n"
    if seconds is not None:
        text += f"\n{len(results)} cells in {seconds:.1f} s.\n"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return text
