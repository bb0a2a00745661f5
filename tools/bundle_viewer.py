#!/usr/bin/env python3
"""Bundle fishgen's pages: one kit (three.js + the shared modules) and each page's own app, minified.

Run after `npm ci` whenever a page's JavaScript or package.json (three's or esbuild's version) changes:

    python tools/bundle_viewer.py                 # writes fishgen/web/static/
    python tools/bundle_viewer.py --check         # exit 1 unless a rebuild gives the committed bytes
    python tools/bundle_viewer.py --check-hashes  # no node needed: exit 1 if a committed bundle
                                                  # or a source differs from what manifest.json records

esbuild (pinned in package.json) bundles fishgen/web/kit.js - the parts of three.js the pages use
(three-parts.js), its addons and the modules the pages share (fishgen/web/cloudlight.js, drawing.js) -
into `kit.min.js`, a classic script that sets `window.fishgenKit`, and each page's app.js (with its own
modules) into `<page>.min.js`, which takes three.js from that kit and so holds none of it. The bundles
are committed in fishgen/web/static/ with `manifest.json` (sha256 of every bundle and of every input
file esbuild read, the tool versions and options) and three's licence, so `pip install` needs no node
and no page fetches anything. Every page inlines the kit and its app (fishgen/web/page.py). A page is
one line in BUNDLES.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NODE_MODULES = ROOT / "node_modules"
STATIC = ROOT / "fishgen" / "web" / "static"
KIT = "kit"
#: bundle -> its entry module; the bundle is STATIC / f"{name}.min.js"
BUNDLES = {
    KIT: "fishgen/web/kit.js",
    "viewer": "fishgen/viewer/app.js",
    "editor": "fishgen/editor/app.js",
    "fly": "fishgen/fly/app.js",
}
LICENSE = "THREE-LICENSE"
# Fixed options, so the same inputs and esbuild version give the same bytes; symlinks kept, so a
# worktree's node_modules linked to another checkout's is recorded as node_modules/ all the same.
OPTIONS = ["--bundle", "--minify", "--target=es2022", "--charset=ascii", "--legal-comments=eof",
           "--preserve-symlinks", "--log-level=warning"]
FORMAT = {KIT: ["--format=iife", "--global-name=fishgenKit"]}
"""The kit is a classic script that sets window.fishgenKit; the apps are modules (the default below)."""
APP_FORMAT = ["--format=esm"]
# The page inlines each bundle in a <script> element: these would end or confuse it.
UNSAFE_IN_SCRIPT = re.compile(r"</script|<!--|<script", re.I)
THREE_PARTS = "fishgen/web/three-parts.js"
"""The kit's THREE: the names of three.js the pages may use."""
_EXPORTS = re.compile(r"export \{(.*?)\} from 'three';", re.S)
_USES_THREE = re.compile(r"\bTHREE\.([A-Za-z_$][\w$]*)")


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _version(package: str) -> str:
    return json.loads((NODE_MODULES / package / "package.json").read_text())["version"]


def file_name(bundle: str) -> str:
    return f"{bundle}.min.js"


def _esbuild(name: str, tmp: Path) -> tuple[bytes, list[str]]:
    """One bundle's bytes and the files esbuild read for it (relative to ROOT)."""
    out, meta = tmp / file_name(name), tmp / f"{name}.meta.json"
    options = [*OPTIONS, *FORMAT.get(name, APP_FORMAT)]
    run = subprocess.run([str(NODE_MODULES / ".bin" / "esbuild"), BUNDLES[name], *options,
                          f"--outfile={out}", f"--metafile={meta}"], cwd=ROOT, capture_output=True, text=True)
    if run.returncode != 0:
        raise SystemExit(f"esbuild failed for {name}:\n{run.stderr}")
    if run.stderr.strip():  # warnings: a page's bundle should build cleanly
        raise SystemExit(f"esbuild warned for {name}:\n{run.stderr}")
    bundle = out.read_bytes()
    unsafe = UNSAFE_IN_SCRIPT.search(bundle.decode("ascii"))
    if unsafe:
        raise SystemExit(f"the {name} bundle contains {unsafe[0]!r}, which cannot sit inside a <script> "
                         "element")
    return bundle, sorted(json.loads(meta.read_text())["inputs"])


def _check_apps(inputs: dict[str, list[str]]) -> None:
    """Each app takes three.js from the kit: it bundles none of it and uses no THREE name the kit lacks."""
    parts = _EXPORTS.search((ROOT / THREE_PARTS).read_text(encoding="utf-8"))
    if parts is None:
        raise SystemExit(f"{THREE_PARTS}: expected `export {{ ... }} from 'three';`")
    exported = set(re.findall(r"\w+", parts[1]))
    for name, files in inputs.items():
        if name == KIT:
            continue
        three = [f for f in files if f.startswith("node_modules/")]
        if three:
            raise SystemExit(f"{name} imports {three[0]}: take it from window.fishgenKit ({BUNDLES[KIT]})")
        used = {m for f in files for m in _USES_THREE.findall((ROOT / f).read_text(encoding="utf-8"))}
        if used - exported:
            raise SystemExit(f"{name} uses THREE.{', THREE.'.join(sorted(used - exported))}: "
                             f"add to {THREE_PARTS}")


def build() -> dict[str, bytes]:
    """File name in STATIC -> contents: the bundles, three's licence and the manifest."""
    files: dict[str, bytes] = {}
    inputs: dict[str, list[str]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in BUNDLES:
            files[file_name(name)], inputs[name] = _esbuild(name, Path(tmp))
    _check_apps(inputs)
    licence = (NODE_MODULES / "three" / "LICENSE").read_bytes()
    manifest = {
        "tools": {"esbuild": _version("esbuild"), "three": _version("three")},
        "options": OPTIONS,
        "bundles": {name: {"file": file_name(name), "entry": entry, "format": FORMAT.get(name, APP_FORMAT),
                           "bytes": len(files[file_name(name)]), "sha256": _sha256(files[file_name(name)]),
                           "inputs": {f: _sha256((ROOT / f).read_bytes()) for f in inputs[name]}}
                    for name, entry in BUNDLES.items()},
        "license": {"file": LICENSE, "from": "node_modules/three/LICENSE", "sha256": _sha256(licence)},
    }
    return {**files, LICENSE: licence, "manifest.json": (json.dumps(manifest, indent=1) + "\n").encode()}


def check_hashes(static: Path) -> list[str]:
    """Problems with the committed files that need no node to find (empty: consistent)."""
    try:
        manifest = json.loads((static / "manifest.json").read_text())
        entries = [*manifest["bundles"].values(), manifest["license"]]
    except (OSError, ValueError, KeyError, AttributeError) as err:
        return [f"manifest.json unreadable: {err!r}"]
    problems = []
    expected = {entry["file"] for entry in entries} | {"manifest.json"}
    extra = sorted(p.name for p in static.iterdir() if p.name not in expected)
    if extra:
        problems.append(f"files not in the manifest (delete them): {', '.join(extra)}")
    missing = sorted(set(BUNDLES) - set(manifest["bundles"]))
    if missing:
        problems.append(f"bundles missing from the manifest: {', '.join(missing)}")
    for entry in entries:
        path = static / entry["file"]
        if not path.is_file() or _sha256(path.read_bytes()) != entry["sha256"]:
            problems.append(f"{entry['file']} differs from its sha256 in manifest.json")
    for bundle in manifest["bundles"].values():
        for name, digest in bundle["inputs"].items():
            # Inputs in the repository are always checkable; node_modules ones only after `npm ci`.
            if name.startswith("node_modules/") and not NODE_MODULES.is_dir():
                continue
            path = ROOT / name
            if not path.is_file() or _sha256(path.read_bytes()) != digest:
                problems.append(f"{name} changed since the bundles were built: "
                                "run python tools/bundle_viewer.py")
    return problems


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--check", action="store_true",
                      help="rebuild in memory and compare with the committed files (needs npm ci)")
    mode.add_argument("--check-hashes", action="store_true",
                      help="compare the committed files and sources with manifest.json (no node needed)")
    parser.add_argument("--static", type=Path, default=STATIC, help=argparse.SUPPRESS)  # for tests
    args = parser.parse_args()
    static: Path = args.static
    if args.check_hashes:
        return _report(check_hashes(static))
    if not (NODE_MODULES / ".bin" / "esbuild").exists() or not (NODE_MODULES / "three").is_dir():
        print("node_modules/esbuild or node_modules/three is missing: run `npm ci` in the project root",
              file=sys.stderr)
        return 2
    files = build()
    if args.check:
        return _report(check_hashes(static) + [
            f"{name} is not what a rebuild gives" for name, data in files.items()
            if not (static / name).is_file() or (static / name).read_bytes() != data])
    static.mkdir(parents=True, exist_ok=True)
    for old in static.iterdir():
        if old.is_file() and old.name not in files:
            old.unlink()  # bundles of an older layout, say
    for name, data in files.items():
        (static / name).write_bytes(data)
    shown = static.relative_to(ROOT) if static.is_relative_to(ROOT) else static
    manifest = json.loads(files["manifest.json"])
    sizes = ", ".join(f"{name} {len(files[file_name(name)]):,}" for name in BUNDLES)
    print(f"bundled with three {manifest['tools']['three']} (esbuild {manifest['tools']['esbuild']}) "
          f"in {shown}: {sizes} bytes")
    return 0


def _report(problems: list[str]) -> int:
    for problem in problems:
        print(f"stale: {problem}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
