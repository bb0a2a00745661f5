#!/usr/bin/env python3
"""Regenerate the README's pictures of `fishgen texture` and `fishgen species --random`.

    python docs/make_authoring_renders.py

- docs/images/random-species.png: 16 species from `fishgen species --random --seed 100
  --count 16`, side views in one contact sheet.
- docs/images/texture-compare.png: a "photo" (seed 106's species rendered side-on on a plain
  backdrop, saved as JPEG, turned 6 degrees and mirrored) made into a species with
  `fishgen texture -s params/bonybream.txt --fit-shape --compare`: photo left, rebuilt right.
- docs/images/texture-roundtrip.png: the same for a photo of threadfingoldie on its own base.

No real photographs ship with fishgen (licences); the photos are renders of species the
command has never seen as species files, on backdrops it has to model.
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image, ImageOps

ROOT = Path(__file__).resolve().parents[1]
IMAGES = ROOT / "docs" / "images"


def fishgen(*args: str) -> None:
    print("fishgen " + " ".join(args))
    subprocess.run([sys.executable, "-m", "fishgen", *args], cwd=ROOT, check=True, stdout=subprocess.DEVNULL)


def photo_of(species: Path, out: Path, turn: float, mirror: bool) -> None:
    """A side render on a plain backdrop, turned and mirrored like a hand-held shot, as JPEG."""
    png = out.with_suffix(".png")
    fishgen("preview", str(species), "--view", "side", "--ortho", "--background", "#dde6ee",
            "--size", "800x400", "-o", str(png))
    img = Image.open(png).convert("RGB")
    img = img.rotate(turn, resample=Image.Resampling.BICUBIC, expand=True, fillcolor=(221, 230, 238))
    if mirror:
        img = ImageOps.mirror(img)
    img.save(out, quality=85)


def main() -> int:
    IMAGES.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="fishgen-docs-") as tmp:
        work = Path(tmp)
        fishgen("species", "--random", "--seed", "100", "--count", "16", "-o", str(work / "reef"))
        fishgen("preview", *sorted(map(str, (work / "reef").glob("*.txt"))), "--view", "side",
                "--size", "320x200", "--columns", "4", "-o", str(IMAGES / "random-species.png"))
        fishgen("species", "--random", "--seed", "106", "-o", str(work / "stranger.txt"))
        photo_of(work / "stranger.txt", work / "stranger.jpg", 6.0, True)
        fishgen("texture", str(work / "stranger.jpg"), "-s", "params/bonybream.txt",
                "-o", str(work / "new" / "fish.txt"), "--fit-shape",
                "--compare", str(IMAGES / "texture-compare.png"))
        photo_of(ROOT / "params" / "threadfingoldie.txt", work / "goldie.jpg", -8.0, False)
        fishgen("texture", str(work / "goldie.jpg"), "-s", "params/threadfingoldie.txt", "-o",
                str(work / "new" / "goldie.txt"), "--compare", str(IMAGES / "texture-roundtrip.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
