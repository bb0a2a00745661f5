"""The silhouette cut from a photo's backdrop keeps thin fins: their tips set the fish's size."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image, ImageDraw
from scipy import ndimage  # type: ignore[import-untyped]

from fishgen.authoring.photo.image import Photo
from fishgen.authoring.photo.silhouette import grain, silhouette
from fishgen.errors import FishgenError
from tests.conftest import ROOT

SIZE = (400, 240)
FISH = np.array([220.0, 200.0, 150.0])


def _photo(fin: float = 0.45, with_speck: bool = False, noise: float = 0.0) -> Photo:
    """A pale fish on a vertical water-like gradient: an ellipse body and, above its back, a fin
    (``fin``: its opacity over the backdrop) tapering from 12 px to a 1-px thread reaching row 40."""
    w, h = SIZE
    ys = np.linspace(0.0, 1.0, h)[:, None, None]
    top, bottom = np.array([60.0, 140.0, 170.0]), np.array([20.0, 60.0, 110.0])
    rgb = (top * (1 - ys) + bottom * ys) * np.ones((1, w, 1))
    body, fin_layer = Image.new("L", SIZE, 0), Image.new("L", SIZE, 0)
    ImageDraw.Draw(body).ellipse((100, 100, 300, 160), fill=255)
    pen = ImageDraw.Draw(fin_layer)
    pen.polygon([(180, 105), (192, 105), (187, 80)], fill=255)
    pen.line([(187, 80), (196, 40)], fill=255, width=1)
    if with_speck:
        ImageDraw.Draw(body).rectangle((40, 40, 41, 41), fill=255)
    on_fin = (np.asarray(fin_layer) > 0)[:, :, None]
    rgb = np.where(on_fin, rgb + fin * (FISH - rgb), rgb)
    rgb = np.where((np.asarray(body) > 0)[:, :, None], FISH, rgb)
    if noise:
        rgb += np.random.default_rng(3).normal(0.0, noise, rgb.shape)
    return Photo(np.clip(rgb, 0, 255).astype(np.uint8), None, Path("photo.png"))


def _top(mask: np.ndarray) -> int:
    return int(np.flatnonzero(mask.any(axis=1))[0])


def test_a_thread_thin_fin_tip_stays_on_the_fish():
    """The noise-clearing opening takes off anything under 3 px wide; a fin's 1-px thread touching
    the fish comes back, so the silhouette reaches the tip's row."""
    mask = silhouette(_photo(fin=0.45)).mask
    assert _top(mask) <= 43, f"the fin's tip (row 40) was cut at row {_top(mask)}"
    assert mask[41:80].sum() >= 30     # the thread itself, not one stray pixel


def test_a_faint_thread_the_box_filter_averages_away_stays_too():
    """A translucent fin's thread has a third of its contrast after the 3x3 box filter, under the
    backdrop's threshold; judged on the photo's own pixels it is still the fish's."""
    mask = silhouette(_photo(fin=0.28)).mask
    assert _top(mask) <= 43, f"the faint fin's tip (row 40) was cut at row {_top(mask)}"


def test_specks_apart_from_the_fish_stay_out():
    mask = silhouette(_photo(with_speck=True, noise=4.0)).mask
    assert not mask[30:50, 30:50].any()
    ys, xs = np.nonzero(mask)
    assert xs.min() >= 98 and xs.max() <= 302 and ys.max() <= 162


#: The committed photo whose silhouette falls short: a translucent pelvic fin nearly the water's
#: colour, which the silhouette leaves out (IoU 0.893 with the true coverage) and only
#: :func:`~fishgen.authoring.photo.silhouette.pale_patches` tells (the tests below).
PALE_FIN = "sampled_2007"


def test_translucent_fins_over_mottled_water_are_fish():
    """Blender's photos (committed, with the true coverage): translucent fins over a mottled water
    backdrop sit within the backdrop's own spread of colours, yet they are fish. Judged against the
    backdrop just around them they are kept (the border model alone: IoU 0.72 and 0.86)."""
    from fishgen.authoring.photo.image import load_photo
    from tests.authoring.blender_photo import fixture_records, read_mask

    for name, rec in fixture_records().items():
        if rec["shot"]["backdrop"] != "water":
            continue
        sil = silhouette(load_photo(rec["photo"]))
        truth = read_mask(rec["mask"])
        assert sil.source == "background model"
        iou = (sil.mask & truth).sum() / (sil.mask | truth).sum()
        if name == PALE_FIN:   # the known shortfall: a fin nearly the water's colour left out
            assert 0.85 <= iou < 0.92, f"{name}: silhouette IoU {iou:.3f} (a fix? move it to the rest)"
            continue
        assert iou >= 0.92, f"{name}: silhouette IoU {iou:.3f} with the true coverage"


def test_faint_edges_give_back_the_fin_tips_that_set_the_box():
    """Over water a translucent fin's last tips are too faint for the silhouette, yet they set the
    box a cropped IoU is measured in: the silhouette's faint edges (thin runs joined to it that
    differ from the backdrop around them) bring that box back to the true coverage's."""
    from fishgen.authoring.photo.compare import silhouette_iou
    from fishgen.authoring.photo.image import load_photo
    from fishgen.authoring.photo.silhouette import faint_edges
    from tests.authoring.blender_photo import fixture_records, read_mask

    for name, rec in fixture_records().items():
        if rec["shot"]["backdrop"] != "water":
            continue
        photo, truth = load_photo(rec["photo"]), read_mask(rec["mask"])
        fish = silhouette(photo).mask
        faint = faint_edges(photo, fish)
        assert not (faint & fish).any()
        # the rest is mostly the rim: pixels less than half covered, which the truth leaves out
        assert (faint & truth).sum() >= 2 / 3 * faint.sum(), f"{name}: faint edges off the fish"
        before, after = silhouette_iou(truth, fish), silhouette_iou(truth, fish | faint)
        # 2007's faint edges stop 8 rows short of its dorsal fin's one-pixel tip (0.857 -> 0.871)
        gain = 0.01 if name == PALE_FIN else 0.03
        assert after >= before + gain, f"{name}: cropped IoU {before:.3f} -> {after:.3f}"


def test_faint_edges_of_an_alpha_photo_are_its_faint_alpha():
    alpha = np.zeros((40, 60), np.uint8)
    alpha[10:30, 10:40] = 255          # the fish
    alpha[19:21, 40:50] = 30           # a translucent fin's tip, under the silhouette's cutoff
    alpha[2:4, 2:6] = 30               # faint, but not joined to the fish
    photo = Photo(np.zeros((40, 60, 3), np.float32), alpha, Path("p.png"))
    from fishgen.authoring.photo.silhouette import faint_edges

    fish = silhouette(photo).mask
    assert not fish[19:21, 40:50].any()
    assert faint_edges(photo, fish).sum() == 20 and faint_edges(photo, fish)[19:21, 40:50].all()


def _curled(hole_alpha: int, hole: tuple[int, int] = (10, 20)) -> Photo:
    """An alpha photo of a fish 100 x 60 px round a hole of ``hole`` (rows, columns) px of alpha
    ``hole_alpha`` (0: the backdrop seen through it), as a fin curled back to the body leaves."""
    alpha = np.zeros((100, 160), np.uint8)
    alpha[20:80, 30:130] = 255
    rows, cols = hole
    alpha[45:45 + rows, 60:60 + cols] = hole_alpha
    return Photo(np.zeros((100, 160, 3), np.uint8), alpha, Path("p.png"))


def test_a_hole_an_alpha_photo_shows_the_backdrop_through_stays_open():
    """The hand-shaped tall fish's caudal lobe closes a hole over its body: filled, the fit's
    target stood 0.92 from the true silhouette, and the fish fitted to it 0.847 in Blender."""
    fish = silhouette(_curled(0, (10, 20))).mask
    assert not fish[45:55, 60:80].any()
    assert fish.sum() == 60 * 100 - 10 * 20


def test_a_hole_of_faint_alpha_is_a_translucent_fin_and_filled():
    assert silhouette(_curled(40, (10, 20))).mask[45:55, 60:80].all()


def test_a_transparent_spot_under_a_fiftieth_of_the_fish_is_filled():
    """A background remover's transparent eye or spot is no gap between fin and body."""
    assert silhouette(_curled(0, (8, 8))).mask[45:53, 60:68].all()     # 64 px: about 1 %


def test_opening_a_hole_never_cuts_a_fin_off():
    """A dorsal arch 2 px off the body, which the gap-closing joined across the hole under it:
    opened, the arch would float apart, so that hole stays filled."""
    alpha = np.zeros((100, 160), np.uint8)
    alpha[50:80, 30:130] = 255          # the body
    alpha[20:26, 50:110] = 255          # the arch's top
    alpha[26:48, 50:56] = 255           # its legs, ending 2 px above the body
    alpha[26:48, 104:110] = 255
    fish = silhouette(Photo(np.zeros((100, 160, 3), np.uint8), alpha, Path("p.png"))).mask
    assert fish[30:45, 60:100].all()


def test_a_mask_file_s_holes_are_filled_as_unpainted_spots(tmp_path):
    """A drawn mask's unpainted spots, or a mask drawn as an outline, are no backdrop: 25 spots of
    6 px took a review's fit from 0.933 to 0.742 while they were left open."""
    drawn = np.zeros((100, 160), np.uint8)
    drawn[20:80, 30:130] = 255
    drawn[45:55, 60:80] = 0
    Image.fromarray(drawn).save(tmp_path / "mask.png")
    photo = Photo(np.full((100, 160, 3), 90, np.uint8), None, Path("p.png"))
    assert silhouette(photo, tmp_path / "mask.png").mask[45:55, 60:80].all()


def test_over_water_a_hole_is_filled_as_fish_of_the_water_s_colour():
    """Over Blender's water photos, 143 of 144 holes were fish the water's colour."""
    rgb = np.full((100, 160, 3), (40, 90, 120), np.uint8)
    rgb[20:80, 30:130] = (200, 120, 60)
    rgb[45:55, 60:80] = (40, 90, 120)
    assert silhouette(Photo(rgb, None, Path("p.png"))).mask[45:55, 60:80].all()


def _swirled_photo() -> tuple[Photo, np.ndarray]:
    """(photo, truth): an orange fish over flat water with, round its tail, a swirl of darker water
    (14 units deep at its heart, 45 px across, as a Blender murky-water backdrop has them) which the
    frame's border never shows; the caudal fin is a pale tint (a fifth opaque) over that swirl."""
    w, h = SIZE
    yy, xx = np.mgrid[0:h, 0:w]
    swirl = np.exp(-((xx - 330.0) ** 2 + (yy - 120.0) ** 2) / (2 * 45.0 ** 2))
    rgb = np.array([70.0, 140.0, 160.0]) - 14.0 * swirl[:, :, None]
    body, fin = Image.new("L", SIZE, 0), Image.new("L", SIZE, 0)
    ImageDraw.Draw(body).ellipse((100, 100, 280, 150), fill=255)
    ImageDraw.Draw(fin).polygon([(272, 125), (330, 80), (318, 125), (330, 170)], fill=255)
    on_fin, on_body = (np.asarray(fin) > 0)[:, :, None], (np.asarray(body) > 0)[:, :, None]
    rgb = np.where(on_fin, rgb + 0.2 * (np.array([200.0, 220.0, 220.0]) - rgb), rgb)
    rgb = np.where(on_body, np.array([200.0, 120.0, 60.0]), rgb)
    rgb += np.random.default_rng(5).normal(0.0, 1.5, rgb.shape)
    photo = Photo(np.clip(rgb, 0, 255).astype(np.uint8), None, Path("photo.png"))
    return photo, (on_fin | on_body)[:, :, 0]


def test_a_translucent_fin_over_a_swirl_of_darker_water_is_fish():
    """Murky water darker than the frame's edge lies many border deviations off the border's plane:
    it was no known backdrop, so a translucent fin inside such a swirl had nothing near it to stand
    out from and was lost (Blender's seed 901 and 605: their caudal fins). Against the swirl's own
    smooth backdrop the fin's tint stands out, and the swirl stays out (IoU 0.918 before)."""
    photo, truth = _swirled_photo()
    mask = silhouette(photo).mask
    iou = (mask & truth).sum() / (mask | truth).sum()
    assert iou >= 0.97, f"silhouette IoU {iou:.3f} with the truth"
    assert (truth & ~mask).sum() <= 200 and (mask & ~truth).sum() <= 50


def _pale_scene(kind: str, noise: float = 0.6) -> tuple[Photo, np.ndarray, np.ndarray]:
    """A dark fish over plain water, and under it a patch as large as a pelvic fin: ``fin``, the
    water's colour but 4 levels with paler rays every 8 px; ``swirl``, smooth water 8 levels paler.
    (photo, the fish, where the patch is)."""
    rng = np.random.default_rng(3)
    h, w = 200, 320
    y, x = np.mgrid[0:h, 0:w]
    rgb = np.array([110.0, 153.0, 166.0]) + rng.normal(0, noise, (h, w, 3))
    fish = ((x - 160) / 80.0) ** 2 + ((y - 90) / 30.0) ** 2 <= 1
    rgb[fish] = [150, 110, 160]
    under = (x >= 140) & (x < 180) & (y >= 112) & (y < 150) & ~fish
    if kind == "fin":
        rgb[under] += [0, 4, -2]
        rgb[under & ((x - 140) % 8 < 2)] += 6
    else:
        rgb += 8 * np.exp(-(((x - 160) / 16.0) ** 2 + ((y - 128) / 16.0) ** 2))[..., None] * ~fish[..., None]
    return Photo(np.clip(np.rint(rgb), 0, 255).astype(np.uint8), None, Path("p.png")), fish, under


def test_a_fin_nearly_the_water_s_colour_is_a_pale_patch_and_a_smooth_swirl_is_not(monkeypatch):
    """Joined to the fish and a few levels off the water around it, a patch with rays (fine detail
    the water lacks) may be a translucent fin; a swirl of water, though it stands further off, is as
    smooth as the water and is not (three.js's murky water: its swirls 6-12 levels off, 1.0-1.5 times
    the water's detail). Without that test of detail the swirl would be taken too."""
    from fishgen.authoring.photo import silhouette as module

    photo, fish, under = _pale_scene("fin")
    pale = module.pale_patches(photo, fish)
    assert (pale & under).sum() >= 0.9 * under.sum() and (pale & ~under).sum() <= 0.05 * pale.sum()
    photo, fish, under = _pale_scene("swirl")
    assert not module.pale_patches(photo, fish).any()
    monkeypatch.setattr(module, "PALE_GRAIN", 0.0)
    assert (module.pale_patches(photo, fish) & under).sum() >= 0.5 * under.sum()
    monkeypatch.undo()
    alpha = Photo(photo.rgb, np.full(fish.shape, 255, np.uint8), Path("p.png"))
    assert not module.pale_patches(alpha, fish).any()    # an alpha channel says what is fish


def test_blender_s_pale_pelvic_fin_is_a_pale_patch():
    """Blender's committed photo of seed 2007 over water: its translucent pelvic fin, nearly the
    water's colour, is left out of the silhouette and its faint edges (IoU 0.922 with the true
    coverage) but found as a pale patch, nearly all of it fish (0.949 with it). On the other water
    photos there is none: the few dozen pixels their outlines' halos leave are judged only
    PALE_RING px off the outline and more, where they are water."""
    from fishgen.authoring.photo.image import load_photo
    from fishgen.authoring.photo.silhouette import faint_edges, pale_patches
    from tests.authoring.blender_photo import fixture_records, read_mask

    for name, rec in fixture_records().items():
        if rec["shot"]["backdrop"] != "water":
            continue
        photo, truth = load_photo(rec["photo"]), read_mask(rec["mask"])
        sil = silhouette(photo).mask
        outline = sil | faint_edges(photo, sil)
        pale = pale_patches(photo, outline)
        assert not (pale & outline).any()
        if name != PALE_FIN:   # beside the outline (ringing, a rim's halo) nothing is judged
            assert not pale.any(), name
            continue
        assert pale.sum() >= 0.03 * outline.sum() and (pale & truth).sum() >= 0.9 * pale.sum()
        iou = [(m & truth).sum() / (m | truth).sum() for m in (outline, outline | pale)]
        assert iou[0] < 0.93 and iou[1] >= iou[0] + 0.02, iou


FAINT_TIP = ROOT / "tests" / "fixtures" / "faint_tip" / "sampled_2411"


def test_a_tall_fin_s_faint_tip_is_a_faint_edge(monkeypatch):
    """Blender's photo of seed 2411 (tests/fixtures/faint_tip): the last 12 px of its tall dorsal
    fin are a 1-px line 3-4 deviations off water nearly its colour. The silhouette and the faint
    edges at FAINT_SIGMAS stop short of it, and the box a fit is measured in was 5 % short (0.945
    by the command's figure, 0.846 in Blender, said by nothing). The line runs on out from the
    fish, so it is a faint edge too: the outline reaches the true top, and every pixel the line
    adds is fish."""
    from fishgen.authoring.photo import silhouette as module
    from fishgen.authoring.photo.image import load_photo
    from tests.authoring.blender_photo import read_mask

    photo = load_photo(FAINT_TIP.with_suffix(".png"))
    truth = read_mask(FAINT_TIP.with_name(FAINT_TIP.name + "_mask.png"))
    fish = silhouette(photo).mask
    tip = module.faint_edges(photo, fish)
    monkeypatch.setattr(module, "TIP_REACH", 10**6)    # the tip's rule off: the faint edges alone
    faint = module.faint_edges(photo, fish)
    top = np.nonzero(truth)[0].min()
    assert np.nonzero(fish | faint)[0].min() - top >= 10          # the fin's tip, lost without it
    assert np.nonzero(fish | tip)[0].min() - top <= 1
    added = tip & ~faint
    assert added.sum() >= 10 and not (added & ~ndimage.binary_dilation(truth)).any()


def test_jpeg_rings_round_an_outline_are_no_fin_tip(tmp_path, monkeypatch):
    """The committed water photos saved as JPEG 90 with their colour at half size: the blocks ring
    round every outline in lines as faint as the tip above, but along it: the tip's rule takes
    none of them, so the outline's box stays where the faint edges alone put it."""
    from PIL import Image

    from fishgen.authoring.photo import silhouette as module
    from fishgen.authoring.photo.image import load_photo
    from tests.authoring.blender_photo import fixture_records

    waters = [rec for rec in fixture_records().values() if rec["shot"]["backdrop"] == "water"]
    assert len(waters) >= 3
    for rec in waters:
        path = tmp_path / f"{rec['photo'].stem}.jpg"
        Image.open(rec["photo"]).convert("RGB").save(path, quality=90, subsampling="4:2:0")
        photo = load_photo(path)
        fish = silhouette(photo).mask
        with monkeypatch.context() as m:
            m.setattr(module, "TIP_REACH", 10**6)
            faint = module.faint_edges(photo, fish)
        assert not (module.faint_edges(photo, fish) & ~faint).any(), path.name


def test_over_a_noise_free_backdrop_a_smooth_patch_is_not_pale(monkeypatch):
    """A backdrop with no noise at all (a flat studio colour, a synthetic render) has no fine detail
    to compare with: it counts as PALE_DETAIL's, so a smooth shadow beside the fish is not taken
    for a fin, as it would be were any detail at all 1.5 times none."""
    from fishgen.authoring.photo import silhouette as module

    photo, fish, under = _pale_scene("swirl", noise=0.0)
    assert not module.pale_patches(photo, fish).any()
    monkeypatch.setattr(module, "PALE_DETAIL", 0.0)
    assert (module.pale_patches(photo, fish) & under).sum() >= 0.3 * under.sum()


def test_grain_is_the_border_s_spread_round_its_own_mean():
    """A render's backdrop is smooth; a camera's sensor adds grain, measured in levels."""
    smooth = _photo()
    rng = np.random.default_rng(7)
    grainy = Photo(np.clip(smooth.rgb + rng.normal(0.0, 4.0, smooth.rgb.shape), 0, 255).astype(np.uint8),
                   None, Path("grainy.png"))
    assert grain(smooth) < 0.5
    assert 3.0 < grain(grainy) < 4.5        # 4 levels, less the 3 x 3 mean's own share of it


WATER = np.array([70.0, 140.0, 160.0])


def _outlined_fish(gap: int, grain: float = 3.0) -> tuple[Photo, np.ndarray]:
    """A fish nearly the water's colour (its body 15 levels off it in hue) that stands out by its
    dark outline alone, the outline broken for ``gap`` px on its back; and the body's true pixels."""
    w, h = SIZE
    body, rim = Image.new("L", SIZE, 0), Image.new("L", SIZE, 0)
    ImageDraw.Draw(body).ellipse((100, 80, 300, 160), fill=255)
    ImageDraw.Draw(rim).ellipse((100, 80, 300, 160), outline=255, width=5)
    inside, outline = np.asarray(body) > 0, np.asarray(rim) > 0
    outline[:120, 200:200 + gap] = False
    rgb = np.ones((h, w, 1)) * WATER
    rgb = np.where(inside[:, :, None], WATER + np.array([14.0, -4.0, -6.0]), rgb)
    rgb = np.where(outline[:, :, None], np.array([30.0, 60.0, 70.0]), rgb)
    rgb += np.random.default_rng(5).normal(0.0, grain, rgb.shape)
    return Photo(np.clip(rgb + 0.5, 0, 255).astype(np.uint8), None, Path("photo.png")), inside


def test_the_inside_of_a_faint_fish_does_not_leak_out_through_a_break_in_its_outline(monkeypatch):
    """Grain or JPEG breaks a faint fish's outline for a few pixels, and the body inside, no hole
    then, was lost (3011 in grain: silhouette 0.51 with the truth). Sealed, and another colour
    than the water beside it, it is fish."""
    from fishgen.authoring.photo import silhouette as module

    for gap in (6, 10):
        photo, inside = _outlined_fish(gap)
        assert silhouette(photo).mask[inside].mean() >= 0.98, gap
    monkeypatch.setattr(module, "leaked_inside", lambda rgb, fish: np.zeros_like(fish))
    monkeypatch.setattr(module, "GRAINY", np.inf)   # nor judged smoothed as grain's faint body
    photo, inside = _outlined_fish(10)
    assert silhouette(photo).mask[inside].mean() < 0.5     # what it was


def _notch(colour: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(rgb, fish, notch): a fish with two fins on its back 14 px apart at their tips, the water
    between them painted ``colour``."""
    w, h = SIZE
    fish_img, hull = Image.new("L", SIZE, 0), Image.new("L", SIZE, 0)
    pen = ImageDraw.Draw(fish_img)
    pen.ellipse((100, 80, 300, 160), fill=255)
    pen.polygon([(160, 95), (185, 95), (192, 40)], fill=255)
    pen.polygon([(212, 95), (235, 95), (206, 40)], fill=255)
    ImageDraw.Draw(hull).polygon([(192, 40), (206, 40), (212, 95), (185, 95)], fill=255)
    fish = np.asarray(fish_img) > 0
    notch = (np.asarray(hull) > 0) & ~fish
    rgb = np.ones((h, w, 1)) * WATER
    rgb = np.where(notch[:, :, None], colour, rgb)
    rgb = np.where(fish[:, :, None], FISH, rgb)
    return np.clip(rgb, 0, 255).astype(np.uint8), fish, notch


def test_water_in_shade_between_two_fins_stays_water():
    """The disk that seals a broken outline seals the notch between two fins too; water there in
    shade or light is the water's own colour darker or brighter (three.js's mottled water beside a
    pineapple fish's fins: 6.9 levels darker, 2.5 in hue) and stays out. The same notch in another
    hue is taken: the rule is the hue, not the notch."""
    from fishgen.authoring.photo.silhouette import leaked_inside

    for shade in (0.7, 1.2):
        rgb, fish, notch = _notch(WATER * shade)
        assert not (leaked_inside(rgb, fish) & notch).any(), shade
    rgb, fish, notch = _notch(WATER + np.array([20.0, -8.0, -8.0]))
    assert (leaked_inside(rgb, fish) & notch).sum() >= 0.9 * notch.sum()


def test_the_water_between_a_spiny_fish_s_spines_is_no_leaked_body():
    """A spiny fish's dorsal seals many narrow gaps, each a chance to stand out in hue from the
    water beside it (over water blotched in hue, a review's spiny fish took 2-21 of its 46 gaps at
    5 levels: its IoU 0.97 -> 0.80-0.96). A gap the disk merely bridged is no wider than the disk:
    only a region wider than that, a body behind a break, is judged."""
    from fishgen.authoring.photo.silhouette import LEAK_CLOSE, leaked_inside

    w, h = SIZE
    img = Image.new("L", SIZE, 0)
    pen = ImageDraw.Draw(img)
    pen.ellipse((80, 110, 320, 170), fill=255)
    for x in range(120, 280, 13):            # spines 3 px wide, 10 px apart
        pen.polygon([(x, 125), (x + 3, 125), (x + 2, 50), (x + 1, 50)], fill=255)
    fish = np.asarray(img) > 0
    gaps = ndimage.binary_fill_holes(ndimage.binary_closing(fish, structure=np.ones((2 * LEAK_CLOSE + 1,) * 2,
                                                                                   bool))) & ~fish
    assert gaps.sum() > 1000
    rgb = np.ones((h, w, 1)) * WATER
    rgb = np.where(gaps[:, :, None], WATER + np.array([20.0, -8.0, -8.0]), rgb)   # another hue there
    rgb = np.where(fish[:, :, None], FISH, rgb)
    assert not (leaked_inside(np.clip(rgb, 0, 255).astype(np.uint8), fish) & gaps).any()


def _faint_half(swirl: bool = False) -> tuple[Photo, np.ndarray]:
    """A grainy photo of a fish whose head stands 40 levels off the water and whose body behind it
    only 17, with a sharp edge (a body nearly the water's colour, as a camera's grain leaves it);
    with ``swirl``, in a larger frame, a smooth swirl of water as faint just above its head. And the
    fish's pixels."""
    (w, h), box, split = ((560, 360), (100, 110, 460, 300), 190) if swirl else (SIZE, (60, 40, 340, 200), 130)
    img = Image.new("L", (w, h), 0)
    ImageDraw.Draw(img).ellipse(box, fill=255)
    body = np.asarray(img) > 0
    tint = np.array([1.0, -0.13, -0.47])
    rgb = np.ones((h, w, 1)) * WATER
    if swirl:
        yy, xx = np.mgrid[0:h, 0:w]
        rgb = rgb + 22.0 * np.exp(-((yy - 95) ** 2 + (xx - 165) ** 2) / (2 * 30.0 ** 2))[:, :, None] * tint
    head = body & (np.arange(w)[None, :] < split)
    rgb = np.where(head[:, :, None], WATER + np.array([40.0, -5.0, -20.0]), rgb)
    rgb = np.where((body & ~head)[:, :, None], WATER + 15.0 * tint, rgb)
    rgb += np.random.default_rng(6).normal(0.0, 2.0, rgb.shape)
    return Photo(np.clip(rgb + 0.5, 0, 255).astype(np.uint8), None, Path("photo.png")), body


def test_a_body_nearly_the_water_s_colour_joined_to_the_fish_is_fish(monkeypatch):
    """2801 in full HD, given a camera's grain, lost its faint back (silhouette 0.60 against the
    truth): 13-18 levels off the water, under the 20 the background model asks of a pixel alone.
    A solid region joined to the fish whose edge steps up from the water is judged down to 12."""
    from fishgen.authoring.photo import silhouette as module

    photo, body = _faint_half()
    assert silhouette(photo).mask[body].mean() >= 0.97
    monkeypatch.setattr(module, "_faint_body", lambda contrast, distance, sure, **_: np.zeros_like(sure))
    assert silhouette(photo).mask[body].mean() < 0.5      # what it was


def test_a_smooth_swirl_of_water_as_faint_beside_the_fish_stays_water(monkeypatch):
    """Water as far off the border's model (a swirl, a gradient) rises out of the water round it
    with no edge: over 8 of Blender's sets such regions stood 3.4 levels at most above the water
    just beyond them, fish 4 and more. Not judged by that step, the swirl would be fish."""
    from fishgen.authoring.photo import silhouette as module

    photo, body = _faint_half(swirl=True)
    apart = ~ndimage.binary_dilation(body, iterations=3)
    mask = silhouette(photo).mask
    assert mask[body].mean() >= 0.97
    assert mask[apart].sum() == 0
    monkeypatch.setattr(module, "FAINT_STEP", -np.inf)
    assert silhouette(photo).mask[apart].sum() > 1000


def _grainy_head(swirl: float = 0.0) -> tuple[Photo, np.ndarray, np.ndarray]:
    """A camera's photo (grain of 6 levels a channel, softened as a lens and JPEG soften it: 1.5 by
    :func:`grain`) of a fish whose head stands 10 levels off the water and whose body behind it 40;
    with ``swirl``, a smooth swirl of water that many levels off at its peak, over the body and
    touching it. And the fish's pixels, and its head's."""
    (w, h), split = (560, 360), 190
    img = Image.new("L", (w, h), 0)
    ImageDraw.Draw(img).ellipse((100, 110, 460, 300), fill=255)
    body = np.asarray(img) > 0
    head = body & (np.arange(w)[None, :] < split)
    tint = np.array([1.0, -0.13, -0.47])
    yy, xx = np.mgrid[0:h, 0:w]
    rgb = WATER + swirl * np.exp(-((yy - 100) ** 2 + (xx - 330) ** 2) / (2 * 30.0 ** 2))[:, :, None] * tint
    rgb = np.where((body & ~head)[:, :, None], WATER + np.array([40.0, -5.0, -20.0]), rgb)
    rgb = np.where(head[:, :, None], WATER + 10.0 * tint, rgb)
    rng = np.random.default_rng(3)
    shared, own = rng.standard_normal((h, w, 1)), rng.standard_normal((h, w, 3))   # luma, channels
    rgb += 6.0 * (np.sqrt(0.6) * shared + np.sqrt(0.4) * own)
    rgb = ndimage.gaussian_filter(rgb, (0.7, 0.7, 0))
    return Photo(np.clip(rgb + 0.5, 0, 255).astype(np.uint8), None, Path("photo.jpg")), body, head


def test_in_a_camera_s_grain_a_head_nearly_the_water_s_colour_is_fish(monkeypatch):
    """4303 and 4109 in Blender, given a camera's grain, lost their heads (9-14 levels off the water,
    under the faint body's 12, in 3-4 levels of grain): in a grainy photo the faint body is judged
    again on the photo smoothed over 2 px, where the grain falls under a level."""
    from fishgen.authoring.photo import silhouette as module

    photo, body, head = _grainy_head()
    assert 1.0 <= grain(photo) < 2.0
    mask = silhouette(photo).mask
    assert mask[head].mean() >= 0.9
    assert (mask & ~body).sum() < 50
    monkeypatch.setattr(module, "GRAINY", np.inf)     # a render's photo: judged pixel by pixel alone
    assert silhouette(photo).mask[head].mean() < 0.1


GRAINY_HEAD = ROOT / "tests" / "fixtures" / "grainy_head" / "sampled_4109"


def test_a_camera_s_photo_of_a_fish_with_a_pale_head_keeps_the_head(monkeypatch):
    """Blender's photo of seed 4109 as a camera writes it (tests/fixtures/grainy_head): the head was
    lost to the grain (silhouette 0.865 against the truth; its fits 0.58-0.74 in Blender, each said
    by the grain line). Judged smoothed, it is fish."""
    from fishgen.authoring.photo import silhouette as module
    from fishgen.authoring.photo.image import load_photo
    from tests.authoring.blender_photo import read_mask

    photo = load_photo(GRAINY_HEAD.with_suffix(".jpg"))
    truth = read_mask(GRAINY_HEAD.with_name(GRAINY_HEAD.name + "_mask.png"))
    mask = silhouette(photo).mask
    monkeypatch.setattr(module, "GRAINY", np.inf)
    lost = silhouette(photo).mask
    assert (lost & truth).sum() / (lost | truth).sum() < 0.88
    assert (mask & truth).sum() / (mask | truth).sum() >= 0.92
    added = mask & ~lost
    assert added.sum() >= 1000 and (added & ~ndimage.binary_dilation(truth, iterations=2)).sum() < 20


def test_in_a_camera_s_grain_a_smooth_swirl_beside_the_fish_stays_water(monkeypatch):
    """Smoothed, the water's swirls stand out as a faint body does; the edge test still tells them
    apart (a swirl rises out of the water with no step)."""
    from fishgen.authoring.photo import silhouette as module

    photo, body, head = _grainy_head(swirl=14.0)
    mask = silhouette(photo).mask
    assert mask[head].mean() >= 0.9
    assert (mask & ~body).sum() < 200
    monkeypatch.setattr(module, "FAINT_STEP", -np.inf)
    assert (silhouette(photo).mask & ~body).sum() > 1000


def test_a_fish_whose_fins_alone_stand_out_is_told_it_may_be_one_fish():
    """Two bright fins on a body of the water's own colour are two objects to the border model; the
    refusal says that they may be one fish, not only "crop the photo to one fish" (3607 in Blender)."""
    w, h = SIZE
    fins = Image.new("L", SIZE, 0)      # on a body (100, 80)-(300, 160) drawn in the water's colour
    pen = ImageDraw.Draw(fins)
    pen.polygon([(150, 85), (200, 85), (190, 30)], fill=255)
    pen.polygon([(170, 155), (220, 155), (230, 215)], fill=255)
    fin = np.asarray(fins) > 0
    rgb = np.ones((h, w, 1)) * WATER
    rgb = np.where(fin[:, :, None], np.array([40.0, 70.0, 230.0]), rgb)
    rgb += np.random.default_rng(7).normal(0.0, 1.0, rgb.shape)
    photo = Photo(np.clip(rgb + 0.5, 0, 255).astype(np.uint8), None, Path("photo.png"))
    with pytest.raises(FishgenError, match="found 2 objects of similar size .several fish, or one whose "
                                           "body is nearly the backdrop's colour"):
        silhouette(photo)
