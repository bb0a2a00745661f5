"""Every sample of `fishgen species --random` for seeds 0..N-1, painted, built, exported as glb
and run through the Khronos glTF-Validator in one batch.

    python benchmarks/species.py [--count 500]

Prints the seconds each stage took and the validator's totals; exits 1 if any
file has an error or a warning. (tests/authoring/test_sampler.py parses and
builds all 500 and validates every 25th; this script validates them all.)
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import fishgen  # noqa: E402
from fishgen.authoring.species_files import sample_files  # noqa: E402
from fishgen.species.parser import load_species  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--count", type=int, default=500)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        start = time.perf_counter()
        paths = []
        for seed in range(args.count):
            for name, data in sample_files(seed, f"s{seed}").items():
                (folder / name).write_bytes(data)
            out = folder / f"s{seed}.glb"
            fishgen.export(fishgen.build_fish(load_species(folder / f"s{seed}.txt")), out)
            paths.append(out)
        built = time.perf_counter() - start
        start = time.perf_counter()
        proc = subprocess.run(["node", str(ROOT / "tools" / "validate_gltf.mjs"), *map(str, paths)],
                              cwd=ROOT, capture_output=True, text=True, check=True)
        checked = time.perf_counter() - start
    reports = json.loads(proc.stdout)
    errors = sum(r["numErrors"] for r in reports)
    warnings = sum(r["numWarnings"] for r in reports)
    bad = [Path(r["file"]).name for r in reports if r["numErrors"] or r["numWarnings"]]
    print(f"{len(reports)} samples: sampled, painted, built and exported in {built:.1f} s, "
          f"validated in {checked:.1f} s; {errors} errors, {warnings} warnings"
          + (f" in {', '.join(bad[:10])}" if bad else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
