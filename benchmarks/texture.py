"""Measured accuracy of `fishgen texture` on synthetic photos of the shipped species.

    python benchmarks/texture.py            # a table: species x photo kind
    python benchmarks/texture.py --fit      # and --fit-shape: each photo on each base species
    python benchmarks/texture.py --photographs [--subjects a,b] [--kinds k,l] [--fit-kinds k] [--bases a,b]
        # issue 25: fish fishgen does not ship, lit photos on textured backdrops, turned and in
        # perspective; each on its own geometry, then --fit-shape on every shipped base, the
        # rebuilt fish photographed by three.js
    python benchmarks/texture.py --blender [--seeds 301,302,303,304] [--bases a,b] [--no-lens] [--mirror]
                                           [--size 1920x1080] [--kinds png,jpeg90,jpeg90-444,camera]
        # issue 32: fish from `fishgen species --random` on seeds held out from all tuning,
        # photographed by Blender (Cycles, a 50-135 mm lens, small yaw and roll, a sun, translucent
        # fins over alpha or a mottled backdrop); --fit-shape on every shipped base, the rebuilt
        # fish photographed again by Blender side-on with the photo's lens: IoU per fit, min, median;
        # the command is told each photo's --focal-length unless --no-lens; --mirror fits the
        # photos mirrored (the fish facing right); --size photographs them (and the rebuilt fish) at
        # that size (default 640x360); --kinds fits the same photos once for each kind: png (the
        # default), jpegQ the water photos saved as JPEG at quality Q with their colour at half size
        # (4:2:0), jpegQ-444 at full size, camera blurred 0.6 px, given a camera's grain and saved
        # as JPEG 85 (--jpeg Q [--subsampling 4:4:4] and --camera name one kind, as before); and for
        # each kind how many misses the command said in one line, and how many passes it warned

Each photo is an orthographic side render (tests/authoring/photos.py), varied as
the robustness tests vary it. Columns: the rebuilt fish's silhouette IoU against
the photo's (in the fish's own level, head-left frame), the worst and mean body
texture point error and the worst fin point error, as fractions of the texture
size, and the seconds `make_texture` took. A three.js row (photos from three.js in
Chromium, tests/authoring/threejs.py) is added when Chromium and node_modules/three are there.
"""
from __future__ import annotations

import re
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fishgen.authoring.photo.compare import silhouette_iou  # noqa: E402
from fishgen.authoring.photo.run import make_texture  # noqa: E402
from fishgen.species.parser import load_species  # noqa: E402
from tests.authoring import photos as ph  # noqa: E402
from tests.authoring.photos import KINDS  # noqa: E402


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


def _option(name: str) -> list[str] | None:
    if name in sys.argv:
        return sys.argv[sys.argv.index(name) + 1].split(",")
    return None


def photographs() -> None:
    """Issue 25's photos: every subject x photographic kind, on its own geometry (IoU and point
    errors), then with --fit-shape on each shipped base (IoU by three.js, and whether the fit is
    whole by fishgen.authoring.photo.checks)."""
    import numpy as np
    from PIL import Image

    from fishgen.authoring.photo.checks import fit_problems
    from fishgen.authoring.photo.run import TextureOptions
    from fishgen.errors import FishgenError
    from tests.authoring.subjects import write_subjects
    from tests.authoring.threejs import LIT_KINDS, ThreePhotographer, lit_photo, unavailable

    if unavailable() is not None:
        print(f"--photographs needs three.js in Chromium: {unavailable()}")
        return
    work = Path(tempfile.mkdtemp(prefix="fishgen-photographs-"))
    subjects = {n: load_species(ROOT / "params" / f"{n}.txt") for n in SHIPPED}
    subjects.update(write_subjects(work / "subjects"))
    wanted = _option("--subjects")
    kinds = _option("--kinds") or ["three.js", *LIT_KINDS]
    bases = {n: load_species(ROOT / "params" / f"{n}.txt") for n in (_option("--bases") or SHIPPED)}
    camera = ThreePhotographer(work / "assets")

    def shoot(sp, kind):
        if kind == "three.js":
            p = camera.photo(sp)
            return p, p.rgba[:, :, 3] >= 64
        return lit_photo(camera, sp, kind)

    def run(photo_path, base, out, options, notes):
        """make_texture, and with the true silhouette as --mask when the photo's own fails."""
        try:
            return make_texture(photo_path, base, out, options, notes.append), ""
        except FishgenError as err:
            mask = photo_path.with_name("mask.png")
            return make_texture(photo_path, base, out, replace(options, mask=mask), notes.append), \
                f"needs --mask ({err.message.split(' (')[0]})"

    def three_iou(result, out, truth):
        rebuilt = load_species(out)
        shot = camera.photo(replace(rebuilt, name=f"r{time.monotonic_ns()}"))
        return silhouette_iou(result.frame.level(truth), shot.rgba[:, :, 3] >= 64)

    rows = []
    print(f"{'subject':16s} {'photo':13s} {'IoU':>6s} {'body max':>9s} {'body mean':>9s} {'worst fin':>18s} "
          "note")
    for name, sp in subjects.items():
        if wanted and name not in wanted:
            continue
        for kind in kinds:
            photo, truth = shoot(sp, kind)
            folder = work / name / kind
            folder.mkdir(parents=True, exist_ok=True)
            path = folder / "photo.png"
            photo.save(path)
            Image.fromarray(truth.astype(np.uint8) * 255).save(folder / "mask.png")
            notes: list[str] = []
            result, how = run(path, sp, folder / "own.txt", TextureOptions(), notes)
            rebuilt = load_species(folder / "own.txt")
            body, fins = ph.errors(rebuilt, photo)
            iou = silhouette_iou(result.frame.level(truth), ph.rendered_mask(rebuilt))
            worst = max(fins, key=lambda n: fins[n])
            print(f"{name:16s} {kind:13s} {iou:6.3f} {body.max():9.4f} {body.mean():9.4f} "
                  f"{worst + ' ' + format(fins[worst], '.4f'):>18s} {how}", flush=True)
            rows.append((name, kind, path, truth, how))
    print("\n--fit-shape on each shipped base; IoU of the rebuilt fish photographed by three.js (and by "
          "the command's own render), against the photo's true silhouette")
    print(f"{'subject':16s} {'photo':13s} {'base':16s} {'IoU 3js':>8s} {'own':>6s} {'kept':>5s} "
          f"{'whole':>6s} {'s':>5s} note")
    worst_iou = 1.0
    fit_kinds = _option("--fit-kinds") or kinds
    said, fits = {False: 0, True: 0}, {False: 0, True: 0}
    for name, kind, path, truth, _ in rows:
        if kind not in fit_kinds:
            continue
        for base_name, base in bases.items():
            notes = []
            out = path.with_name(f"fit_{base_name}.txt")
            start = time.perf_counter()
            result, how = run(path, base, out, TextureOptions(fit_shape=True), notes)
            seconds = time.perf_counter() - start
            iou = three_iou(result, out, truth)
            worst_iou = min(worst_iou, iou)
            problems = result.fit_problems
            if result.fitted and result.shape_fit is not None:   # re-checked from the file as written
                fit = result.shape_fit
                written = load_species(out)
                problems = fit_problems(written, fit.work, fit.placement)
            whole = "yes" if not problems else "NO"
            if iou < 0.85 and not how:   # the escape hatch: is it the photo's silhouette or the fit?
                hatch, _ = run(path, base, out, replace(TextureOptions(fit_shape=True),
                                                        mask=path.with_name("mask.png")), [])
                how = f"with --mask: {three_iou(hatch, out, truth):.3f}"
            warned = next((n for n in notes if n.startswith("silhouette IoU")), "")
            said[iou >= 0.85] += bool(warned)
            fits[iou >= 0.85] += 1
            print(f"{name:16s} {kind:13s} {base_name:16s} {iou:8.3f} {result.iou or 0:6.3f} "
                  f"{'yes' if result.fitted else 'no':>5s} {whole:>6s} {seconds:5.1f} "
                  f"{how or (problems[0] if problems else '')}"
                  f"{' | says: ' + warned if warned else ''}", flush=True)
    print(f"\nlowest IoU by three.js: {worst_iou:.3f} (target 0.85); the command said in one line that "
          f"the fish may look unlike the photo's for {said[False]} of {fits[False]} fits under 0.85 and "
          f"{said[True]} of {fits[True]} at 0.85 or more")
    camera.close()


SHIPPED = ("bonybream", "centroberyx", "pineapplefish", "threadfingoldie")
#: `fishgen species --random` seeds never looked at while the fit was tuned for Blender's photos
#: (tuned on 201-203 and the shaped fish of tests/authoring/subjects.py).
HELD_OUT = (301, 302, 303, 304)


def _kinds() -> list[str]:
    """The kinds of photo asked: --kinds k,l, or the one --jpeg/--camera name, or PNG alone."""
    if kinds := _option("--kinds"):
        return kinds
    if "--camera" in sys.argv:
        return ["camera"]
    if jpeg := _option("--jpeg"):
        return [f"jpeg{int(jpeg[0])}" + ("-444" if (_option("--subsampling") or [""])[0] == "4:4:4" else "")]
    return ["png"]


def _resaved(kind: str, records: dict, folder: Path) -> tuple[dict, str]:
    """``records`` as ``kind`` (png, jpegQ, jpegQ-444 or camera) and how they were saved."""
    from tests.authoring.blender_photo import CAMERA_QUALITY, resaved

    if kind == "png":
        return records, "PNG"
    if kind == "camera":
        grainy = resaved(records, folder, CAMERA_QUALITY, camera=True)
        return grainy, f"blurred, grainy, JPEG {CAMERA_QUALITY}"
    quality, _, full = kind.removeprefix("jpeg").partition("-")
    subsampling = "4:4:4" if full else "4:2:0"
    return resaved(records, folder, int(quality), subsampling), f"JPEG {quality} {subsampling}"


def blender() -> None:
    """Issue 32, item 1: Blender's photos of held-out sampled fish, fitted on every shipped base,
    once for each kind of photo asked (the same photos, saved again)."""
    import statistics

    from tests.authoring.blender_photo import bpy_python, fit_photos, mirrored, photograph, shots_for
    from tests.authoring.subjects import write_subjects

    if bpy_python() is None:
        print("--blender needs a Python with bpy ($FISHGEN_BPY_PYTHON or /tmp/bpyvenv/bin/python)")
        return
    kinds = _kinds()
    if bad := [k for k in kinds if not re.fullmatch(r"png|camera|jpeg\d{1,3}(-444)?", k)]:
        raise SystemExit(f"--kinds: expected png, camera, jpegQ or jpegQ-444, found {bad[0]!r}")
    start = time.perf_counter()
    seeds = tuple(int(s) for s in (_option("--seeds") or HELD_OUT))
    work = Path(tempfile.mkdtemp(prefix="fishgen-blender-"))
    subjects = write_subjects(work / "subjects", seeds, {})
    shots = shots_for(list(subjects))
    w, h = (int(v) for v in (_option("--size") or ["640x360"])[0].split("x"))
    photographed = photograph(subjects, shots, work / "shots", (w, h))
    if "--mirror" in sys.argv:
        photographed = mirrored(photographed, work / "mirrored")
    print(f"photos {time.perf_counter() - start:.0f} s")
    bases = {n: load_species(ROOT / "params" / f"{n}.txt") for n in (_option("--bases") or SHIPPED)}
    summary = []
    for kind in kinds:
        records, saved = _resaved(kind, photographed, work / kind)
        rows = fit_photos(records, bases, work / "fits" / kind, lens="--no-lens" not in sys.argv, size=(w, h))
        # Blender: the fitted glb as Blender shows it (its materials' alpha kept: a fitted fin's
        # texture mask trims it in every glTF client); triangles: every triangle, the masks ignored
        # (as Pillow); half: the command's own figure at half coverage, where it measured one.
        print(f"{'photo':12s} {'lens':>5s} {'yaw':>5s} {'roll':>5s} {'backdrop':8s} {'base':16s} "
              f"{'Blender':>8s} {'triangles':>9s} {'Pillow':>7s} {'own':>6s} {'half':>6s} {'s':>5s} note")
        for r in rows:
            shot = shots[r.photo]
            note = next((n for n in r.notes
                         if n.startswith(("silhouette IoU", "needs --mask")) or "not kept" in n), "")
            print(f"{r.photo:12s} {shot.lens:5.0f} {shot.yaw:5.0f} {shot.roll:5.0f} {shot.backdrop:8s} "
                  f"{r.base:16s} "
                  f"{r.blender or 0:8.3f} {r.triangles or 0:9.3f} {r.raster:7.3f} {r.own or 0:6.3f} "
                  f"{'-' if r.half is None else format(r.half, '6.3f'):>6s} {r.seconds:5.1f} {note}")
        for label, ious in (("as Blender shows the file", [r.blender or 0.0 for r in rows]),
                            ("every triangle, fin masks ignored", [r.triangles or 0.0 for r in rows])):
            print(f"{len(rows)} fits of {len(records)} Blender photos {w}x{h}, {saved} "
                  f"(seeds {','.join(map(str, seeds))}), "
                  f"{label}: IoU min {min(ious):.3f}, median {statistics.median(ious):.3f}, "
                  f"{sum(i >= 0.85 for i in ious)}/{len(ious)} >= 0.85")
        warned = {id(r) for r in rows if any(n.startswith("silhouette IoU") or "not kept" in n
                                             for n in r.notes)}
        misses = [r for r in rows if (r.blender or 0.0) < 0.85]
        said = sum(id(r) in warned for r in misses)
        passes = len(rows) - len(misses)
        masked = sum(any(n.startswith("needs --mask") for n in r.notes) for r in rows)
        if masked:
            print(f"fits whose photo's own silhouette failed, given the true one as --mask: {masked}")
        print(f"misses (as Blender shows the file) the command said in one line: {said} of {len(misses)}"
              f"{' (the photos mirrored: the fish facing right)' if '--mirror' in sys.argv else ''}; "
              f"passes it warned all the same: {len(warned) - said} of {passes}")
        print(f"fits {sum(r.seconds for r in rows):.0f} s")
        summary.append(f"{saved}: {passes}/{len(rows)} >= 0.85, misses said {said} of {len(misses)}, "
                       f"passes warned {len(warned) - said}")
    if len(summary) > 1:   # every kind's line together, to read side by side
        print("\n".join(summary))
    print(f"whole run {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    if "-h" in sys.argv or "--help" in sys.argv:     # it read no option it did not know: say them
        print(__doc__)
    elif "--blender" in sys.argv:
        blender()
    elif "--photographs" in sys.argv:
        photographs()
    else:
        main()
        if "--fit" in sys.argv:
            fit_table()
