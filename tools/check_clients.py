#!/usr/bin/env python
"""Load every fishgen output format in the clients people use and print a ✓/✗ table.

    python tools/check_clients.py                 # three.js and Babylon.js (headless Chromium), Godot 3
                                                  # (godot3-server), trimesh, pygltflib, plyfile, numpy
    python tools/check_clients.py --blender       # Blender's importers, through the `bpy` module
    python tools/check_clients.py --out DIR       # keep the generated assets (and Godot's project) in DIR
    python tools/check_clients.py --look DIR      # also save what Babylon.js (and Godot 3, if `godot3`
                                                  # and `xvfb-run` are installed) draw, from three sides

The matrix is the one the test-suite runs (tests/clients/); see docs/clients.md.
--blender needs a Python with `bpy` (PyPI's wheel is Python 3.11 only and large,
so keep it in its own venv): --bpy-python PATH, $FISHGEN_BPY_PYTHON, or
/tmp/bpyvenv/bin/python, e.g.

    python3.11 -m venv /tmp/bpyvenv && /tmp/bpyvenv/bin/pip install bpy

Exit status: 0 when every cell passes or fails only for a known client
limitation (docs/clients.md), 1 otherwise.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.clients.matrix import (  # noqa: E402
    CLIENTS,
    FORMATS,
    THREE_DIR,
    Asset,
    Cell,
    CellFailure,
    Matrix,
    expect,
    table,
    write_report,
)

BLENDER_SCRIPT = ROOT / "tests" / "clients" / "blender_import.py"
BLENDER_FORMATS = ("glb", "gltf", "obj", "ply")
BLENDER_KINDS = ("fish", "cloud")   # the school row is not judged in Blender yet
# what Blender cannot do, as (substring of the failure, short reason)
BLENDER_KNOWN = {"fish ply": ("no material",
                              "ply_import ignores `comment TextureFile`: no material or image")}


def _bpy_python(explicit: str | None) -> str | None:
    for candidate in (explicit, os.environ.get("FISHGEN_BPY_PYTHON"), "/tmp/bpyvenv/bin/python"):
        if candidate and Path(candidate).is_file():
            return candidate
    try:
        import bpy  # noqa: F401
        return sys.executable
    except ImportError:
        return None


def _judge_blender(asset: Asset, r: dict) -> str:
    expect("error" not in r, f"import failed: {r.get('error')}")
    # what the scene shows: not the coarser levels (an excluded collection), nor the importer's bone shapes
    meshes = [o for o in r["objects"]
              if o["type"] == "MESH" and o.get("visible", True) and not o.get("bone_shape")]
    expect(bool(meshes), "no mesh objects")
    exp = asset.expected
    tris = sum(o["triangles"] for o in meshes)
    verts = sum(o["vertices"] for o in meshes)
    notes = [f"{len(r['objects'])} objects"]
    if asset.fmt.kind == "fish" or "--billboards" in asset.fmt.flags:
        expect(tris == exp["triangles"], f"triangles: found {tris}, fishgen made {exp['triangles']}")
        expect(verts == exp["vertices"], f"vertices: found {verts}, fishgen made {exp['vertices']}")
        for o in meshes:
            mats = [m for m in o["materials"] if m["name"]]
            expect(bool(mats), f"{o['name']}: no material")
            for m in mats:
                imgs = [i for i in m["images"] if i["size"][0] > 0]
                expect(bool(imgs), f"{o['name']}: material {m['name']} has no image that loaded")
        images = sorted({i["name"] for o in meshes for m in o["materials"] for i in m["images"]})
        notes.append("images " + ", ".join(images))
        if asset.fmt.ext == "obj":
            alpha = [i for o in meshes for m in o["materials"] if m["name"].endswith("fins")
                     for i in m["images"] if "Principled BSDF.Alpha" in i["to"]]
            expect(bool(alpha), "fins: map_d mask not wired to Alpha")
            notes.append("mask → Alpha")
    else:
        expect(verts == exp["particles"], f"points: found {verts}, fishgen made {exp['particles']}")
        attrs = set().union(*(o["attributes"] for o in meshes))
        want = {"_RADIUS", "_DENSITY", "_CUBE"} if asset.fmt.ext == "glb" else {"radius", "density"}
        expect(want <= attrs, f"point attributes missing: {sorted(want - attrs)}")
        expect(any(o["color_attributes"] for o in meshes), "no colour attribute")
        notes.append("point attrs " + ", ".join(sorted(want)))
    if "--billboards" in asset.fmt.flags:
        expect(tris == 2 * exp["quads"], "quads != particles")
    if asset.engine is not None:
        notes += _judge_blender_engine(asset, r, meshes)
    elif asset.fmt.kind == "fish" and asset.fmt.ext in ("glb", "gltf"):
        swim = [a for a in r["actions"] if a["name"].startswith("swim")]
        expect(bool(swim), f"no swim action (actions: {[a['name'] for a in r['actions']]})")
        animated = [o["name"] for o in r["objects"] if (o.get("action") or "").startswith("swim")]
        expect(len(animated) == 4, f"swim drives {len(animated)} objects, expected the 4 paired fins")
        waving = [o["name"] for o in r["objects"] if o.get("shape_keys") == 4
                  and (o.get("shape_key_action") or "").startswith("swim")]
        expect(len(waving) == 9, f"the body wave drives the shape keys of {len(waving)} meshes, expected 9")
        notes.append(f"action swim: {swim[0]['channels']} F-curves on {len(animated)} fins; "
                     f"4 shape keys animated on {len(waving)} meshes")
    return "; ".join(notes)


def _judge_blender_engine(asset: Asset, r: dict, meshes: list[dict]) -> list[str]:
    """An engine fish: the finest level shown, skinned by an armature, its shape keys fishgen's
    targets, and an action for each clip."""
    engine = asset.engine
    assert engine is not None
    hidden = [o["name"] for o in r["objects"] if o["type"] == "MESH" and not o.get("visible", True)
              and not o.get("bone_shape")]
    expect(len(hidden) == len(engine.levels) - 1,
           f"{len(hidden)} hidden meshes, expected one a coarser level")
    for o in meshes:
        expect(o.get("armature") is not None, f"{o['name']}: no armature modifier")
        expect(o.get("shape_keys") == len(engine.targets), f"{o['name']}: {o.get('shape_keys')} shape keys, "
                                                            f"fishgen made {len(engine.targets)}")
    names = {a["name"] for a in r["actions"]}
    missing = [c for c in engine.clips if not any(n == c or n.startswith(f"{c}_") for n in names)]
    expect(not missing, f"no action for {missing} (actions: {sorted(names)})")
    return [f"LOD0 shown, {len(hidden)} coarser level(s) in an excluded collection",
            f"actions {', '.join(engine.clips)}"]


def run_blender(assets: dict[str, Asset], bpy_python: str) -> tuple[dict, str]:
    chosen = [a for a in assets.values() if a.fmt.ext in BLENDER_FORMATS and a.fmt.kind in BLENDER_KINDS]
    proc = subprocess.run([bpy_python, str(BLENDER_SCRIPT), *map(str, (a.path for a in chosen))],
                          capture_output=True, text=True, timeout=600)
    reports = [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
    if proc.returncode != 0 or len(reports) != len(chosen):
        raise SystemExit(f"bpy run failed (exit {proc.returncode}): {proc.stderr.strip()[-2000:]}")
    version = reports[0].get("blender", "?")
    results = {}
    for asset, report in zip(chosen, reports, strict=True):
        known = BLENDER_KNOWN.get(asset.label)
        try:
            note = _judge_blender(asset, report)
            cell = Cell(asset.label, "Blender", "pass", note)
            if known:
                cell = Cell(asset.label, "Blender", "fail", f"listed as known ({known[1]}) but passes")
        except CellFailure as e:
            reason = str(e)
            cell = (Cell(asset.label, "Blender", "known", known[1]) if known and known[0] in reason
                    else Cell(asset.label, "Blender", "fail", reason))
        cell.details = report
        results[(asset.label, "Blender")] = cell
    return results, version


def versions(matrix: Matrix) -> str:
    """The versions of the clients that ran, for the table's heading."""
    out = []
    three = json.loads((THREE_DIR / "package.json").read_text())["version"] if THREE_DIR.is_dir() else None
    if three and matrix._three is not None:
        out.append(f"three.js {three}")
    if matrix._babylon is not None:
        out.append(f"Babylon.js {matrix._babylon.version}")
    if matrix._godot is not None:
        out.append(f"Godot {matrix._godot.version}")
    return ", ".join(out)


def look(matrix: Matrix, folder: Path) -> None:
    """PNGs of every asset Babylon.js and Godot 3 load, from three sides, into ``folder``."""
    import math

    from tests.clients.godot import render

    folder.mkdir(parents=True, exist_ok=True)
    views = {"side": (0.0, math.pi / 2), "front": (math.pi / 2, math.pi / 2), "above": (0.0, 0.35)}
    babylon = matrix.babylon()
    if babylon is not None:
        for asset in matrix.assets.values():
            if asset.fmt.ext in ("glb", "gltf", "obj", "ply") and "error" not in babylon.inspect(asset):
                for side, (alpha, beta) in views.items():
                    babylon.screenshot(folder / f"babylon-{asset.fmt.slug}-{side}.png", alpha, beta)
    godot = matrix.godot()
    if godot is not None:
        why = render(godot, folder)
        if why:
            print(f"Godot pictures skipped: {why}", file=sys.stderr)
    print(f"pictures in {folder}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--blender", action="store_true",
                    help="import each format with Blender's bpy module instead")
    ap.add_argument("--bpy-python", help="a Python that can `import bpy` (default: $FISHGEN_BPY_PYTHON, "
                                         "/tmp/bpyvenv/bin/python, or this one)")
    ap.add_argument("--out", type=Path, help="folder for the generated assets (default: a temporary one)")
    ap.add_argument("--report", type=Path, default=ROOT / "out" / "client-matrix.md",
                    help="where to write the markdown table (default: out/client-matrix.md; "
                         "out/client-matrix-blender.md with --blender)")
    ap.add_argument("--json", action="store_true", help="also print every cell's details as JSON")
    ap.add_argument("--look", type=Path, metavar="DIR",
                    help="save PNGs of each asset as Babylon.js (and Godot 3, with `godot3` and `xvfb-run`) "
                         "draws it, from the side, the front and above")
    args = ap.parse_args(argv)

    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="fishgen-clients-") as tmp:
        folder = args.out or Path(tmp)
        matrix = Matrix(folder, godot_now=not args.blender)
        try:
            if args.blender:
                bpy_python = _bpy_python(args.bpy_python)
                if bpy_python is None:
                    print("no Python with bpy: "
                          "python3.11 -m venv /tmp/bpyvenv && /tmp/bpyvenv/bin/pip install bpy",
                          file=sys.stderr)
                    return 1
                results, version = run_blender(matrix.assets, bpy_python)
                clients: tuple[str, ...] = ("Blender",)
                title = f"Blender {version} (bpy)"
            else:
                matrix.run_all()
                results, clients, title = matrix.results, CLIENTS, versions(matrix)
                if args.look:
                    look(matrix, args.look)
        finally:
            matrix.close()
    seconds = time.perf_counter() - start
    rows = [f for f in FORMATS if any((f.label, c) in results for c in clients)]
    text = table(results, clients)
    if args.blender:
        text = "\n".join(line for line in text.splitlines()
                         if not line.startswith("| ") or any(line.startswith(f"| {f.label} |") for f in rows)
                         or line.startswith("| format"))
    report = args.report
    if args.blender and report == ap.get_default("report"):
        report = ROOT / "out" / "client-matrix-blender.md"
    report.parent.mkdir(parents=True, exist_ok=True)
    if args.blender:
        report.write_text(f"# fishgen in {title}\n\n{text}\n\n{len(results)} cells in {seconds:.1f} s.\n",
                          encoding="utf-8")
    else:
        write_report(results, report, seconds)
    if title:
        print(title)
    print(text)
    print(f"\n{len(results)} cells in {seconds:.1f} s; table written to {report}")
    if args.json:
        print(json.dumps({f"{k[0]} / {k[1]}": {"status": c.status, "reason": c.reason, "details": c.details}
                          for k, c in results.items()}, indent=1, default=str))
    bad = [c for c in results.values() if c.status == "fail"]
    for c in bad:
        print(f"FAIL {c.label} / {c.client}: {c.reason}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
