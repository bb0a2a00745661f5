"""Photos of fishgen fish from a renderer that is not fishgen's and not three.js: Blender's Cycles
(issue 32, item 1), with a perspective camera of a given focal length, a little yaw and roll, a
sun with shadows and a world light, over a procedural backdrop or with alpha.

The camera is set here, from the fish's own extents (:func:`camera_for`), and Blender is only told
where it is; so the same camera can be put on a fitted fish (its lens, fill, pitch; side-on) and
projected without Blender (:func:`raster_mask`, Pillow's polygon fill, for CI which has no Blender).
Blender writes the photo and the fish's exact coverage from the same camera (every surface one
opaque emission, the backdrop hidden): the true silhouette.
"""
from __future__ import annotations

import json
import subprocess
import tempfile
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from fishgen.scene.model import Scene

HERE = Path(__file__).resolve().parent
SIZE = (640, 360)
SENSOR_MM = 36.0


def bpy_python() -> str | None:
    """The Python that has `bpy` (the engine matrix's), or None."""
    from tests.assembly.engine_clients import BPY

    return BPY


@dataclass(frozen=True)
class Shot:
    """How a fish is photographed, relative to its size: ``lens`` in mm on a 36 mm sensor, the
    share of the width its length ``fill``s, the camera ``pitch`` above it, the fish's ``yaw`` off
    side-on and the camera's ``roll`` (degrees); ``backdrop``: alpha, water (a backdrop plane) or
    sand (that and a floor under the fish)."""
    lens: float = 50.0
    fill: float = 0.7
    pitch: float = 5.0
    yaw: float = 0.0
    roll: float = 0.0
    backdrop: str = "alpha"
    seed: int = 0

    def side_on(self) -> Shot:
        """The same lens, framing and height, the fish side-on and the camera level: how a fitted
        (side-on) species is photographed to compare it with this photo, levelled."""
        return Shot(self.lens, self.fill, self.pitch, 0.0, 0.0, "alpha", self.seed)


def rest_triangles(scene: Scene) -> np.ndarray:
    """(n, 3, 3) every drawn triangle at rest, glTF axes, metres."""
    from fishgen.exchange.rest import rest_meshes

    return np.concatenate([m.positions[m.faces] for m in rest_meshes(scene)])


def camera_for(points: np.ndarray, shot: Shot, size=SIZE) -> dict:
    """A perspective camera that photographs ``points`` (glTF axes) as ``shot`` says: aimed at their
    box's centre from ``pitch`` above and ``yaw`` round the side (+X: the left side, head left), far
    enough that the length fills ``fill`` of the width and the height at most 75 % of the height."""
    w, h = size
    lo, hi = points.min(0), points.max(0)
    target = (lo + hi) / 2
    length, height = float(hi[2] - lo[2]), float(hi[1] - lo[1])
    tan_h = SENSOR_MM / 2 / shot.lens
    tan_v = tan_h * h / w
    distance = max(0.5 * length / shot.fill / tan_h, 0.5 * height / 0.75 / tan_v) + float(hi[0] - lo[0]) / 2
    p, y = np.radians(shot.pitch), np.radians(shot.yaw)
    towards = np.array([np.cos(p) * np.cos(y), np.sin(p), np.cos(p) * np.sin(y)])
    eye = target + distance * towards
    forward = -towards
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    r = np.radians(shot.roll)
    up = np.cos(r) * up + np.sin(r) * right
    sun = towards * 0.5 + np.array([0.0, 1.0, 0.35])
    job: dict = {"width": w, "height": h, "lens": shot.lens, "sensor": SENSOR_MM, "eye": eye.tolist(),
                 "target": target.tolist(), "up": up.tolist(), "sun": (sun / np.linalg.norm(sun)).tolist()}
    if shot.backdrop in ("water", "sand"):
        back = 1.5 * length
        job["backdrop"] = {"centre": (target - back * towards).tolist(), "normal": towards.tolist(),
                           "size": 3.0 * (distance + back) * tan_h}
    if shot.backdrop == "sand":
        job["floor"] = float(lo[1] - 0.15 * height)
    return job


def project(points: np.ndarray, camera: dict) -> np.ndarray:
    """(n, 2) pixel positions (x right, y down; pixel centres at +0.5) of glTF points."""
    eye, target = np.asarray(camera["eye"]), np.asarray(camera["target"])
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, camera["up"])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    rel = np.asarray(points, float) - eye
    depth = rel @ forward
    focal = camera["lens"] / camera["sensor"] * camera["width"]
    return np.stack([camera["width"] / 2 + focal * (rel @ right) / depth,
                     camera["height"] / 2 - focal * (rel @ up) / depth], 1)


def raster_mask(scene: Scene, camera: dict) -> np.ndarray:
    """The scene's coverage from ``camera``: every triangle projected and filled by Pillow (no
    renderer of fishgen's) at 4 x 4 samples a pixel, and a pixel covered when half its samples are,
    as Blender's box-filtered coverage counts it (Pillow's fill takes every pixel an edge touches:
    at one sample a pixel, thin fins came out a pixel wider all round)."""
    from PIL import Image, ImageDraw

    k = 4
    tris = project(rest_triangles(scene).reshape(-1, 3), camera).reshape(-1, 3, 2) * k - 0.5
    w, h = camera["width"], camera["height"]
    img = Image.new("L", (w * k, h * k), 0)
    draw = ImageDraw.Draw(img)
    for t in tris:   # a test's rasteriser: a few thousand triangles
        draw.polygon([tuple(p) for p in t], fill=255)
    samples = np.asarray(img).reshape(h, k, w, k) >= 128
    return samples.mean(axis=(1, 3)) >= 0.5


@dataclass(frozen=True)
class Job:
    glb: Path
    camera: dict
    mask: Path
    photo: Path | None = None
    seed: int = 0
    alpha: bool = False   # the mask of what the file shows (materials' alpha kept), not of every triangle


def run_blender(jobs: list[Job], timeout: float = 1800.0) -> list[dict]:
    """Render ``jobs`` in one Blender process; each writes its mask (and photo) PNG."""
    python = bpy_python()
    if python is None:
        raise RuntimeError("no Python with bpy ($FISHGEN_BPY_PYTHON)")
    with tempfile.TemporaryDirectory(prefix="fishgen-blender-") as tmp:
        spec = Path(tmp) / "jobs.json"
        spec.write_text(json.dumps([
            {"glb": str(j.glb),
             "camera": {k: v for k, v in j.camera.items() if k not in ("backdrop", "floor", "sun")},
             "sun": j.camera["sun"], "backdrop": j.camera.get("backdrop"), "floor": j.camera.get("floor"),
             "photo": None if j.photo is None else str(j.photo), "mask": str(j.mask), "seed": j.seed,
             "alpha": j.alpha}
            for j in jobs]))
        run = subprocess.run([python, str(HERE / "blender_photo_bpy.py"), str(spec)], capture_output=True,
                             text=True, timeout=timeout)
    if run.returncode != 0:
        raise RuntimeError(run.stderr[-2000:])
    return [json.loads(line) for line in run.stdout.splitlines() if line.startswith("{")]


def fish_glb(scene: Scene, path: Path) -> Path:
    import fishgen

    fishgen.export(scene, path)
    return path


def read_mask(path: Path) -> np.ndarray:
    """A mask PNG: Blender's coverage (its alpha) or a committed 1-bit one (white is fish)."""
    from PIL import Image

    img = Image.open(path)
    if img.mode == "RGBA":
        return np.asarray(img)[:, :, 3] >= 128
    return np.asarray(img.convert("L")) >= 128


def photograph(species: dict, shots: dict, folder: Path, size: tuple[int, int] = SIZE) -> dict[str, dict]:
    """Photograph each ``species[name]`` as ``shots[name]`` into ``folder`` at ``size``: ``NAME.png``
    (the photo), ``NAME_mask.png`` (its true silhouette) and ``NAME.json`` (the shot and the camera);
    name -> that record with the paths."""
    from fishgen.assembly.fish import build_fish

    folder.mkdir(parents=True, exist_ok=True)
    jobs, out = [], {}
    for name, sp in species.items():
        shot = shots[name]
        scene = build_fish(sp, fins="blend")     # translucent fins, as a real fin shows the backdrop
        camera = camera_for(rest_triangles(scene).reshape(-1, 3), shot, size)
        glb = fish_glb(scene, folder / f"{name}.glb")
        jobs.append(Job(glb, camera, folder / f"{name}_mask.png", folder / f"{name}.png", shot.seed))
        record = {"shot": asdict(shot), "camera": camera}
        (folder / f"{name}.json").write_text(json.dumps(record, indent=1))
        out[name] = {**record, "photo": folder / f"{name}.png", "mask": folder / f"{name}_mask.png"}
    run_blender(jobs)
    for name in species:
        (folder / f"{name}.glb").unlink()
    return out


def mirrored(records: dict[str, dict], folder: Path) -> dict[str, dict]:
    """:func:`photograph`'s records with each photo and its true silhouette mirrored into ``folder``:
    the fish facing right, as a camera on its other side shows it. The command's frame turns it
    head-left, and its levelling of the mirrored truth is what a fit is measured against."""
    from PIL import Image, ImageOps

    folder.mkdir(parents=True, exist_ok=True)
    out = {}
    for name, rec in records.items():
        paths = {key: folder / Path(rec[key]).name for key in ("photo", "mask")}
        for key, path in paths.items():
            with Image.open(rec[key]) as img:
                ImageOps.mirror(img).save(path)
        out[name] = {**rec, **paths}
    return out


#: A camera's photo as issue 32's JPEG rounds made it (docs/blender-photos.md): a lens's softness
#: (Gaussian blur, px), sensor grain (normal, levels a channel; this share of its variance shared by
#: the three channels, as luma grain is) and the camera's JPEG quality.
CAMERA_BLUR, CAMERA_GRAIN, CAMERA_SHARED, CAMERA_QUALITY = 0.6, 4.0, 0.6, 85


def resaved(records: dict[str, dict], folder: Path, quality: int, subsampling: str = "4:2:0",
            camera: bool = False) -> dict[str, dict]:
    """:func:`photograph`'s water photos (a JPEG has no alpha) saved again into ``folder`` as JPEG at
    ``quality`` with its colour kept at ``subsampling`` ("4:2:0", as Pillow and most cameras do, or
    "4:4:4"); with ``camera`` first blurred and given grain (``CAMERA_*``, seeded by the shot), as a
    camera's photo is. The true silhouettes are the same files."""
    from PIL import Image, ImageFilter

    folder.mkdir(parents=True, exist_ok=True)
    out = {}
    for name, rec in records.items():
        if rec["shot"]["backdrop"] != "water":
            continue
        with Image.open(rec["photo"]) as img:
            rgb = img.convert("RGB")
        if camera:
            rgb = rgb.filter(ImageFilter.GaussianBlur(CAMERA_BLUR))
            rng = np.random.default_rng(int(rec["shot"]["seed"]))
            h, w = rgb.height, rgb.width
            noise = CAMERA_GRAIN * (np.sqrt(CAMERA_SHARED) * rng.standard_normal((h, w, 1))
                                    + np.sqrt(1 - CAMERA_SHARED) * rng.standard_normal((h, w, 3)))
            rgb = Image.fromarray(np.clip(np.asarray(rgb) + noise, 0, 255).round().astype(np.uint8))
        path = folder / f"{name}.jpg"
        rgb.save(path, "JPEG", quality=quality, subsampling=subsampling)
        out[name] = {**rec, "photo": path}
    return out


def fitted_masks(fits: dict[str, tuple], folder: Path,
                 size: tuple[int, int] = SIZE) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each fitted species (name -> (species, Shot)) photographed side-on in Blender with its photo's
    lens and framing, at ``size``: name -> its coverage masks, of what the file shows (the
    materials' alpha kept: a fitted fin's texture mask trims it) and of every triangle."""
    from fishgen.assembly.fish import build_fish

    folder.mkdir(parents=True, exist_ok=True)
    jobs = []
    for name, (sp, shot) in fits.items():
        scene = build_fish(sp)
        camera = camera_for(rest_triangles(scene).reshape(-1, 3), shot.side_on(), size)
        glb = fish_glb(scene, folder / f"{name}.glb")
        jobs += [Job(glb, camera, folder / f"{name}_shown.png", alpha=True),
                 Job(glb, camera, folder / f"{name}_mask.png")]
    run_blender(jobs)
    return {name: (read_mask(folder / f"{name}_shown.png"), read_mask(folder / f"{name}_mask.png"))
            for name in fits}


@dataclass(frozen=True)
class Fitted:
    """One photo fitted on one base: the command's own figure, and the rebuilt fish's overlap with
    the photo's true silhouette (levelled by the command's frame) photographed by Blender as the
    file shows it (``blender``) and every triangle of it (``triangles``: the fins' texture masks
    ignored), and, with no renderer, every triangle filled by :func:`raster_mask`."""
    photo: str
    base: str
    kept: bool
    own: float | None
    raster: float
    blender: float | None
    notes: tuple[str, ...]
    seconds: float
    triangles: float | None = None
    half: float | None = None     # the command's figure at half coverage (TextureResult.half_covered)


@dataclass(frozen=True)
class FitRun:
    """One ``fishgen texture --fit-shape`` of a photo on a base (:func:`fit_one`): its row, the
    command's result, the species file written (beside its textures), the rebuilt species, the shot
    it is photographed side-on with, the photo's true silhouette levelled by the command, and the
    photo's size in pixels (the rebuilt fish is photographed at it)."""
    key: str
    row: Fitted
    result: Any = field(repr=False)
    out: Path
    rebuilt: Any = field(repr=False)
    shot: Shot
    level: np.ndarray = field(repr=False)
    size: tuple[int, int] = SIZE


def photo_size(rec: dict) -> tuple[int, int]:
    """The size a :func:`photograph` record's photo was taken at (its camera's), in pixels."""
    camera = rec.get("camera") or {}
    return (int(camera["width"]), int(camera["height"])) if "width" in camera else SIZE


def fit_one(name: str, rec: dict, base_name: str, base: Any, folder: Path, lens: bool = True) -> FitRun:
    """``fishgen texture --fit-shape`` of the photo ``name`` (:func:`photograph`'s record) on
    ``base``, into ``folder/name/base_name.txt``, told the photo's ``--focal-length`` when ``lens``
    (as a camera's EXIF tells it); the rebuilt fish filled from the photo's camera, side-on, by
    :func:`raster_mask` at the photo's own size against the photo's true silhouette."""
    import time

    from PIL import Image

    from fishgen.assembly.fish import build_fish
    from fishgen.authoring.photo.compare import silhouette_iou
    from fishgen.authoring.photo.run import TextureOptions, make_texture
    from fishgen.errors import FishgenError
    from fishgen.species.parser import load_species

    truth = read_mask(Path(rec["mask"]))
    shot = Shot(**rec["shot"])
    options = TextureOptions(fit_shape=True, **({"focal_length": shot.lens} if lens else {}))
    out = folder / name / f"{base_name}.txt"
    out.parent.mkdir(parents=True, exist_ok=True)
    notes: list[str] = []
    start = time.perf_counter()
    try:
        result = make_texture(rec["photo"], base, out, options, notes.append)
    except FishgenError as err:   # the photo's own silhouette failed: the documented escape
        notes = [f"needs --mask ({err.message})"]
        mask = folder / name / "mask.png"
        Image.fromarray(truth).save(mask)
        result = make_texture(rec["photo"], base, out, replace(options, mask=mask), notes.append)
    seconds = time.perf_counter() - start
    rebuilt = load_species(out)
    level = result.frame.level(truth)
    scene = build_fish(rebuilt)
    size = photo_size(rec)
    camera = camera_for(rest_triangles(scene).reshape(-1, 3), shot.side_on(), size)
    raster = silhouette_iou(level, raster_mask(scene, camera))
    row = Fitted(name, base_name, result.fitted, result.iou, raster, None, tuple(notes), seconds,
                 half=result.half_covered)
    return FitRun(f"{name}--{base_name}", row, result, out, rebuilt, shot, level, size)


def photographed(runs: list[FitRun], folder: Path, size: tuple[int, int] | None = None) -> list[Fitted]:
    """Each run's row with the rebuilt fish photographed side-on by Blender (:func:`fitted_masks`)
    against the photo's true silhouette: as the file shows it and every triangle of it, at ``size``
    or else at its photo's own size (a full-HD photo's thin fin tips vanish at 640 x 360, and the
    overlap, cropped to each fish's box, then stretches the rebuilt fish onto the photo's)."""
    from fishgen.authoring.photo.compare import silhouette_iou

    masks: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for each in sorted({size or run.size for run in runs}):
        fits = {run.key: (run.rebuilt, run.shot) for run in runs if (size or run.size) == each}
        masks |= fitted_masks(fits, folder, each)
    return [replace(run.row, blender=silhouette_iou(run.level, masks[run.key][0]),
                    triangles=silhouette_iou(run.level, masks[run.key][1])) for run in runs]


def fit_photos(records: dict[str, dict], bases: dict, folder: Path, blender: bool = True,
               skip: dict[str, str] | None = None, lens: bool = True,
               size: tuple[int, int] | None = None) -> list[Fitted]:
    """``fishgen texture --fit-shape`` of every photo (name -> :func:`photograph`'s record) on every
    base (name -> species) but the one it was shaped from (``skip``: photo -> base), told the
    photo's ``--focal-length`` when ``lens`` (as a camera's EXIF tells it): :func:`fit_one` each,
    then, with ``blender``, :func:`photographed` at ``size`` (by default each photo's own)."""
    runs = [fit_one(name, rec, base_name, base, folder, lens)
            for name, rec in records.items() for base_name, base in bases.items()
            if (skip or {}).get(name) != base_name]
    return photographed(runs, folder / "blender", size) if blender else [run.row for run in runs]


#: The lenses photos are taken with (mm on a 36 mm sensor: a normal lens to a short telephoto). A
#: wide angle close up is left out: a fish's paired fins stand out sideways, towards the camera, and
#: at 35 mm the true fish's own side-on photo differs from its orthographic side view by up to 0.17
#: IoU, which no side-on species fitted without knowing the camera can hold.
LENSES = (50.0, 85.0, 135.0)


def shots_for(names: list[str]) -> dict[str, Shot]:
    """A shot per subject, cycling lens, a small yaw and roll, and backdrop (alpha or water)."""
    return {name: Shot(LENSES[k % 3], 0.7, 0.0, (-8.0, 5.0, 8.0, -4.0)[k % 4], (2.0, -3.0, 0.0)[k % 3],
                       ("water", "alpha")[k % 2], k) for k, name in enumerate(names)}


FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "blender_photos"


def write_fixtures(folder: Path, subjects: dict[str, Shot], seeds: tuple[int, ...]) -> None:
    """Photograph ``subjects`` (sampled ``seeds`` and :func:`.subjects.shaped` fish) into ``folder``
    as CI's committed Blender photos: the photo, its true silhouette as a 1-bit PNG, the shot."""
    from PIL import Image

    from tests.authoring.subjects import shaped, write_subjects

    with tempfile.TemporaryDirectory(prefix="fishgen-fixtures-") as tmp:
        made = {k: v for k, v in shaped().items() if k in subjects}
        species = write_subjects(Path(tmp) / "subjects", seeds, made)
        records = photograph({n: species[n] for n in subjects}, subjects, Path(tmp) / "shots")
        folder.mkdir(parents=True, exist_ok=True)
        for name, rec in records.items():
            Image.open(rec["photo"]).save(folder / f"{name}.png", optimize=True)
            bits = Image.fromarray(read_mask(rec["mask"])).convert("1")
            bits.save(folder / f"{name}_mask.png", optimize=True)
            (folder / f"{name}.json").write_text(json.dumps({"shot": rec["shot"], "camera": rec["camera"]},
                                                            indent=1) + "\n")


def fixture_records(folder: Path = FIXTURES) -> dict[str, dict]:
    """The committed photos as :func:`photograph` returns them: name -> shot, camera and paths."""
    out = {}
    for meta in sorted(folder.glob("*.json")):
        rec = json.loads(meta.read_text())
        out[meta.stem] = {**rec, "photo": meta.with_suffix(".png"),
                          "mask": meta.with_name(f"{meta.stem}_mask.png")}
    return out


#: CI's committed photos: a held-out sample (seed 303) and two shaped fish, over water and alpha.
FIXTURE_SHOTS = {"sampled_303": Shot(85.0, 0.7, 0.0, 5.0, -3.0, "water", 1),
                 "long": Shot(50.0, 0.7, 0.0, -8.0, 2.0, "water", 2),
                 "deep-tail": Shot(135.0, 0.7, 0.0, 8.0, 0.0, "alpha", 3)}


if __name__ == "__main__":   # regenerate the committed photos: python -m tests.authoring.blender_photo
    write_fixtures(FIXTURES, FIXTURE_SHOTS, (303,))
