"""What a correct preview of each shipped species and cloud looks like, in checks that hold on any machine.

Nothing here compares a render with a stored picture pixel by pixel: Mesa's llvmpipe
(4x multisampling) and softpipe (none) disagree along every edge. Instead each mesh
part of a fish is drawn in a flat colour and measured - how much of the frame it
covers and where its centre lies - and the tests state what makes the fish right:

* every fin of the species shows, the small adipose fin included, at about its recorded size;
* seen from its left flank the fish faces left (field-guide view), from its right flank right;
* dorsal and adipose fins sit above the body, anal and pelvic fins below it, the pectoral
  fins ahead of the anal fin and the caudal fin at the tail end;
* the body shows its texture: its colours, and the variation a flat-coloured body lacks.

Each cloud covers about its recorded share of the frame, framed and centred.

The second half proves the checks catch an upside-down fish, a lost texture and any one
dropped fin; `test_checks_hold_under_softpipe` runs this module again under softpipe.
Recorded sizes live in reference_measures.json; when a change is meant to alter the
look, rewrite it with `PYTHONPATH=. python -m tests.preview.test_reference --update`
(the README's pictures are made separately: docs/preview.md lists where each comes from).

Every use of fishgen's preview internals is in tests/preview/partrender.py.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import PARAMS, ROOT
from tests.preview import partrender

pytestmark = pytest.mark.usefixtures("gl_available")

SIZE = (400, 300)
MEASURES = Path(__file__).with_name("reference_measures.json")

# --- what each species has --------------------------------------------------------------------

ADIPOSE = {"bonybream": True, "centroberyx": False, "pineapplefish": False, "threadfingoldie": False}
"""Which shipped species (params/*.txt) grow an adipose fin (its lengths are nonzero)."""
CLOUDS = ("table_4_2", "table_4_3", "table_4_4")
"""The report's cloud files, params/clouds/*.awn."""


def fins(species: str) -> list[str]:
    """Every fin the species must show."""
    median = ["dorsal_fin", "anal_fin", "caudal_fin"] + (["adipose_fin"] if ADIPOSE[species] else [])
    return median + [f"{fin}_{side}" for fin in ("pectoral_fin", "pelvic_fin") for side in ("left", "right")]


def shown_from(side: str, species: str) -> list[str]:
    """The parts a flank view shows: body, median fins and that side's paired fins."""
    return ["body"] + [f for f in fins(species) if not f.endswith("_left" if side == "right" else "_right")]


# --- thresholds -------------------------------------------------------------------------------

MIN_AREA = 5e-5
"""A fin 'shows' when it covers at least this fraction of the frame (the adipose fin: ~1.1e-4, half of
it hidden where it lies in the caudal fin's plane; a dropped fin covers 0 and fails the record check)."""
AREA_TOLERANCE = 0.20
"""Relative difference allowed from a part's recorded area (2 % or less between rasterizers, except
on the adipose fin's few pixels)."""
AREA_SLACK_PIXELS = 6
"""...or this many pixels, whichever is more: the adipose fin shows only ~13 px at SIZE (half of it in
the caudal fin's plane) and llvmpipe and softpipe differ on 2-3 of its edge pixels; dropping it
changes 13."""
TEXTURE_DETAIL = 0.02
"""Least spread of the body's chromaticity (sum of r, g, b standard deviations); a textured body
shows 0.039 to 0.16, a flat-coloured one about 0.005 (lighting alone)."""
TEXTURE_HUE = 0.03
"""Largest difference of mean chromaticity (any channel) between the body's pixels and the texels
under its vertices: correct bodies are off by at most 0.013, untextured ones by 0.17 to 0.22 -
except bonybream, whose nearly grey texture is only 0.020 off white, so TEXTURE_DETAIL catches
its loss."""
CLOUD_AREA_TOLERANCE = 0.10
CLOUD_BOX_TOLERANCE = 0.03
"""Fractions of the frame a cloud's covered share and bounding box may move from the record."""


# --- measuring --------------------------------------------------------------------------------

@dataclass(frozen=True)
class Part:
    area: float  # fraction of the frame the part visibly covers
    x: float     # centroid, as fractions of the frame's width and height from its top-left
    y: float

    def __str__(self) -> str:
        return f"{self.area:.5f} of the frame at ({self.x:.3f}, {self.y:.3f})"


@dataclass
class Flank:
    """A fish seen side-on: ``side`` is the flank facing the camera (left: head to the left)."""

    side: str
    parts: dict[str, Part]
    body_middle: np.ndarray  # per image column, the body's mid-height (fraction); nan where none

    def tailward(self, part: str) -> float:
        """How far toward the tail (fractions of the frame width) the part's centroid lies."""
        return self.parts[part].x if self.side == "left" else 1.0 - self.parts[part].x

    def height_over_body(self, part: str) -> float:
        """How far the part's centroid lies above the body's middle in its column (fractions of height)."""
        p = self.parts[part]
        column = min(int(p.x * len(self.body_middle)), len(self.body_middle) - 1)
        middle = self.body_middle[column]
        if np.isnan(middle):
            middle = self.parts["body"].y
        return float(middle - p.y)


def measure(coverage: dict[str, np.ndarray]) -> dict[str, Part]:
    out = {}
    for name, c in coverage.items():
        total = float(c.sum())
        h, w = c.shape
        if total == 0:
            out[name] = Part(0.0, float("nan"), float("nan"))
            continue
        ys, xs = np.mgrid[0:h, 0:w]
        out[name] = Part(total / c.size, float((c * (xs + 0.5)).sum() / total / w),
                         float((c * (ys + 0.5)).sum() / total / h))
    return out


def flank(scene, side: str) -> Flank:
    coverage = partrender.part_coverage(scene, side, SIZE)
    body = coverage.get("body", np.zeros(SIZE[::-1], np.float32))
    rows = np.arange(body.shape[0])[:, None] + 0.5
    weight = body.sum(0)
    with np.errstate(invalid="ignore", divide="ignore"):
        middle = np.where(weight > 0.5, (body * rows).sum(0) / weight / body.shape[0], np.nan)
    return Flank(side, measure(coverage), middle)


def recorded() -> dict:
    return json.loads(MEASURES.read_text()) if MEASURES.is_file() else {}


# --- what a correct fish is -------------------------------------------------------------------

def fish_problems(species: str, flanks: dict[str, Flank]) -> list[str]:
    """Every way the two flank views differ from a correct fish; empty when it is right."""
    problems = []
    record = recorded().get(species, {})
    for side, view in flanks.items():
        for part in shown_from(side, species):
            p = view.parts.get(part)
            if p is None or p.area < MIN_AREA:
                problems.append(f"{side} flank: {part} does not show ({p.area if p else 0:.5f} of the "
                                f"frame, at least {MIN_AREA} expected)")
                continue
            expected = record.get(side, {}).get(part)
            if expected is None:
                problems.append(f"{side} flank: {part} has no recorded area (run --update)")
            elif abs(p.area - expected) > max(AREA_TOLERANCE * expected,
                                              AREA_SLACK_PIXELS / (SIZE[0] * SIZE[1])):
                problems.append(f"{side} flank: {part} covers {p.area:.5f} of the frame, recorded "
                                f"{expected:.5f} (within {AREA_TOLERANCE:.0%} or {AREA_SLACK_PIXELS} px)")
        for part in view.parts:
            if part != "body" and part not in fins(species):
                problems.append(f"{part} is not a fin {species} has")
        problems += layout_problems(view)
    return problems


def layout_problems(view: Flank) -> list[str]:
    """Where the parts that show sit wrongly for a fish seen from ``view.side``."""
    def shows(part):
        return part in view.parts and view.parts[part].area >= MIN_AREA

    problems = []
    for part in ("dorsal_fin", "adipose_fin"):
        if shows(part) and view.height_over_body(part) <= 0:
            problems.append(f"{view.side} flank: {part} is not above the body "
                            f"({view.height_over_body(part):+.3f} of the frame height)")
    for part in ("anal_fin", f"pelvic_fin_{view.side}"):
        if shows(part) and view.height_over_body(part) >= 0:
            problems.append(f"{view.side} flank: {part} is not below the body "
                            f"({view.height_over_body(part):+.3f} of the frame height)")
    pectoral = f"pectoral_fin_{view.side}"
    if shows(pectoral) and shows("anal_fin") and view.tailward(pectoral) >= view.tailward("anal_fin"):
        problems.append(f"{view.side} flank: the pectoral fin is not ahead of the anal fin "
                        f"(the head is not to the {view.side})")
    if shows("caudal_fin"):
        rest = max((view.tailward(p) for p in view.parts if p != "caudal_fin" and shows(p)), default=0)
        if view.tailward("caudal_fin") <= rest:
            problems.append(f"{view.side} flank: the caudal fin is not at the tail end")
    return problems


def texture_problems(scene, beauty: np.ndarray, body: np.ndarray) -> list[str]:
    """How the body's pixels in a beauty render fail to show its texture; empty when they do."""
    pixels = beauty[..., :3][body > 0.99].astype(np.float64)
    chroma = pixels / np.maximum(pixels.sum(-1, keepdims=True), 1)
    problems = []
    detail = float(chroma.std(0).sum())
    if detail < TEXTURE_DETAIL:
        problems.append(f"the body is flat: colour spread {detail:.4f}, at least {TEXTURE_DETAIL} expected")
    texture, uvs = partrender.texture_of(scene, "body")
    texels = texels_under(texture, uvs)
    if texels is None:
        problems.append("the body has no texture")
    else:
        want = (texels / texels.sum(-1, keepdims=True)).mean(0)
        off = float(np.abs(chroma.mean(0) - want).max())
        if off > TEXTURE_HUE:
            problems.append(f"the body's colour is not its texture's: chromaticity {chroma.mean(0).round(3)} "
                            f"vs {want.round(3)} (off by {off:.3f}, at most {TEXTURE_HUE})")
    return problems


def texels_under(texture, uvs) -> np.ndarray | None:
    """The texture's sRGB colours under each vertex (nearest texel), or None without a texture."""
    if texture is None or uvs is None:
        return None
    h, w = texture.shape[:2]
    rows = np.clip((np.asarray(uvs)[:, 1] * h).astype(int), 0, h - 1)
    cols = np.clip((np.asarray(uvs)[:, 0] * w).astype(int), 0, w - 1)
    return texture[rows, cols, :3].astype(np.float64) + 1e-9


@dataclass(frozen=True)
class Cloud:
    area: float                                 # alpha-weighted share of the frame
    box: tuple[float, float, float, float]      # left, top, right, bottom of alpha > 0.05, fractions

    @staticmethod
    def of(image: np.ndarray) -> Cloud:
        alpha = image[..., 3] / 255.0
        ys, xs = np.nonzero(alpha > 0.05)
        h, w = alpha.shape
        if len(xs) == 0:
            return Cloud(0.0, (0.0, 0.0, 0.0, 0.0))
        return Cloud(float(alpha.mean()),
                     (xs.min() / w, ys.min() / h, (xs.max() + 1) / w, (ys.max() + 1) / h))


def cloud_problems(name: str, cloud: Cloud) -> list[str]:
    problems = []
    left, top, right, bottom = cloud.box
    if not (left > 0 and top > 0 and right < 1 and bottom < 1):  # its soft edge too, on every side
        problems.append(f"the cloud leaves the frame: box {np.round(cloud.box, 3)}")
    if max(right - left, bottom - top) < 0.6:
        problems.append(f"the cloud is lost in the frame: box {np.round(cloud.box, 3)}")
    record = recorded().get(name)
    if record is None:
        return problems + [f"{name} has no recorded measures (run --update)"]
    if abs(cloud.area / record["area"] - 1) > CLOUD_AREA_TOLERANCE:
        problems.append(f"the cloud covers {cloud.area:.4f} of the frame, recorded {record['area']:.4f}")
    if np.abs(np.subtract(cloud.box, record["box"])).max() > CLOUD_BOX_TOLERANCE:
        problems.append(f"the cloud's box {np.round(cloud.box, 3)} moved from {np.round(record['box'], 3)}")
    return problems


# --- the shipped species and clouds -----------------------------------------------------------

@cache
def species_scene(species: str):
    return partrender.load(PARAMS / f"{species}.txt")


@cache
def flanks_of(species: str) -> dict[str, Flank]:
    scene = species_scene(species)
    return {side: flank(scene, side) for side in ("left", "right")}


def test_every_shipped_species_and_cloud_is_specified():
    assert sorted(p.stem for p in PARAMS.glob("*.txt")) == sorted(ADIPOSE)
    assert sorted(p.stem for p in (PARAMS / "clouds").glob("*.awn")) == sorted(CLOUDS)
    assert any(ADIPOSE.values()), "no species with an adipose fin: the small-fin fault needs one"


@pytest.mark.parametrize("species", sorted(ADIPOSE))
def test_fish_has_every_fin_in_place(species):
    scene = species_scene(species)
    assert sorted(partrender.part_names(scene)) == sorted(["body", *fins(species)])
    assert fish_problems(species, flanks_of(species)) == []


@pytest.mark.parametrize("species", sorted(ADIPOSE))
def test_body_shows_its_texture(species):
    scene = species_scene(species)
    beauty = partrender.beauty_render(scene, "three-quarter", SIZE)  # the README's view
    body = partrender.part_coverage(scene, "three-quarter", SIZE)["body"]
    assert texture_problems(scene, beauty, body) == []


@pytest.mark.parametrize("name", CLOUDS)
def test_cloud_fills_the_frame_as_recorded(name):
    scene = partrender.load(PARAMS / "clouds" / f"{name}.awn")
    assert cloud_problems(name, Cloud.of(partrender.beauty_render(scene, "three-quarter", SIZE))) == []


@pytest.mark.parametrize("view", ["left", "right", "top", "front", "three-quarter"])
@pytest.mark.parametrize("name", CLOUDS)
def test_a_cloud_stays_whole_in_frame_from_every_side(name, view):
    """A particle's quad reaches its radius across the view whatever the view: framed by its
    centre +- radius along the world axes, the three-quarter view (the preview's default) cut
    Table 4.3's and 4.4's lower edges off."""
    scene = partrender.load(PARAMS / "clouds" / f"{name}.awn")
    left, top, right, bottom = Cloud.of(partrender.beauty_render(scene, view, SIZE)).box
    assert left > 0 and top > 0 and right < 1 and bottom < 1, (left, top, right, bottom)


# --- the checks catch the faults they exist for -----------------------------------------------

FAULT_SPECIES = next(s for s, has in sorted(ADIPOSE.items()) if has)  # bonybream: has every fin


def test_catches_an_upside_down_fish():
    scene = partrender.upside_down(species_scene(FAULT_SPECIES))
    problems = fish_problems(FAULT_SPECIES, {side: flank(scene, side) for side in ("left", "right")})
    assert any("not above the body" in p for p in problems), problems
    assert any("not below the body" in p for p in problems), problems


def test_catches_a_lost_texture():
    scene = species_scene(FAULT_SPECIES)
    lost = partrender.without_texture(scene)
    beauty = partrender.beauty_render(lost, "three-quarter", SIZE)
    body = partrender.part_coverage(scene, "three-quarter", SIZE)["body"]
    assert texture_problems(scene, beauty, body), "a lost texture went unnoticed"


@pytest.mark.parametrize("fin", fins(FAULT_SPECIES))
def test_catches_a_dropped_fin(fin):
    scene = partrender.without_part(species_scene(FAULT_SPECIES), fin)
    side = "right" if fin.endswith("_right") else "left"
    problems = fish_problems(FAULT_SPECIES, {side: flank(scene, side)})
    assert any(fin in p and "does not show" in p for p in problems), problems


def test_checks_hold_under_softpipe():
    """The checks on correct renders again, in a subprocess on Mesa's softpipe (no multisampling).

    The fault tests stay out of the rerun to keep the suite quick: a fault's distance from
    the thresholds is far larger than anything a rasterizer changes (see the thresholds). So do the
    clouds' side views but the three-quarter one: the same point sprites from other cameras."""
    if os.environ.get("GALLIUM_DRIVER") == "softpipe":
        pytest.skip("already running under softpipe")
    env = {**os.environ, "GALLIUM_DRIVER": "softpipe",
           "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    probe = subprocess.run([sys.executable, "-c", ("import moderngl; c = moderngl.create_context("
                            "standalone=True, backend='egl'); print(c.info['GL_RENDERER'])")],
                           env=env, capture_output=True, text=True, check=False)
    assert "softpipe" in probe.stdout, f"expected Mesa softpipe, found {probe.stdout!r} {probe.stderr}"
    run = subprocess.run([sys.executable, "-m", "pytest", __file__, "-q", "-p", "no:cacheprovider",
                          "-k", "not softpipe and not catches and (not every_side or three-quarter)"],
                         cwd=ROOT, env=env, capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-2000:]


# --- recording the measured sizes -------------------------------------------------------------

def update() -> None:
    """Rewrite reference_measures.json from renders of the shipped species and clouds."""
    out = {}
    for species in sorted(ADIPOSE):
        out[species] = {side: {part: round(view.parts[part].area, 6) for part in shown_from(side, species)}
                        for side, view in flanks_of(species).items()}
    for name in CLOUDS:
        cloud = Cloud.of(partrender.beauty_render(partrender.load(PARAMS / "clouds" / f"{name}.awn"),
                                                  "three-quarter", SIZE))
        out[name] = {"area": round(cloud.area, 5), "box": [round(v, 4) for v in cloud.box]}
    MEASURES.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {MEASURES.relative_to(ROOT)}")


if __name__ == "__main__":
    if sys.argv[1:] != ["--update"]:
        sys.exit("usage: PYTHONPATH=. python -m tests.preview.test_reference --update")
    update()
