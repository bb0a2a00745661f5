#!/usr/bin/env python3
"""Copy the three.js modules the viewer needs from node_modules into the package.

Run after `npm ci` whenever package.json changes three's version:

    python tools/bundle_viewer.py          # writes fishgen/viewer/static/
    python tools/bundle_viewer.py --check  # exit 1 if the committed copy is stale

The copies are committed, so `pip install` needs no node and `fishgen view`
never fetches anything. Relative imports are rewritten to bare specifiers
(`three`, `three/addons/...`): the page loads each module from a blob: URL
through an import map, and blob: URLs have no directory to be relative to.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
THREE = ROOT / "node_modules" / "three"
STATIC = ROOT / "fishgen" / "viewer" / "static"

# import-map specifier -> file inside the three package
MODULES = {
    "three/core": "build/three.core.js",
    "three": "build/three.module.js",
    "three/addons/controls/OrbitControls.js": "examples/jsm/controls/OrbitControls.js",
    "three/addons/loaders/GLTFLoader.js": "examples/jsm/loaders/GLTFLoader.js",
    "three/addons/loaders/PLYLoader.js": "examples/jsm/loaders/PLYLoader.js",
    "three/addons/loaders/OBJLoader.js": "examples/jsm/loaders/OBJLoader.js",
    "three/addons/loaders/MTLLoader.js": "examples/jsm/loaders/MTLLoader.js",
    "three/addons/utils/BufferGeometryUtils.js": "examples/jsm/utils/BufferGeometryUtils.js",
    "three/addons/utils/SkeletonUtils.js": "examples/jsm/utils/SkeletonUtils.js",
}
_IMPORT = re.compile(r"""(\bfrom\s*|\bimport\s*\(?\s*)(['"])(\.{1,2}/[^'"]+)\2""")


def _specifier(importer: str, relative: str) -> str:
    target = (Path(importer).parent / relative).as_posix()
    parts: list[str] = []
    for piece in target.split("/"):
        if piece == "..":
            parts.pop()
        elif piece not in ("", "."):
            parts.append(piece)
    target = "/".join(parts)
    for spec, file in MODULES.items():
        if file == target:
            return spec
    raise SystemExit(f"{importer} imports {relative} ({target}), which is not bundled: add it to MODULES")


def bundled() -> dict[str, bytes]:
    """file name in static/ -> rewritten module text, plus manifest and licence."""
    version = json.loads((THREE / "package.json").read_text())["version"]
    out: dict[str, bytes] = {}
    manifest = {"three": version, "source": "npm package three (node_modules/three)", "modules": {}}
    for spec, file in MODULES.items():
        text = (THREE / file).read_text(encoding="utf-8")
        text = _IMPORT.sub(lambda m: f"{m[1]}{m[2]}{_specifier(file, m[3])}{m[2]}", text)
        name = Path(file).name
        out[name] = text.encode("utf-8")
        manifest["modules"][spec] = {"file": name, "from": file,
                                     "sha256": hashlib.sha256(out[name]).hexdigest()}
    out["THREE-LICENSE"] = (THREE / "LICENSE").read_bytes()
    out["manifest.json"] = (json.dumps(manifest, indent=1) + "\n").encode()
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare instead of writing")
    args = parser.parse_args()
    if not THREE.is_dir():
        print("node_modules/three is missing: run `npm ci` in the project root", file=sys.stderr)
        return 2
    files = bundled()
    if args.check:
        stale = [n for n, data in files.items()
                 if not (STATIC / n).is_file() or (STATIC / n).read_bytes() != data]
        for name in stale:
            print(f"stale: fishgen/viewer/static/{name}", file=sys.stderr)
        return 1 if stale else 0
    STATIC.mkdir(parents=True, exist_ok=True)
    for name, data in files.items():
        (STATIC / name).write_bytes(data)
    print(f"bundled three {json.loads(files['manifest.json'])['three']} into {STATIC.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
