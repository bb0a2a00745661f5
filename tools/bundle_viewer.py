#!/usr/bin/env python3
"""Bundle each of fishgen's pages (its app.js + the parts of three.js it uses) into one minified file.

Run after `npm ci` whenever a page's app.js or package.json (three's or esbuild's version) changes:

    python tools/bundle_viewer.py                 # every page: writes fishgen/<page>/static/
    python tools/bundle_viewer.py --page viewer   # one page
    python tools/bundle_viewer.py --check         # exit 1 unless a rebuild gives the committed bytes
    python tools/bundle_viewer.py --check-hashes  # no node needed: exit 1 if a committed bundle
                                                  # or its app.js differ from what manifest.json records

The pages are listed in PAGES: a new page is one line there.

esbuild (pinned in package.json) resolves app.js's imports (`three`,
`three/addons/...`) in node_modules, drops what the viewer never calls, and
minifies. The result, `static/viewer.min.js`, is committed together with
`static/manifest.json` (sha256 of the bundle and of every input file esbuild
read, the tool versions and options) and three's licence, so `pip install`
needs no node and `fishgen view` never fetches anything. The page inlines the
bundle as one module script (fishgen/viewer/page.py).
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
#: page -> (its entry module, the folder its bundle is committed in, the bundle's file name)
PAGES = {
    "viewer": ("fishgen/viewer/app.js", ROOT / "fishgen" / "viewer" / "static", "viewer.min.js"),
    "editor": ("fishgen/editor/app.js", ROOT / "fishgen" / "editor" / "static", "editor.min.js"),
    "fly": ("fishgen/fly/app.js", ROOT / "fishgen" / "fly" / "static", "fly.min.js"),
}
STATIC = PAGES["viewer"][1]
LICENSE = "THREE-LICENSE"
# Fixed options, so the same inputs and esbuild version give the same bytes.
OPTIONS = ["--bundle", "--format=esm", "--minify", "--target=es2022", "--charset=ascii",
           "--legal-comments=eof", "--log-level=warning"]
# The page inlines the bundle in a <script> element: these would end or confuse it.
UNSAFE_IN_SCRIPT = re.compile(r"</script|<!--|<script", re.I)


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _version(package: str) -> str:
    return json.loads((NODE_MODULES / package / "package.json").read_text())["version"]


def build(page: str = "viewer") -> dict[str, bytes]:
    """File name in the page's static/ -> contents: the bundle, three's licence and the manifest."""
    entry, _, bundle_name = PAGES[page]
    esbuild = NODE_MODULES / ".bin" / "esbuild"
    with tempfile.TemporaryDirectory() as tmp:
        out, meta = Path(tmp) / bundle_name, Path(tmp) / "meta.json"
        run = subprocess.run([str(esbuild), entry, *OPTIONS, f"--outfile={out}", f"--metafile={meta}"],
                             cwd=ROOT, capture_output=True, text=True)
        if run.returncode != 0:
            raise SystemExit(f"esbuild failed:\n{run.stderr}")
        if run.stderr.strip():  # warnings: a viewer bundle should build cleanly
            raise SystemExit(f"esbuild warned:\n{run.stderr}")
        bundle = out.read_bytes()
        inputs = sorted(json.loads(meta.read_text())["inputs"])  # paths relative to ROOT
    unsafe = UNSAFE_IN_SCRIPT.search(bundle.decode("ascii"))
    if unsafe:
        raise SystemExit(f"the bundle contains {unsafe[0]!r}, which cannot sit inside a <script> element")
    licence = (NODE_MODULES / "three" / "LICENSE").read_bytes()
    manifest = {
        "bundle": {"file": bundle_name, "bytes": len(bundle), "sha256": _sha256(bundle)},
        "entry": entry,
        "tools": {"esbuild": _version("esbuild"), "three": _version("three")},
        "options": OPTIONS,
        "inputs": {name: _sha256((ROOT / name).read_bytes()) for name in inputs},
        "license": {"file": LICENSE, "from": "node_modules/three/LICENSE", "sha256": _sha256(licence)},
    }
    return {bundle_name: bundle, LICENSE: licence,
            "manifest.json": (json.dumps(manifest, indent=1) + "\n").encode()}


def check_hashes(static: Path) -> list[str]:
    """Problems with the committed files that need no node to find (empty: consistent)."""
    try:
        manifest = json.loads((static / "manifest.json").read_text())
    except (OSError, ValueError) as err:
        return [f"manifest.json unreadable: {err}"]
    problems = []
    expected = {manifest["bundle"]["file"], manifest["license"]["file"], "manifest.json"}
    extra = sorted(p.name for p in static.iterdir() if p.name not in expected)
    if extra:
        problems.append(f"files not in the manifest (delete them): {', '.join(extra)}")
    for entry in (manifest["bundle"], manifest["license"]):
        path = static / entry["file"]
        if not path.is_file() or _sha256(path.read_bytes()) != entry["sha256"]:
            problems.append(f"{entry['file']} differs from its sha256 in manifest.json")
    for name, digest in manifest["inputs"].items():
        # Inputs in the repository are always checkable; node_modules ones only after `npm ci`.
        path = ROOT / name
        if name.startswith("node_modules/") and not NODE_MODULES.is_dir():
            continue
        if not path.is_file() or _sha256(path.read_bytes()) != digest:
            problems.append(f"{name} changed since the bundle was built: run python tools/bundle_viewer.py")
    return problems


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--check", action="store_true",
                      help="rebuild in memory and compare with the committed files (needs npm ci)")
    mode.add_argument("--check-hashes", action="store_true",
                      help="compare the committed files and app.js with manifest.json (no node needed)")
    parser.add_argument("--page", choices=sorted(PAGES), action="append", help="a page (default: every page)")
    parser.add_argument("--static", type=Path, default=None, help=argparse.SUPPRESS)  # for tests: one page
    args = parser.parse_args()
    pages = args.page or sorted(PAGES)
    if args.static is not None and len(pages) != 1:
        pages = ["viewer"]
    status = 0
    for page in pages:
        static = args.static or PAGES[page][1]
        status = max(status, _one(page, static, args.check, args.check_hashes))
    return status


def _one(page: str, static: Path, check: bool, hashes_only: bool) -> int:
    if hashes_only:
        problems = check_hashes(static)
        for problem in problems:
            print(f"stale: {page}: {problem}", file=sys.stderr)
        return 1 if problems else 0
    if not (NODE_MODULES / ".bin" / "esbuild").exists() or not (NODE_MODULES / "three").is_dir():
        print("node_modules/esbuild or node_modules/three is missing: run `npm ci` in the project root",
              file=sys.stderr)
        return 2
    files = build(page)
    if check:
        problems = check_hashes(static)
        problems += [f"{name} is not what a rebuild gives" for name, data in files.items()
                     if not (static / name).is_file() or (static / name).read_bytes() != data]
        for problem in problems:
            print(f"stale: {page}: {problem}", file=sys.stderr)
        return 1 if problems else 0
    static.mkdir(parents=True, exist_ok=True)
    for old in static.iterdir():
        if old.is_file() and old.name not in files:
            old.unlink()  # modules of an older layout, say
    for name, data in files.items():
        (static / name).write_bytes(data)
    manifest = json.loads(files["manifest.json"])
    shown = static.relative_to(ROOT) if static.is_relative_to(ROOT) else static
    print(f"bundled {PAGES[page][0]} with three {manifest['tools']['three']} (esbuild "
          f"{manifest['tools']['esbuild']}): {len(files[PAGES[page][2]]):,} bytes in {shown}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
