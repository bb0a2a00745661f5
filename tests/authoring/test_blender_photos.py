"""Photos from Blender (Cycles, a perspective camera, a sun and a world light, translucent fins over
alpha or a mottled backdrop) of fish fishgen does not ship, fitted with --fit-shape on other bases
(issue 32, item 1). CI has no Blender: it fits the committed photos (tests/fixtures/blender_photos)
and fills the fitted fish's triangles with Pillow from the photo's camera; with Blender, the fit is
photographed again by Blender itself."""
from __future__ import annotations

import json
import re

import numpy as np
import pytest

from tests.authoring import blender_photo as bp
from tests.conftest import PARAMS

#: The fits CI holds to the target: each committed photo on bases it was not shaped from.
TARGET = 0.85
FITS = [("sampled_303", "centroberyx"), ("long", "bonybream"), ("deep-tail", "centroberyx")]
"""long on ThreadfinGoldie (0.942, told the lens; 0.928 not) is as near the target as long on
BonyBream (0.940; 0.924), whose fits, told the lens and not, the other tests here hold too.
sampled_303 on PineappleFish (0.857; 0.849 until the fit took the silhouette's faint edges, the
translucent caudal lobes' thin tips) tries every level of the fish and takes a minute: it is left
to `python benchmarks/texture.py --blender`, and the photo is held here on Centroberyx."""

needs_blender = pytest.mark.skipif(bp.bpy_python() is None, reason="no Python with bpy ($FISHGEN_BPY_PYTHON)")


def _bases(names):
    from fishgen.species.parser import load_species

    return {n: load_species(PARAMS / f"{n}.txt") for n in names}


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """``fitted(photo, base, lens=True)``: :func:`.blender_photo.fit_one` of a committed photo on a
    shipped base, told the photo's focal length when ``lens``, made once for the module (a fit
    takes 5-10 s, and several tests here hold the same one to different things)."""
    runs: dict[tuple[str, str, bool], bp.FitRun] = {}

    def fit(photo: str, base: str, lens: bool = True) -> bp.FitRun:
        if (photo, base, lens) not in runs:
            folder = tmp_path_factory.mktemp(f"fit-{photo}-{base}-{'lens' if lens else 'blind'}")
            runs[photo, base, lens] = bp.fit_one(photo, bp.fixture_records()[photo], base,
                                                 _bases([base])[base], folder, lens)
        return runs[photo, base, lens]

    return fit


def test_fixtures_are_whole():
    """Each committed photo has its true silhouette and the shot it was taken with."""
    records = bp.fixture_records()
    assert {"sampled_303", "long", "deep-tail", "sampled_2007"} <= set(records)
    for name, rec in records.items():
        truth = bp.read_mask(rec["mask"])
        assert truth.shape == (rec["camera"]["height"], rec["camera"]["width"]), name
        assert 0.03 < truth.mean() < 0.6, f"{name}: the mask is not a fish"
        bp.Shot(**rec["shot"])


def test_rasteriser_agrees_with_the_committed_blender_masks(tmp_path):
    """The Pillow rasteriser CI measures fits with, from the committed camera, covers what Blender
    covered (a subject rebuilt from its seed): it is a stand-in for Blender, not for fishgen."""
    from fishgen.assembly.fish import build_fish
    from tests.authoring.subjects import write_subjects

    rec = bp.fixture_records()["sampled_303"]
    species = write_subjects(tmp_path, (303,), {})["sampled_303"]
    scene = build_fish(species, fins="blend")
    camera = bp.camera_for(bp.rest_triangles(scene).reshape(-1, 3), bp.Shot(**rec["shot"]))
    for key in ("eye", "target", "up", "lens", "width", "height"):
        assert np.allclose(camera[key], rec["camera"][key]), key
    mine, truth = bp.raster_mask(scene, rec["camera"]), bp.read_mask(rec["mask"])
    assert (mine & truth).sum() / (mine | truth).sum() >= 0.97


@pytest.mark.slow
@pytest.mark.parametrize("photo, base", FITS)
def test_fit_of_a_blender_photo_holds_on_another_base(gl_available, fitted, photo, base):
    """--fit-shape on a base the fish was not shaped from: the rebuilt fish, projected side-on with
    the photo's lens and framing, overlaps the photo's true silhouette (levelled by the command)
    with IoU >= 0.85, and the command's own figure is not kinder than that by more than 0.06."""
    row = fitted(photo, base).row
    assert row.kept, row.notes
    assert row.raster >= TARGET, f"{photo} on {base}: IoU {row.raster:.3f} (the command says {row.own:.3f})"
    assert row.own is not None and row.own - row.raster <= 0.06


@needs_blender
def test_blender_covers_what_the_rasteriser_fills(tmp_path):
    """Blender's mask pass and Pillow's fill of the same fish from the same camera agree."""
    from fishgen.assembly.fish import build_fish
    from tests.authoring.subjects import write_subjects

    species = write_subjects(tmp_path / "s", (303,), {})
    shot = bp.Shot(85.0, 0.7, 0.0, 5.0, -3.0, "alpha", 1)
    rec = bp.photograph(species, {"sampled_303": shot}, tmp_path / "shots")["sampled_303"]
    truth = bp.read_mask(rec["mask"])
    mine = bp.raster_mask(build_fish(species["sampled_303"], fins="blend"), rec["camera"])
    assert (mine & truth).sum() / (mine | truth).sum() >= 0.97
    assert json.loads((tmp_path / "shots" / "sampled_303.json").read_text())["camera"] == rec["camera"]


@pytest.mark.slow
@needs_blender
def test_fit_photographed_again_by_blender(tmp_path, gl_available, fitted):
    """The whole measure in Blender: a committed photo fitted on another base (the fit above), the
    fitted species built as a glb and photographed by Blender with the photo's lens, IoU >= 0.85."""
    (row,) = bp.photographed([fitted("long", "bonybream")], tmp_path)
    assert row.blender is not None and row.blender >= TARGET, row
    assert abs(row.blender - row.raster) <= 0.03


def test_each_rebuilt_fish_is_photographed_at_its_photo_s_size(monkeypatch, tmp_path):
    """A full-HD photo's rebuilt fish is photographed at full HD, a small photo's at its size: at
    640 x 360 a full-HD fish's thin fin tips vanish and the box-cropped overlap stretches it."""
    asked = []

    def masks(fits, folder, size):
        asked.append((sorted(fits), size))
        return {key: (np.ones((4, 8), bool), np.ones((4, 8), bool)) for key in fits}

    monkeypatch.setattr(bp, "fitted_masks", masks)
    records = {"hd": {"camera": {"width": 1920, "height": 1080}},
               "small": {"camera": {"width": 640, "height": 360}}}
    runs = [bp.FitRun(f"{name}--bonybream", bp.Fitted(name, "bonybream", True, 0.9, 0.9, None, (), 0.0), None,
                      tmp_path, None, bp.Shot(), np.ones((4, 8), bool), bp.photo_size(rec))
            for name, rec in records.items()]
    rows = bp.photographed(runs, tmp_path)
    assert asked == [(["small--bonybream"], (640, 360)), (["hd--bonybream"], (1920, 1080))]
    assert [row.blender for row in rows] == [1.0, 1.0]
    assert bp.photo_size({"shot": {}}) == bp.SIZE     # a record without its camera: the default


def test_fixtures_folder_is_small():
    """Committed photos stay a few hundred KB."""
    assert sum(p.stat().st_size for p in bp.FIXTURES.iterdir()) < 800_000
    assert np.all([p.suffix in (".png", ".json") for p in bp.FIXTURES.iterdir()])


@pytest.mark.slow
def test_focal_length_fits_for_the_photo_s_perspective(gl_available, fitted):
    """A 50 mm photo fitted told its focal length: the fish from the photo's camera is no less like
    the photo than a fit that assumed no perspective (the two fits the next test reads; 0.940 and
    0.924 measured). That the same inputs write the same bytes is held by
    test_a_fit_that_leans_on_the_faint_edges_and_faded_pixels_together_is_said_so."""
    rec = bp.fixture_records()["long"]
    assert rec["shot"]["lens"] == 50.0
    told = fitted("long", "bonybream").row
    blind = fitted("long", "bonybream", lens=False).row
    assert told.kept and told.raster >= TARGET, told
    assert told.own is not None and told.own - told.raster <= 0.06, told
    assert told.raster >= blind.raster - 0.005, (told, blind)


def test_told_the_lens_a_fit_over_water_keeps_the_faint_fin_tips_in_its_mask(gl_available, fitted):
    """Over a backdrop the fit reaches the silhouette's faint edges (a translucent fin's last
    pixels), and told the lens its fins take their texture where the render from the photo's camera
    shows them, out to those edges: its mask texture is cut with them, or it trims the very tips
    the fish was fitted to (issue 32: 703 on BonyBream, 0.885 -> 0.777 in Blender). Without the lens
    the mask stays the bare silhouette, as before."""
    from PIL import Image, ImageOps
    from scipy import ndimage

    from fishgen.authoring.photo.image import load_photo, measuring_side, working_copy
    from fishgen.authoring.photo.silhouette import faint_edges, silhouette

    rec = bp.fixture_records()["long"]
    assert rec["shot"]["lens"] == 50.0
    original = load_photo(rec["photo"])
    photo = working_copy(original, measuring_side(original.size))
    sil = silhouette(photo)
    faint = faint_edges(photo, sil.mask)
    assert sil.source == "background model" and faint.sum() > 20
    for lens in (True, False):   # --focal-length 50, and none
        run = fitted("long", "bonybream", lens)
        notes = run.row.notes
        assert run.result.fitted
        assert not any(n.startswith("needs --mask") for n in notes), notes   # its own silhouette
        # its bare figure is its own: nothing to say of doubts taken together (the next test)
        assert not [n for n in notes if "give --mask to be sure" in n], notes
        mask = np.asarray(ImageOps.flip(Image.open(run.out.with_name("bonybream_mask.png")))) >= 128
        assert mask.shape == sil.mask.shape and mask[sil.mask].all()
        # a fitted fish's mask also widens the outline's 1-px threads (test_photo_roundtrip)
        cut = sil.mask | faint if lens else sil.mask
        thin = cut & ~ndimage.binary_opening(cut, structure=np.ones((3, 3), bool))
        assert np.array_equal(mask, cut | ndimage.binary_dilation(thin)), lens


def test_a_fit_that_leans_on_the_faint_edges_and_faded_pixels_together_is_said_so(tmp_path, gl_available,
                                                                                  fitted, monkeypatch):
    """Fitted to the silhouette with its faint edges, the rebuilt fish may score a little less against
    the bare silhouette and a little less at half coverage, neither alone under 0.85; both together
    can be (605 in Blender: 0.894 by its own figure, 0.857 bare, 0.874 at half, 0.840 in Blender).
    Then one line says so, with each figure; where the bare figure is the fitted one, it is silent
    (the same fit unpatched, in the test above). What is said changes nothing written: the files are
    the unpatched fit's byte for byte, as the same inputs always write the same bytes."""
    from fishgen.authoring.photo import run as run_module
    from fishgen.authoring.photo.image import load_photo, measuring_side, working_copy
    from fishgen.authoring.photo.run import TextureOptions, make_texture
    from fishgen.authoring.photo.silhouette import silhouette

    rec = bp.fixture_records()["long"]
    original = load_photo(rec["photo"])
    bare = silhouette(working_copy(original, measuring_side(original.size))).mask
    base = _bases(["bonybream"])["bonybream"]
    options = TextureOptions(fit_shape=True, focal_length=rec["shot"]["lens"])
    real = run_module._iou_with
    lower = 0.06

    def iou_with(candidate, mask, render):
        """The rebuilt fish against the bare silhouette ``lower`` less: a fish whose faint edges
        hold more of its outline."""
        return real(candidate, mask, render) - (lower if np.array_equal(mask, bare) else 0.0)

    unpatched = fitted("long", "bonybream")   # the module's shared fit, made (if not yet) before the patch
    monkeypatch.setattr(run_module, "_iou_with", iou_with)
    notes: list[str] = []
    result = make_texture(rec["photo"], base, tmp_path / "bonybream.txt", options, notes.append)
    said = [n for n in notes if "with both" in n]
    assert result.fitted and result.iou is not None and result.iou >= 0.9, notes
    assert len(said) == 1 and "\n" not in said[0], notes
    assert said[0].startswith(f"silhouette IoU {result.iou:.3f}, but 0."), said
    assert "give --mask" in said[0], said
    assert not any(n.startswith("needs --mask") for n in unpatched.row.notes), unpatched.row.notes
    for name in ("bonybream.txt", "bonybream.png", "bonybream_mask.png"):
        assert (tmp_path / name).read_bytes() == unpatched.out.with_name(name).read_bytes(), name


@pytest.mark.slow
def test_a_fit_that_misses_a_pale_fin_says_so(gl_available, fitted):
    """Seed 2007 over water (a fresh set's photo, 50 mm): its translucent pelvic fin is nearly the
    water's colour, the silhouette leaves it out, and the rebuilt fish, without it, matches that
    silhouette well (0.907-0.935 by the command's own figure on the four bases) but not the photo
    (0.795-0.818 in Blender). The pale patch the fin leaves (silhouette.pale_patches) is taken with
    the other doubts, and one line says so with each figure."""
    row = fitted("sampled_2007", "threadfingoldie").row
    assert row.kept and row.own is not None and row.own >= 0.9, row
    assert row.raster < TARGET, row     # the miss, as CI measures it without Blender
    said = [n for n in row.notes if n.startswith("silhouette IoU")]
    assert len(said) == 1 and "\n" not in said[0], row.notes
    assert "if the pale patches joined to the photo's outline are fish" in said[0], said
    assert "translucent fin" in said[0] and "give --mask" in said[0], said
    figures = [float(f) for f in re.findall(r"\b0\.\d{3}\b", said[0])]
    assert figures[0] == round(row.own, 3) and figures[-1] < TARGET, said


@pytest.mark.parametrize("subsampling, sampling", [("4:2:0", 2), ("4:4:4", 0)])
def test_photos_resaved_as_jpeg_keep_their_water_and_their_colour_s_sampling(tmp_path, subsampling, sampling):
    """The benchmark's JPEG rounds (`benchmarks/texture.py --blender --jpeg 90`): only water photos
    (a JPEG has no alpha), saved at the quality and sampling asked, the true silhouette unchanged."""
    from PIL import Image, JpegImagePlugin

    records = bp.fixture_records()
    out = bp.resaved(records, tmp_path, 90, subsampling)
    assert set(out) == {n for n, r in records.items() if r["shot"]["backdrop"] == "water"}
    for name, rec in out.items():
        assert rec["mask"] == records[name]["mask"]
        with Image.open(rec["photo"]) as img:
            assert img.format == "JPEG" and img.size == (rec["camera"]["width"], rec["camera"]["height"])
            assert JpegImagePlugin.get_sampling(img) == sampling
            with Image.open(records[name]["photo"]) as png:
                error = np.abs(np.asarray(img, float) - np.asarray(png.convert("RGB"), float)).mean()
        assert 0 < error < 2, f"{name}: {error:.2f} levels from the PNG"


def test_a_camera_s_photo_is_blurred_and_grainy_and_the_same_every_time(tmp_path):
    """`--camera`: blur, grain seeded by the shot and JPEG 85, so a rerun fits the same photo."""
    from fishgen.authoring.photo.image import load_photo
    from fishgen.authoring.photo.silhouette import grain

    records = {"long": bp.fixture_records()["long"]}
    first = bp.resaved(records, tmp_path / "a", bp.CAMERA_QUALITY, camera=True)["long"]["photo"]
    again = bp.resaved(records, tmp_path / "b", bp.CAMERA_QUALITY, camera=True)["long"]["photo"]
    assert first.read_bytes() == again.read_bytes()
    clean = bp.resaved(records, tmp_path / "c", bp.CAMERA_QUALITY)["long"]["photo"]
    assert grain(load_photo(first)) > grain(load_photo(clean)) + 0.5
