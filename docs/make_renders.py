#!/usr/bin/env python3
"""Regenerate the README's renders in docs/images/ with `fishgen preview`.

    python docs/make_renders.py          # every render
    python docs/make_renders.py --list   # what would be rendered

One still per shipped species (params/*.txt) and per report cloud
(params/clouds/*.awn), a side-view contact sheet of the species, a swim loop,
the engine fish's clips, the reef and a small school (and the reef's measures,
by `fishgen school --plot`). The README's other pictures come from other
scripts or by hand (docs/preview.md lists each). Run it (and look at the images) whenever a change is meant to alter how
an asset looks. The tests do not diff against these files; they measure each
part instead (tests/preview/test_reference.py).
"""
from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
IMAGES = ROOT / "docs" / "images"
STILL_SIZE = "640x480"


def stills() -> list[tuple[str, list[str]]]:
    """(output name, `fishgen preview` arguments without -o) for every still render."""
    inputs = sorted((ROOT / "params").glob("*.txt")) + sorted((ROOT / "params" / "clouds").glob("*.awn"))
    return [(f"{p.stem}.png", [str(p.relative_to(ROOT)), "--size", STILL_SIZE]) for p in inputs]


def extras() -> list[tuple[str, list[str]]]:
    species = [str(p.relative_to(ROOT)) for p in sorted((ROOT / "params").glob("*.txt"))]
    out = []
    if species:
        out.append(("species-side.png", [*species, "--view", "side", "--size", "400x300"]))
    if (ROOT / "params" / "bonybream.txt").is_file():
        # from above: the body wave is a sideways motion
        out.append(("bonybream-swim.gif", ["params/bonybream.txt", "--size", "400x300", "--view", "top"]))
    return out


SCHOOL = ["school", "params/reef.toml", "-o", "out/reef.glb", "--plot", "docs/images/reef-measures.png"]
"""The README's school: the shipped reef scene, baked first, then previewed as a loop."""
SMALL_SCHOOL = ["school", "params/bonybream.txt", "--count", "10", "--frames", "150", "--seed", "3",
                "-o", "out/school-swim.glb"]
"""A small school seen close enough to watch the bodies swim."""


CLIPS = ("swim", "idle", "sprint", "turn_left", "turn_right", "burst")
ENGINE_FISH = ["build", "params/bonybream.txt", "--lods", "32x24,16x12,8x6", "--merge", "--clips", ",".join(CLIPS),
               "-o", "out/engine-fish.glb"]
"""The README's engine-ready fish: every clip, three levels, two draw calls."""


def clips_gif(out: Path, cell: tuple[int, int] = (240, 180), frames: int = 24) -> None:
    """Each clip of ENGINE_FISH looped from above, in a labelled 3 x 2 grid (one `fishgen preview` per
    clip, each clip's own length spread over the same frames)."""
    import tempfile

    from PIL import Image, ImageDraw, ImageSequence

    loops = []
    with tempfile.TemporaryDirectory() as tmp:
        for clip in CLIPS:
            gif = Path(tmp) / f"{clip}.gif"
            subprocess.run([sys.executable, "-m", "fishgen", "preview", "out/engine-fish.glb", "-o", str(gif),
                            "--clip", clip, "--view", "top", "--size", f"{cell[0]}x{cell[1]}",
                            "--frames", str(frames)], cwd=ROOT, check=True)
            with Image.open(gif) as im:
                loops.append([f.convert("RGB") for f in ImageSequence.Iterator(im)])
    sheet = []
    for k in range(frames):
        frame = Image.new("RGB", (cell[0] * 3, cell[1] * 2))
        for n, (clip, loop) in enumerate(zip(CLIPS, loops, strict=True)):
            x, y = (n % 3) * cell[0], (n // 3) * cell[1]
            frame.paste(loop[k % len(loop)], (x, y))
            ImageDraw.Draw(frame).text((x + 6, y + 4), clip, fill=(20, 30, 40))
        sheet.append(frame)
    sheet[0].save(out, save_all=True, append_images=sheet[1:], duration=83, loop=0, optimize=True)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", action="store_true", help="print the renders and exit")
    args = parser.parse_args()
    jobs = stills() + extras() + [("reef.gif", ["out/reef.glb", "--size", "480x360", "--view", "top",
                                                "--duration", "10", "--fps", "8"]),
                                  ("school-swim.gif", ["out/school-swim.glb", "--size", "560x380", "--time",
                                                       "2.5", "--duration", "2.5", "--fps", "12"])]
    IMAGES.mkdir(parents=True, exist_ok=True)
    if not args.list:
        subprocess.run([sys.executable, "-m", "fishgen", *ENGINE_FISH], cwd=ROOT, check=True)
        clips_gif(IMAGES / "engine-clips.gif")
    for school in (SCHOOL, SMALL_SCHOOL):
        print(" ".join(["fishgen", *school]))
        if not args.list:
            subprocess.run([sys.executable, "-m", "fishgen", *school], cwd=ROOT, check=True,
                           stdout=subprocess.DEVNULL)
    for name, argv in jobs:
        command = [sys.executable, "-m", "fishgen", "preview", *argv, "-o", str(IMAGES / name)]
        print(" ".join(["fishgen", "preview", *argv, "-o", f"docs/images/{name}"]))
        if not args.list:
            subprocess.run(command, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    return 0


if __name__ == "__main__":
    sys.exit(main())
