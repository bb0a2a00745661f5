"""Babylon.js in the client matrix: its own loaders in the headless Chromium the three.js cells use.

npm `babylonjs` and `babylonjs-loaders` (the UMD builds, one version) are served from
node_modules on 127.0.0.1 to babylon_harness.html, which loads each file with
`BABYLON.LoadAssetContainerAsync`, adds it to a fresh scene and renders a frame
(babylon_harness.js). Babylon.js reads glTF (.glb, .gltf), OBJ (+ MTL) and, through
its Gaussian-splat loader, PLY: a PLY with faces becomes a mesh, one without a point
cloud. It has no CSV or NPY loader (and STL is not a fishgen format).

Each cell checks: it loads with no console error and no failed request, every file
fishgen wrote is fetched and every texture is ready, the counts match fishgen's, the
clip is there with a track for every channel (one per morph target for weights), each
bound to a node of the scene, every key is fishgen's clip at its time, and the bounds
(of the meshes at rest and of every morph target) are fishgen's (tests/clients/bounds.py).
"""
from __future__ import annotations

import json
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
from tests.clients.matrix import ROOT, Asset, HarnessPage, expect, expect_counts, three_unavailable

BABYLON_DIR = ROOT / "node_modules" / "babylonjs"
LOADERS_DIR = ROOT / "node_modules" / "babylonjs-loaders"
ALPHATEST = 1   # PBRMaterial.PBRMATERIAL_ALPHATEST


def babylon_unavailable() -> str | None:
    if not (BABYLON_DIR / "babylon.js").is_file() or not (LOADERS_DIR / "babylonjs.loaders.js").is_file():
        return "Babylon.js not installed (npm ci)"
    why = three_unavailable()   # the same Chromium and playwright
    return why if why and "three.js" not in why else None


class BabylonClient(HarnessPage):
    """One local HTTP server, one Chromium, one Babylon.js page for all the Babylon.js cells."""

    def __init__(self, asset_dir: Path):
        super().__init__({"/babylon/": BABYLON_DIR, "/babylon-loaders/": LOADERS_DIR, "/assets/": asset_dir},
                         "babylon_harness.html")
        self.asset_dir = asset_dir.resolve()
        self.version = self.page.evaluate("BABYLON.Engine.Version")

    def inspect(self, asset: Asset) -> dict:
        self._clear()
        url = f"{self.base}/assets/{asset.path.resolve().relative_to(self.asset_dir).as_posix()}"
        # one JSON string crosses faster than a large nested object
        result = json.loads(self.page.evaluate(
            "async ([u, o]) => JSON.stringify(await window.inspectAsset(u, o))", [url, {}]))
        self.page.wait_for_timeout(50)  # let late console messages and responses land
        return result

    def append(self, asset: Asset) -> dict:
        """Babylon.js's report of ``asset`` loaded by AppendSceneAsync (a whole scene, no container)."""
        self._clear()
        url = f"{self.base}/assets/{asset.path.resolve().relative_to(self.asset_dir).as_posix()}"
        result = self.page.evaluate("(u) => window.appendAsset(u)", url)
        expect("error" not in result, f"loader error: {result.get('error')}")
        expect(not self._problems(), "; ".join(self._problems()[:3]))
        return result

    def screenshot(self, path: Path, alpha: float, beta: float) -> None:
        """The asset inspected last, seen from (alpha, beta) radians about its centre, as a PNG."""
        self.page.evaluate("([a, b]) => window.viewFrom(a, b)", [alpha, beta])
        self.page.locator("#view").screenshot(path=str(path))

    def check(self, asset: Asset) -> str:
        result = self.inspect(asset)
        expect("error" not in result, f"loader error: {result.get('error')}")
        problems = self._problems()
        expect(not problems, "; ".join(problems[:3]))
        note = judge(asset, result)
        never = self._never_fetched(asset)
        expect(not never, f"{', '.join(never)} never requested")
        return note


def judge(asset: Asset, r: dict) -> str:
    """Compare babylon_harness.js's report of one file with what fishgen made (module docstring).

    Counts, bounds and the clip come first, materials last: a known limit of a loader's
    materials (KNOWN_LIMITS) must not hide a wrong number.
    """
    notes: list[str] = []
    meshes = r["meshes"]
    expect(bool(meshes), "no meshes")
    points = [m for m in meshes if m["material"] and m["material"]["points"]]
    solid = [m for m in meshes if m not in points]
    counts = {"triangles": sum(m["indices"] // 3 for m in solid),
              "particles": sum(m["vertices"] for m in points)}
    vertices = sum(m["vertices"] for m in solid)
    if asset.fmt.ext not in ("obj", "ply"):
        counts["vertices"] = vertices
    elif solid and vertices != asset.expected["vertices"]:  # both loaders build their own vertices
        notes.append(f"re-indexed ({vertices} vertices)")
    expect_counts(counts, asset.expected)
    if "quads" in asset.expected:
        expect(counts["triangles"] == 2 * asset.expected["quads"], "quads != particles")
    if points and asset.fmt.ext == "ply":
        notes.append("a point cloud (splat loader): drops radius/density")
    elif points:
        notes.append("drops _RADIUS/_DENSITY/_CUBE")

    expected = asset.bounds
    assert expected is not None
    pairs = pair_primitives([as_box(m["world"]) for m in meshes], expected, "mesh")
    tol = tolerance(expected)
    if asset.fmt.ext in ("glb", "gltf"):
        for m, j in zip(meshes, pairs, strict=True):
            want = expected.primitives[j].targets
            found = [as_box(b) for b in m["targets"]]
            expect(len(found) == len(want),
                   f"{m['path']}: {len(found)} morph targets, fishgen made {len(want)}")
            for k, (a, b) in enumerate(zip(found, want, strict=True)):
                expect(box_close(a, b, tol),
                       f"{m['path']}: morph target {k} bounds {show(a)}, fishgen's {show(b)}")
    if asset.engine is not None:
        notes += _judge_engine(asset, r, tol)
    elif asset.clip:
        notes += _judge_clip(asset, r, tol)

    # every texture arrives, and the materials say what fishgen's say
    expect(r["settled"], "textures never became ready")
    textured = asset.fmt.kind in ("fish", "school") or "--billboards" in asset.fmt.flags
    for m in meshes:
        mat = m["material"]
        if textured:
            expect(mat is not None and mat["albedo"] is not None, f"{m['name']}: material has no texture")
            expect(mat["albedo"]["ready"] and mat["albedo"]["width"] > 0,
                   f"{m['name']}: texture did not arrive")
        if asset.fmt.kind == "cloud":
            expect("color" in m["kinds"] and m["useVertexColors"], f"{m['name']}: particle colours not used")
        if "--billboards" in asset.fmt.flags:
            expect(mat["unlit"], f"{m['name']}: KHR_materials_unlit ignored (particles lit)")
    if asset.fmt.kind in ("fish", "school") and asset.fmt.ext != "ply":
        fins = [m["material"] for m in meshes if m["material"] and m["material"]["name"].endswith("_fins")]
        expect(bool(fins), "no fins material")
        if asset.fmt.ext == "obj":
            expect(all(f["opacity"] and f["opacity"]["ready"] for f in fins), "fins: map_d mask not loaded")
        else:
            expect(all(f["transparencyMode"] == ALPHATEST and abs(f["alphaCutOff"] - 0.5) < 1e-6
                       and not f["backFaceCulling"] for f in fins), "fins lost MASK 0.5/double-sided")
    return "; ".join(notes)


def _judge_engine(asset: Asset, r: dict, tol: float) -> list[str]:
    """An engine row: the finest level only (Babylon's MSFT_lod loader loads the levels coarsest
    first and disposes each when the next is ready), every mesh skinned on the skin's joints with
    every blend shape by name, and every clip checked as the plain fish's swim is."""
    engine, bounds = asset.engine, asset.bounds
    assert engine is not None and bounds is not None and bounds.scene is not None
    coarse = sorted({m["path"] for m in r["meshes"]
                     if any(engine.level(part) > 0 for part in m["path"].split("/"))})
    expect(not coarse, f"coarser levels shown: {coarse[:3]}")
    for m in r["meshes"]:
        expect(m["bones"] is not None, f"{m['path']}: no skeleton")
        expect(engine.same_joints(m["bones"]), f"{m['path']}: bones {m['bones']}, the skin's joints are "
                                               f"{list(engine.joints)}")
        expect(m["targetNames"] == list(engine.targets), f"{m['path']}: morph targets {m['targetNames']}, "
                                                         f"fishgen's {list(engine.targets)}")
    names = [g["name"] for g in r["groups"]]
    missing = [c for c in engine.clips if c not in names]
    expect(not missing, f"animation groups missing: {missing} (found {names})")
    dangling = 0
    for name in engine.clips:
        clip = clip_bounds(bounds.scene, name)
        dangling = max(dangling, len(_judge_clip(asset, r, tol, clip, lods=len(engine.levels))))
    return [f"MSFT_lod: LOD0 kept{f', {dangling} weight tracks of disposed LOD1+ left' if dangling else ''}"]


def _judge_clip(asset: Asset, r: dict, tol: float, clip: ClipBounds | None = None, lods: int = 1) -> list:
    """The clip (asset.clip's, else ``clip``) is there, a track per channel and morph target, each
    bound and each key fishgen's. With ``lods`` levels, the morph weight tracks of all but the finest
    may target nothing (meshes a client disposed): they are returned, the rest checked."""
    assert asset.clip is not None and asset.bounds is not None and asset.bounds.clip is not None
    clip = clip or asset.bounds.clip
    name = clip.name
    groups = [g for g in r["groups"] if g["name"] == name]
    expect(bool(groups), f"no animation group named {name} (found {[g['name'] for g in r['groups']]})")
    group = groups[0]
    # Babylon makes a mesh of each primitive, with its own morph targets: a weights track for each
    per_mesh = asset.engine.primitives if asset.engine is not None else 1
    weights = clip.weight_tracks * per_mesh
    want = clip.rotation_channels + clip.translation_channels + clip.scale_channels + weights
    expect(len(group["tracks"]) == want, f"{name} has {len(group['tracks'])} tracks, expected {want} "
                                         f"({clip.weight_channels} weights channels x their morph targets"
                                         f"{f' x {per_mesh} primitives' if per_mesh > 1 else ''})")
    dangling = [t for t in group["tracks"]
                if not t["inScene"] and t["property"] == "influence" and t["node"] is None]
    if lods > 1:  # the coarser levels' weights tracks, at most: (lods - 1) / lods of them
        expect(len(dangling) * lods <= weights * (lods - 1), f"{name}: {len(dangling)} weight tracks "
                                                                        f"target nothing")
    else:
        dangling = []
    live = [t for t in group["tracks"] if t not in dangling]
    unbound = [t["node"] or t["property"] for t in live if not t["inScene"]]
    expect(not unbound, f"tracks target nothing in the scene: {unbound[:3]}")
    length = (group["to"] - group["from"]) / group["fps"]
    expect(abs(length - clip.duration) < 1e-3,
           f"{name} lasts {length:.4f} s, fishgen's {clip.duration:.4f} s")
    assert asset.bounds.scene is not None
    truth = ClipTruth(asset.bounds.scene, name)
    tracks = [{"node": _node_of(t["node"]), "kind": "weight" if t["property"] == "influence" else "trs",
               "target": t["target"], "keys": t["keys"]} for t in live]
    expect_same_keys(key_errors(truth, tracks), tol)
    played = key_errors(truth, [{**k, "keys": t["played"]} for k, t in zip(tracks, live, strict=True)])
    expect(played.weight < 1e-3,
           f"plays morph weights off by {played.weight:.3g} ({played.worst.get('weight')})")
    expect(played.translation < 1e-4 and played.rotation < 0.1,
           f"plays nodes off by {played.translation * 1000:.2f} mm, {played.rotation:.2f}° "
           f"({played.worst.get('translation') or played.worst.get('rotation')})")
    return dangling


def _node_of(path: str) -> str:
    """The glTF node a Babylon mesh path stands for: a node of several primitives becomes a parent
    with a child mesh per primitive, ``node/node_primitive0``."""
    import re

    parts = path.split("/")
    if len(parts) > 1 and re.fullmatch(rf"{re.escape(parts[-2])}_primitive\d+", parts[-1]):
        parts.pop()
    return "/".join(parts)
