"""Measured accuracy of `fishgen texture` on synthetic photos of the shipped species.

    python benchmarks/texture.py            # a table: species x photo kind
    python benchmarks/texture.py --fit      # and --fit-shape: each photo on each base species

Each photo is an orthographic side render (tests/authoring/photos.py), varied as
the robustness tests vary it. Columns: the rebuilt fish's silhouette IoU against
the photo's (in the fish's own level, head-left frame), the worst and mean body
texture point error and the worst fin point error, as fractions of the texture
size, and the seconds `make_texture` took. A three.js row (photos from three.js in
Chromium, tests/authoring/threejs.py) is added when Chromium and node_modules/three are there.
"""
from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fishgen.authoring.photo.compare import silhouette_iou  # noqa: E402
from fishgen.authoring.photo.run import make_texture  # noqa: E402
from fishgen.species.parser import load_species  # noqa: E402
from tests.authoring import photos as ph  # noqa: E402
from tests.authoring.test_photo_roundtrip import KINDS  # noqa: E402


def main() -> None:
    from tests.authoring.threejs import ThreePhotographer, unavailable

    print(f"{'species':16s} {'photo':15s} {'IoU':>6s} {'body max':>9s} {'body mean':>9s} "
          f"{'worst fin':>18s} {'s':>5s}")
    three = None
    if unavailable() is None:
        three = ThreePhotographer(Path(tempfile.mkdtemp(prefix="fishgen-three-")))
    for name in ("bonybream", "centroberyx", "pineapplefish", "threadfingoldie"):
        species = load_species(ROOT / "params" / f"{name}.txt")
        clean = ph.render_photo(species)
        kinds = dict(KINDS)
        if three is not None:
            shot = three.photo(species)
            kinds["three.js"] = lambda _p, shot=shot: shot
        for kind, make in kinds.items():
            photo = make(clean)
            with tempfile.TemporaryDirectory() as tmp:
                path = Path(tmp) / "photo.png"
                photo.save(path)
                start = time.perf_counter()
                result = make_texture(path, species, Path(tmp) / "new.txt")
                seconds = time.perf_counter() - start
                rebuilt = load_species(Path(tmp) / "new.txt")
                body, fins = ph.errors(rebuilt, photo)
                iou = silhouette_iou(result.level_mask, ph.rendered_mask(rebuilt))
            worst = max(fins, key=lambda n: fins[n])
            print(f"{name:16s} {kind:15s} {iou:6.3f} {body.max():9.4f} {body.mean():9.4f} "
                  f"{worst + ' ' + format(fins[worst], '.4f'):>18s} {seconds:5.2f}")
    if three is not None:
        three.close()


def fit_table() -> None:
    """--fit-shape across bases: the rebuilt fish's IoU with the base's geometry and with the fit."""
    from fishgen.authoring.photo.run import TextureOptions

    names = ("bonybream", "centroberyx", "pineapplefish", "threadfingoldie")
    print(f"\n{'photo of':16s} {'base':16s} {'IoU base':>9s} {'IoU fit':>8s} {'kept':>5s} {'s':>5s}")
    for name in names:
        photo = ph.render_photo(load_species(ROOT / "params" / f"{name}.txt"))
        for base_name in names:
            base = load_species(ROOT / "params" / f"{base_name}.txt")
            notes: list[str] = []
            with tempfile.TemporaryDirectory() as tmp:
                path = Path(tmp) / "photo.png"
                photo.save(path)
                start = time.perf_counter()
                make_texture(path, base, Path(tmp) / "new.txt", TextureOptions(fit_shape=True), notes.append)
                seconds = time.perf_counter() - start
            text = next(n for n in notes if "fitted shape" in n)
            numbers = [float(w.rstrip(",")) for w in text.replace("->", " ").split() if w[:2] == "0."]
            kept = "fitted shape:" in text
            base_iou, fit_iou = (numbers[0], numbers[1]) if kept else (numbers[1], numbers[0])
            print(f"{name:16s} {base_name:16s} {base_iou:9.3f} {fit_iou:8.3f} {'yes' if kept else 'no':>5s} "
                  f"{seconds:5.1f}")


if __name__ == "__main__":
    main()
    if "--fit" in sys.argv:
        fit_table()
