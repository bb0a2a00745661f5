#!/usr/bin/env python3
"""Regenerate the README's cross-species `fishgen texture --fit-shape` pictures (issue 25).

    python docs/make_fit_renders.py

Each picture is a fish fishgen does not ship, photographed by three.js in headless Chromium (lit by
an environment map and a sun, fins translucent, a slight perspective, turned off side-on;
tests/authoring/threejs.py), made into a species with `fishgen texture --fit-shape` on a shipped
species of another shape, and the rebuilt fish beside the photo (`--compare`):

- docs/images/fit-sampled7-on-bonybream.png: `fishgen species --random --seed 7` over open water,
  turned 20 degrees, on BonyBream;
- docs/images/fit-deep-on-threadfingoldie.png: a deep, angelfish-like body on the slender goldie;
- docs/images/fit-longdorsal-on-pineapplefish.png: a long, low dorsal fin on the 8 x 6 pineapple
  fish, whose sections cannot hold it (the fit uses more).

Needs Chromium, playwright and node_modules/three (`bash tools/test.sh` installs them).
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
IMAGES = ROOT / "docs" / "images"

CASES = (  # (subject, photo kind, base, picture)
    ("sampled_7", "lit+water", "bonybream", "fit-sampled7-on-bonybream.png"),
    ("deep", "lit", "threadfingoldie", "fit-deep-on-threadfingoldie.png"),
    ("long-dorsal", "lit", "pineapplefish", "fit-longdorsal-on-pineapplefish.png"),
)


def main() -> int:
    from tests.authoring.subjects import write_subjects
    from tests.authoring.threejs import ThreePhotographer, lit_photo, unavailable

    if unavailable() is not None:
        print(f"needs three.js in Chromium: {unavailable()}")
        return 1
    IMAGES.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="fishgen-docs-") as tmp:
        work = Path(tmp)
        subjects = write_subjects(work / "subjects")
        camera = ThreePhotographer(work / "assets")
        try:
            for subject, kind, base, picture in CASES:
                photo, _ = lit_photo(camera, subjects[subject], kind)
                path = work / f"{subject}.png"
                photo.save(path)
                args = ["texture", str(path), "-s", f"params/{base}.txt", "-o", str(work / "new" / f"{subject}.txt"),
                        "--fit-shape", "--compare", str(IMAGES / picture)]
                print("fishgen " + " ".join(args))
                subprocess.run([sys.executable, "-m", "fishgen", *args], cwd=ROOT, check=True)
        finally:
            camera.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
