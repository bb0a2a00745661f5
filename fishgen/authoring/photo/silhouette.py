"""Fish versus background: alpha when the photo has it, else a colour model of the frame's border.

The border model is a plane per colour channel (a mild lighting gradient is a
plane) fitted robustly to a strip around the frame; a pixel is fish when its
colour lies far outside the border's own spread. The photo is box-filtered
first so sensor noise and JPEG ringing average out before anything is judged.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from scipy import ndimage  # type: ignore[import-untyped]

from fishgen.authoring.photo.image import Photo
from fishgen.errors import FishgenError

ALPHA_CUTOFF = 64          # translucent (blended) fins still count as fish
MIN_FISH_FRACTION = 0.002  # of the frame; less is "no fish"
SECOND_OBJECT = 0.25       # a second blob this big relative to the fish is "several objects"
NOISE_SIGMAS = 5.0         # colour distance, in border standard deviations, that is surely not background
MIN_CONTRAST = 20.0        # ... and never less than this (0-255 units), for flat synthetic backgrounds
THREAD_REACH = 6           # px: how near the fish a fin's thread is judged against its contrast
LOCAL_SIGMA = 12.0         # px: the scale of the local backdrop a translucent fin is judged against
LOCAL_SIGMAS = 4.0         # colour distance from the local backdrop, in its own deviations, that is fin
PATCH_SIGMAS = 6.0         # ... that a patch of fin holds at its median, where mottled water peaks
LOCAL_CONTRAST = 6.0       # ... and never less than this (0-255 units)
LOCAL_BOX = 5              # px: a box filter that averages JPEG's ringing out, not a fin
LOCAL_WIDTH = 4            # px: the narrowest patch of fin judged so
LOCAL_PATCH = 0.001        # of the fish's area: the smallest patch of fin judged so
NEAR_BAND = 12             # px round the fish whose backdrop sets that spread
FAINT_ALPHA = 16           # alpha that may be a translucent fin's edge, not surely fish
OPEN_HOLE = 0.02           # of the fish's area: the smallest hole an alpha channel leaves open
GRAIN_BORDER = 0.05        # of the frame's shorter side: the border strips a photo's grain is read in
FAINT_SIGMAS = 4.0         # unfiltered colour distance from the local backdrop that may be fin
FAINT_HALF_WIDTH = 2.5     # px: the widest run of such pixels that is a fin's thread, not a swirl
TIP_SIGMAS = 3.0           # fainter still: a line this far from the local backdrop that goes on from them
TIP_CONTRAST = 5.0         # ... and never less than this (0-255 units)
TIP_HALF_WIDTH = 1.5       # px: such a line is this narrow (one or two pixels)
TIP_LENGTH = 8             # px: ... this long
TIP_REACH = 8              # px: ... and reaches this far out (JPEG's rings hug the outline)
SWIRL_SIGMA = 24.0         # px: the scale of murky water's swirls, which the border's plane cannot follow
SWIRL_SIGMAS = 3.0         # distance from the swirls' smooth backdrop, in its own deviations, still backdrop
PALE_SIGMAS = 2.5          # a patch's distance from the water around it that may be a fin nearly its colour
PALE_LEVELS = 3.0          # ... and never less than this (0-255 units)
PALE_GRAIN = 1.5           # ... with this many times the fine detail of the water near the fish
PALE_DETAIL = 0.5          # ... the water's detail taken as at least this (a noise-free backdrop has none)
PALE_RING = 6              # px: a patch's detail is judged this far from the outline and more
SWIRL_CLEAR = 12           # px round the fish left out of that smooth backdrop (a fin not yet found)
LEAK_CLOSE = 9             # px: the radius of the disk that seals a break in a faint outline
LEAK_LEVELS = 5.0          # the mean change of hue (0-255 units) from the water beside it that is fish
LEAK_CORE = 20             # px of a sealed region LEAK_CLEAR px off the fish and more, that it is judged by
LEAK_CLEAR = 3             # px: past the outline's own halo
LEAK_WATER = 15            # px: how far round a sealed region the water it is compared with lies
LEAK_DARK = 30.0           # water darker than this (its colour's length, 0-255 units) is judged by nothing
FAINT_FLOOR = 12.0         # contrast (0-255 units) down to which a solid region joined to the fish is judged
FAINT_SOLID = 9            # px: a square this wide fits everywhere in such a region (in grain's specks, not)
FAINT_STEP = 4.0           # levels its edge steps up from the water just beyond it (a gradient's does not)
GRAINY = 1.0               # grain (levels, :func:`grain`) of a camera's photo: a render's is 0-0.5
GRAIN_SMOOTH = 2.0         # px: the Gaussian a grainy photo's faint body is judged again through
GRAIN_SIGMAS = 3.5         # ... at this many of the smoothed border's deviations
GRAIN_FLOOR = 9.0          # ... and at least this contrast (0-255 units)
GRAIN_FLOOR_PER_LEVEL = 5.0  # ... and this many times the grain (heavier grain, rougher water)


@dataclass(frozen=True)
class Silhouette:
    mask: np.ndarray       # (H, W) bool, the fish alone
    source: str            # "alpha", "background model" or "mask file"
    grain: float | None = None   # the photo's grain (:func:`grain`), measured for the background model


def silhouette(photo: Photo, mask_path: str | os.PathLike | None = None,
               mask_size: tuple[int, int] | None = None, mirror: bool = False) -> Silhouette:
    """The fish's silhouette, checked: one object, wholly inside the frame. A mask file must be
    ``mask_size`` (the original photo's, when ``photo`` is a scaled-down working copy); with
    ``mirror``, it is mirrored as ``photo`` was (:func:`.image.mirror_image`)."""
    levels = None
    if mask_path is not None:
        raw, source = _mask_file(mask_path, mask_size or photo.size, photo.size, mirror), "mask file"
    elif photo.alpha is not None:
        raw, source = photo.alpha >= ALPHA_CUTOFF, "alpha"
    else:
        levels = grain(photo)
        raw, faint = background_model_masks(photo.rgb, levels)
        source = "background model"
    fish = _one_fish(raw, photo, source)
    if source == "background model":
        fish |= _slivers(thread_mask(photo.rgb, fish) & ~fish, fish)
        fish |= translucent_mask(photo.rgb, fish)
        fish |= leaked_inside(photo.rgb, fish)
        # last, and only where it touches the fish found so far: the fish as found decides what
        # belongs together (a faint body that joined two pieces took 2701 in grain, a fish the
        # water's colour refused as several objects, to 0.35 of it by the truth), and its outline
        # stands where it was (redrawn round a faint body it already held, 2801's fits moved 0.05)
        fish = _joined_faint(fish, faint)
    return Silhouette(fish, source, levels)


def _joined_faint(fish: np.ndarray, faint: np.ndarray) -> np.ndarray:
    """``fish`` with the pieces of ``faint`` (:func:`_faint_body`) that touch it, and what they enclose."""
    labels, count = ndimage.label(faint & ~fish, structure=np.ones((3, 3), bool))
    if count == 0:
        return fish
    rim = ndimage.binary_dilation(fish, structure=np.ones((3, 3), bool)) & (labels > 0)
    touching = np.unique(labels[rim])
    if touching.size == 0:
        return fish
    return ndimage.binary_fill_holes(fish | np.isin(labels, touching))


def background_model_masks(rgb: np.ndarray, grain_levels: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(fish, faint body): the pixels whose colour the border's planar colour model does not explain
    (they stand out by MIN_CONTRAST), and the :func:`_faint_body` joined to them; in a photo of
    ``grain_levels`` (:func:`grain`) GRAINY or more, also the faint body :func:`_faint_in_grain` finds."""
    img = ndimage.uniform_filter(rgb.astype(np.float32), size=(3, 3, 1))   # float32 halves the memory
    contrast, distance = _off_backdrop(img)
    sure = (distance > NOISE_SIGMAS) & (contrast > MIN_CONTRAST)
    fish, faint = _rimmed(sure, contrast), _faint_body(contrast, distance, sure)
    if grain_levels >= GRAINY:
        faint |= _faint_in_grain(rgb, fish | faint, grain_levels)
    return fish, faint


def _faint_in_grain(rgb: np.ndarray, found: np.ndarray, grain_levels: float) -> np.ndarray:
    """The :func:`_faint_body` joined to ``found`` (the fish and the faint body judged pixel by pixel)
    in a grainy photo, judged on the photo smoothed over GRAIN_SMOOTH px: down to GRAIN_SIGMAS of its
    border's deviations and GRAIN_FLOOR levels, or GRAIN_FLOOR_PER_LEVEL times the grain where that
    is more.

    A camera's grain of 3-4 levels a channel hides a head or a back 9-14 levels off the water from the
    pixel-by-pixel judgement (4303 and 4109 in Blender, given the benchmark's camera: heads lost,
    silhouettes 0.74 and 0.87 against the truth); smoothed, the grain falls to under a level and the
    body stands out, while the solid and edge tests still tell it from the water's swirls. A floor of
    9 levels whatever the grain took a dark swirl beside 3709's dorsal fin under 6 levels of grain.
    What was found pixel by pixel is where these regions grow from, not part of them: a swirl joined
    to a faint body found so would be judged by that body's sharp edge."""
    smooth = ndimage.gaussian_filter(rgb.astype(np.float32), (GRAIN_SMOOTH, GRAIN_SMOOTH, 0))
    contrast, distance = _off_backdrop(smooth)
    floor = max(GRAIN_FLOOR, GRAIN_FLOOR_PER_LEVEL * grain_levels)
    return _faint_body(contrast, distance, found, floor=floor, sigmas=GRAIN_SIGMAS)


def _rimmed(raw: np.ndarray, contrast: np.ndarray) -> np.ndarray:
    # The outline's own pixels are partly fish: keep one when it carries at least half the
    # contrast of the solid fish just inside it -- the 50 % line of an anti-aliased or
    # JPEG-smeared edge rather than its faint halo. Only that one rim layer is judged, so
    # a pale patch beside a dark one inside the fish (an eye) is never cut out.
    core = ndimage.binary_erosion(raw, structure=np.ones((3, 3), bool))
    inside = ndimage.maximum_filter(np.where(core, contrast, 0.0), size=5)
    rim = raw & ~core
    return core | (rim & ((contrast >= 0.5 * inside) | (inside == 0)))


def _faint_body(contrast: np.ndarray, distance: np.ndarray, sure: np.ndarray, *,
                floor: float = FAINT_FLOOR, sigmas: float = NOISE_SIGMAS) -> np.ndarray:
    """Solid regions joined to the ``sure`` pixels that stand out from the border's model by less
    than MIN_CONTRAST but ``floor`` (FAINT_FLOOR) or more, and by ``sigmas`` of its deviations, with
    an edge: a body nearly the water's colour.

    Given a camera's grain, such a body's outline breaks wider than :func:`leaked_inside` seals and
    its inside goes with the water (2801 in full HD, grainy: silhouette 0.60 against the truth, its
    body 13-18 levels off the model where the water stands under 11). Judged down to FAINT_FLOOR,
    the water's own unevenness comes too: grain's specks (a square FAINT_SOLID px wide fits in no
    speck) and smooth gradients or swirls, whose edge rises out of water nearly as far off the model
    (a ring 2 px inside the region against one 2-4 px outside it: water regions 3.4 levels at
    most over 8 of Blender's sets as PNG, JPEG 90 and grain, fish 4 and more for 42 of 73)."""
    faint = (distance > sigmas) & (contrast > floor)
    solid = ndimage.binary_opening(faint & ~sure, structure=np.ones((FAINT_SOLID, FAINT_SOLID), bool))
    joined = ndimage.binary_propagation(sure, mask=solid | sure, structure=np.ones((3, 3), bool)) & ~sure
    labels, count = ndimage.label(joined, structure=np.ones((3, 3), bool))
    body = np.zeros_like(sure)
    if count == 0:
        return body
    water = ~ndimage.binary_dilation(faint | sure, structure=np.ones((3, 3), bool))
    h, w = sure.shape
    for index, box in enumerate(ndimage.find_objects(labels), start=1):
        if box is None:
            continue
        # room for the ring outside it, 4 px
        rows = slice(max(box[0].start - 6, 0), min(box[0].stop + 6, h))
        cols = slice(max(box[1].start - 6, 0), min(box[1].stop + 6, w))
        region = labels[rows, cols] == index
        # the region's own edge: not where it meets the sure pixels it grew from
        inner = region & ~ndimage.binary_erosion(region, structure=np.ones((3, 3), bool), iterations=2) \
            & ~ndimage.binary_dilation(sure[rows, cols], structure=np.ones((3, 3), bool), iterations=2)
        outer = ndimage.binary_dilation(region, structure=np.ones((3, 3), bool), iterations=4) \
            & ~ndimage.binary_dilation(region, structure=np.ones((3, 3), bool)) & water[rows, cols]
        if inner.sum() < 10 or outer.sum() < 10:
            continue
        here = contrast[rows, cols]
        if float(here[inner].mean() - here[outer].mean()) >= FAINT_STEP:
            body[rows, cols] |= region
    return body


def thread_mask(rgb: np.ndarray, fish: np.ndarray) -> np.ndarray:
    """Pixels of the unfiltered photo that stand out from the backdrop as surely as the fish's do
    and carry at least half the contrast of the fish near them (``fish``: within THREAD_REACH px):
    a fin's last 1-px thread, which the box filter before :func:`background_model_masks` averages
    into the backdrop, and not the faint halo round an anti-aliased edge."""
    contrast, distance = _off_backdrop(rgb.astype(np.float32))
    near = ndimage.maximum_filter(np.where(fish, contrast, 0.0), size=2 * THREAD_REACH + 1)
    return (distance > NOISE_SIGMAS) & (contrast > MIN_CONTRAST) & (contrast >= 0.5 * near)


def translucent_mask(rgb: np.ndarray, fish: np.ndarray) -> np.ndarray:
    """Translucent fin joined to ``fish``: pixels that differ from the backdrop just around them.

    A translucent fin over murky water or sand is the backdrop seen through a tint, often nearer the
    border's colours than the border's own mottling is to its mean, so the border model drops it
    (a Blender photo's fins: silhouette IoU 0.52 with the truth). Against the backdrop *around it*,
    the tint stands out: that backdrop is the photo's confidently-backdrop pixels (under 3 border
    deviations, away from the fish) spread over the gaps by a normalised Gaussian, and a pixel is fin
    when it differs from it by LOCAL_SIGMAS of its own spread and LOCAL_CONTRAST, in a patch at least
    LOCAL_WIDTH px wide that touches the fish and differs by PATCH_SIGMAS at its median. Its rim is
    kept as :func:`background_model_masks` keeps the fish's: where it carries half the contrast of
    the fin just inside it."""
    img = ndimage.uniform_filter(rgb.astype(np.float32), size=(LOCAL_BOX, LOCAL_BOX, 1))
    local = _local_contrast(img, fish)
    if local is None:
        return np.zeros_like(fish)
    contrast, weight, spread, _ = local
    # weight: far from any known backdrop (a frame filled by fish) there is nothing to compare with
    raw = (contrast > max(LOCAL_SIGMAS * spread, LOCAL_CONTRAST)) & (weight > 0.02) & ~fish
    raw = ndimage.binary_opening(raw, structure=np.ones((3, 3), bool))   # the fish's own halo is 1 px
    # A fin holds a patch LOCAL_WIDTH px wide and LOCAL_PATCH of the fish: JPEG's ringing along an
    # outline is a few pixels wide. Such a patch brings its whole piece, tips and thin edges too.
    patch = ndimage.binary_opening(raw, structure=np.ones((LOCAL_WIDTH, LOCAL_WIDTH), bool))
    labels, count = ndimage.label(raw, structure=np.ones((3, 3), bool))
    if count == 0:
        return raw
    touching = np.unique(labels[ndimage.binary_dilation(fish, structure=np.ones((3, 3), bool)) & raw])
    patches = np.bincount(labels[patch], minlength=count + 1)
    touching = touching[(touching > 0) & (patches[touching] >= LOCAL_PATCH * fish.sum())]
    # A fin's tint lifts its whole patch; a brighter swirl of mottled water beside a thin fin
    # passes LOCAL_SIGMAS only at its crest (three.js's water: medians of 4.3-5.1 deviations, where
    # Blender's translucent fins hold 6.8 and more).
    if touching.size:
        medians = np.asarray(ndimage.median(contrast, labels, touching))
        touching = touching[medians >= PATCH_SIGMAS * spread]
    fin = np.isin(labels, touching)
    core = ndimage.binary_erosion(fin, structure=np.ones((3, 3), bool))
    inside = ndimage.maximum_filter(np.where(core, contrast, 0.0), size=5)
    fin = core | (fin & ~core & (contrast >= 0.5 * inside))
    return ndimage.binary_fill_holes(fin | fish) & ~fish


def leaked_inside(rgb: np.ndarray, fish: np.ndarray) -> np.ndarray:
    """The inside of a fish near the water's colour that leaked out through a break in its outline.

    Such a fish stands out from the water only by its outline; where grain or JPEG breaks the
    outline for a few pixels, the body inside is no hole and is not filled (3011 in grain: the
    silhouette 0.51 with the truth; 2701 in JPEG 90: 0.20). A disk of LEAK_CLOSE px seals such a
    break (up to about 10 px of a 5-px outline). A region it seals is fish if it is wider than the
    disk somewhere (a gap the disk merely bridged, between two spines, is not: a review's spiny fish
    over water blotched in hue took 2-21 of its 46 such gaps) and if, LEAK_CLEAR px off the outline,
    its mean colour differs in hue from the water within LEAK_WATER px of it by LEAK_LEVELS: the
    part of the difference that is not the water's own colour made brighter or darker. Water in a
    notch between two fins is the water in shade or light (three.js's mottled water: 6.9 levels
    darker, 2.5 in hue; at most 3.3 in hue over 8 of Blender's sets, as PNG, JPEG 90 and grainy JPEG
    85); a leaked body is another colour (6.2-13 levels in hue). Over water darker than LEAK_DARK,
    lighter and darker have no direction to be told from hue by, and nothing is judged."""
    pad = LEAK_CLOSE + 1
    outside = ndimage.distance_transform_edt(~np.pad(fish, pad))
    grown = outside <= LEAK_CLOSE
    closed = (ndimage.distance_transform_edt(grown) > LEAK_CLOSE)[pad:-pad, pad:-pad]
    sealed = ndimage.binary_fill_holes(closed | fish) & ~fish
    labels, count = ndimage.label(sealed, structure=np.ones((3, 3), bool))
    if count == 0:
        return sealed
    off = outside[pad:-pad, pad:-pad]
    cores = np.bincount(labels[off > LEAK_CLEAR], minlength=count + 1)
    # the water beside a region: off the fish and off every sealed region, past the outline's halo
    water = ~ndimage.binary_dilation(fish | sealed, structure=np.ones((3, 3), bool), iterations=2)
    leaked = np.zeros_like(fish)
    h, w = fish.shape
    reach = LEAK_WATER + 1
    for index, box in enumerate(ndimage.find_objects(labels), start=1):
        if box is None or cores[index] < LEAK_CORE:
            continue
        # each region judged in its own box, LEAK_WATER px round it: a spiny fish seals many
        rows = slice(max(box[0].start - reach, 0), min(box[0].stop + reach, h))
        cols = slice(max(box[1].start - reach, 0), min(box[1].stop + reach, w))
        region = labels[rows, cols] == index
        inside = ndimage.distance_transform_edt(region)
        # a gap the disk merely bridged (between two spines, two fins) is no wider than the disk;
        # a body behind a break is
        if inside.max() <= LEAK_CLOSE:
            continue
        core = region & (off[rows, cols] > LEAK_CLEAR)
        beside = water[rows, cols] & (ndimage.distance_transform_edt(~region) <= LEAK_WATER)
        if not beside.any():
            continue
        water_colour = rgb[rows, cols][beside].mean(axis=0, dtype=np.float64)
        length = float(np.linalg.norm(water_colour))
        if length < LEAK_DARK:   # near black, brighter and darker have no direction to tell them by
            continue
        unit = water_colour / length
        # only the change of hue counts: shade, murk and caustics brighten or darken the water itself
        step = rgb[rows, cols][core].mean(axis=0, dtype=np.float64) - water_colour
        if float(np.linalg.norm(step - (step @ unit) * unit)) >= LEAK_LEVELS:
            leaked[rows, cols] |= region
    return leaked


def pale_patches(photo: Photo, fish: np.ndarray) -> np.ndarray:
    """Patches joined to ``fish`` that may be a translucent fin nearly the water's colour, though
    :func:`translucent_mask` left them out: over a backdrop, pieces at least LOCAL_WIDTH px wide that
    differ from the water around them by PALE_SIGMAS of its spread and PALE_LEVELS, and carry fine
    detail (a fin's rays and edges) PALE_GRAIN times the water's. Murky water's swirls stand as far
    from it (three.js's: 6-12 levels) but are as smooth as the water (1.0-1.5 times its detail);
    Blender's pelvic fin of seed 2007 stood 3-6 levels off, 4 spreads, its rays 10 times the water's
    detail. Their backdrop is taken from SWIRL_CLEAR px off the fish and more, so such a fin is not
    its own backdrop, and their detail PALE_RING px off it and more, past the outline's halo and
    JPEG's colour bleeding. Too unsure to measure the fish by, they tell how far its measure can be
    trusted."""
    if photo.alpha is not None:
        return np.zeros_like(fish)
    img = ndimage.uniform_filter(photo.rgb.astype(np.float32), size=(LOCAL_BOX, LOCAL_BOX, 1))
    local = _local_contrast(img, fish, SWIRL_CLEAR, SWIRL_CLEAR + NEAR_BAND)
    if local is None:
        return np.zeros_like(fish)
    contrast, weight, spread, near = local
    raw = (contrast > max(PALE_SIGMAS * spread, PALE_LEVELS)) & (weight > 0.02) & ~fish
    raw = ndimage.binary_opening(raw, structure=np.ones((LOCAL_WIDTH, LOCAL_WIDTH), bool))
    labels, count = ndimage.label(raw, structure=np.ones((3, 3), bool))
    if count == 0:
        return raw
    index = np.arange(1, count + 1)
    touching = np.isin(index, labels[ndimage.binary_dilation(fish, structure=np.ones((3, 3), bool),
                                                              iterations=2) & raw])
    big = np.bincount(labels.ravel(), minlength=count + 1)[1:] >= LOCAL_PATCH * fish.sum()
    detail = np.sqrt(np.einsum("ijk,ijk->ij", photo.rgb - img, photo.rgb - img))   # what the box smooths
    water = max(float(np.median(detail[near])), PALE_DETAIL)
    # judged off the outline: JPEG rings beside every strong edge, as detail the water lacks
    off = ~ndimage.binary_dilation(fish, structure=np.ones((3, 3), bool), iterations=PALE_RING)
    judged = np.where(off, labels, 0)
    grainy = np.asarray(ndimage.median(detail, judged, index)) >= PALE_GRAIN * water
    return np.isin(labels, index[touching & big & grainy])


def grain(photo: Photo) -> float:
    """How grainy ``photo`` is: the spread (a robust standard deviation, in levels of 0-255) of its
    border's pixels round their 3 x 3 mean, in the strips GRAIN_BORDER of the frame deep where
    the backdrop is. Renders are smooth (Blender's 0.5, three.js's 0.2, JPEG's 0); a camera's
    sensor is not (Blender's photos given grain of 4 levels and saved as JPEG 85: 1.5)."""
    h, w = photo.rgb.shape[:2]
    k = max(2, round(GRAIN_BORDER * min(h, w)))
    rgb = photo.rgb.astype(np.float32)
    residual = rgb - ndimage.uniform_filter(rgb, size=(3, 3, 1))
    strips = [residual[1:k, 1:-1], residual[h - k:-1, 1:-1],          # the filter's own edge left out
              residual[k:h - k, 1:k], residual[k:h - k, w - k:-1]]
    values = np.concatenate([s.reshape(-1) for s in strips])
    return float(1.4826 * np.median(np.abs(values))) if values.size else 0.0


def faint_edges(photo: Photo, fish: np.ndarray) -> np.ndarray:
    """Pixels joined to ``fish`` that may be fish too, though the silhouette left them out: an
    alpha photo's pixels of alpha FAINT_ALPHA and more; over a backdrop, thin runs (at most
    2 x FAINT_HALF_WIDTH px wide) of the unfiltered photo that differ from the backdrop around them
    by FAINT_SIGMAS of its spread: a translucent fin's last tips and the outline's own rim; and
    lines fainter still (TIP_SIGMAS) that run on out from them: a tall fin's tip over water nearly
    its colour. Too unsure to measure the fish by, they tell how far its measure can be trusted."""
    if photo.alpha is not None:
        maybe = photo.alpha >= FAINT_ALPHA
    else:
        local = _local_contrast(photo.rgb.astype(np.float32), fish)
        if local is None:
            return np.zeros_like(fish)
        contrast, weight, spread, _ = local
        maybe = (contrast > max(FAINT_SIGMAS * spread, LOCAL_CONTRAST)) & (weight > 0.02)
    grown = ndimage.binary_propagation(fish, mask=maybe | fish, structure=np.ones((3, 3), bool)) & ~fish
    if photo.alpha is not None:
        return grown
    # a swirl of the backdrop beside the fish is a blob; a fin's tip or rim is a thread
    found = _lines(grown, FAINT_HALF_WIDTH)
    # A tall fin's last tip over water nearly its colour: a line of 3-4 deviations, too faint for
    # the rule above, that runs on from the fish and its faint edges (2411 in Blender: 13 px of
    # the dorsal fin's tip at 3.1-4.1 deviations; without them the box the fit is measured in was
    # 5 % short, 0.945 by the command's figure, 0.846 in Blender). Noise makes no such line that
    # long; JPEG's rings do, but along the outline, not out from it (docs/blender-photos.md).
    known = fish | found
    weak = (contrast > max(TIP_SIGMAS * spread, TIP_CONTRAST)) & (weight > 0.02)
    beyond = ndimage.binary_propagation(known, mask=weak | known, structure=np.ones((3, 3), bool)) & ~known
    away = ndimage.distance_transform_edt(~known)
    return found | _lines(beyond, TIP_HALF_WIDTH, TIP_LENGTH, away, TIP_REACH)


def _lines(pixels: np.ndarray, half_width: float, length: int = 0, away: np.ndarray | None = None,
           reach: float = 0.0) -> np.ndarray:
    """The 8-connected pieces of ``pixels`` no wider than ``2 x half_width``, of ``length`` pixels
    or more, and reaching ``reach`` or more of ``away`` (a distance from the fish) at their end."""
    labels, count = ndimage.label(pixels, structure=np.ones((3, 3), bool))
    if count == 0:
        return pixels
    index = np.arange(1, count + 1)
    keep = np.asarray(ndimage.maximum(ndimage.distance_transform_edt(pixels), labels, index)) <= half_width
    if length:
        keep &= np.asarray(ndimage.sum(pixels, labels, index)) >= length
    if away is not None:
        keep &= np.asarray(ndimage.maximum(away, labels, index)) >= reach
    return np.isin(labels, index[keep])


def _local_contrast(img: np.ndarray, fish: np.ndarray, clear: int = 3, reach: int = NEAR_BAND
                    ) -> tuple[np.ndarray, np.ndarray, float, np.ndarray] | None:
    """How far each pixel of ``img`` is from the backdrop around it: (contrast in 0-255 units, the
    weight of known backdrop near it, the spread of that contrast over the backdrop near the fish,
    where that backdrop is); None when no pixel is surely backdrop. The backdrop is the photo's
    confidently-backdrop pixels (``clear`` px off the fish and more, under 3 border deviations or in
    a swirl: :func:`_swirls`) spread over the gaps by a normalised Gaussian; near the fish is within
    ``reach`` px of it."""
    _, distance = _off_backdrop(img)
    away = ~ndimage.binary_dilation(fish, structure=np.ones((3, 3), bool), iterations=clear)
    known = away & ((distance < 3.0) | _swirls(img, fish, away))
    if not known.any():
        return None
    contrast, weight = _off_smoothed(img, known, LOCAL_SIGMA)
    # the spread is the backdrop's near the fish: JPEG rings round an outline, a flat frame does not
    band = known & ndimage.binary_dilation(fish, structure=np.ones((3, 3), bool), iterations=reach)
    near = band if band.sum() >= 50 else known
    return contrast, weight, float(np.median(contrast[near])) * 1.4826 + 0.5, near


def _swirls(img: np.ndarray, fish: np.ndarray, away: np.ndarray) -> np.ndarray:
    """Backdrop the border's plane does not explain: pixels ``away`` from the fish within
    SWIRL_SIGMAS of the backdrop smoothed over SWIRL_SIGMA px (its spread is theirs). Murky water
    darker or paler than the frame's edge is many border deviations off that plane, so it was no
    known backdrop: a translucent fin inside such a swirl had none near it and was lost, and the
    swirl's edge beside the fish, judged against the paler water beyond, was taken for fin (seed 901
    in Blender: silhouette and faint edges IoU 0.76 with the true coverage, 0.94 so; 605: 0.91, 0.97).
    The smooth backdrop is taken from SWIRL_CLEAR px off the fish and more, so a fin beside the fish
    that the silhouette has not yet found does not pull it towards its own tint (the committed
    seed 303's pelvic fin) and stands out from it."""
    clear = ~ndimage.binary_dilation(fish, structure=np.ones((3, 3), bool), iterations=SWIRL_CLEAR)
    if not clear.any():
        return clear
    off, weight = _off_smoothed(img, clear, SWIRL_SIGMA)
    spread = float(np.median(off[clear])) * 1.4826 + 0.5
    return away & (off < SWIRL_SIGMAS * spread) & (weight > 0.02)


def _off_smoothed(img: np.ndarray, known: np.ndarray, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """(distance, weight): each pixel's colour distance (0-255 units) from the ``known`` pixels
    spread over ``sigma`` px by a normalised Gaussian, and how much known backdrop is near it."""
    weight = ndimage.gaussian_filter(known.astype(np.float32), sigma)
    local = np.stack([ndimage.gaussian_filter(img[..., i] * known, sigma) for i in range(3)], axis=-1)
    diff = img - local / np.maximum(weight, 1e-6)[..., None]
    return np.sqrt(np.einsum("ijk,ijk->ij", diff, diff)), weight


def _off_backdrop(img: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(contrast, distance) of every pixel from the border's planar colour model: the colour
    difference in 0-255 units, and in the border's own standard deviations."""
    h, w = img.shape[:2]
    b = max(2, round(0.02 * min(h, w)))
    border = np.zeros((h, w), bool)
    border[:b], border[-b:], border[:, :b], border[:, -b:] = True, True, True, True
    yy, xx = np.nonzero(border)
    design = np.stack([np.ones(yy.size), xx / w, yy / h], axis=1)
    colours = img[yy, xx].astype(np.float64)
    keep = np.ones(yy.size, bool)
    for _ in range(3):  # drop border pixels the plane cannot explain (a fin tip, a label)
        coef, *_ = np.linalg.lstsq(design[keep], colours[keep], rcond=None)
        resid = colours - design @ coef
        mad = np.median(np.abs(resid[keep]), axis=0) * 1.4826 + 0.5
        keep = (np.abs(resid) <= 4 * mad).all(axis=1)
    c = coef.astype(np.float32)
    gx = (np.arange(w, dtype=np.float32) / w)[None, :, None]
    gy = (np.arange(h, dtype=np.float32) / h)[:, None, None]
    diff = img - (c[0] + gx * c[1] + gy * c[2])      # the photo minus the backdrop it should show
    contrast = np.sqrt(np.einsum("ijk,ijk->ij", diff, diff))
    scaled = diff / mad.astype(np.float32)
    distance = np.sqrt(np.einsum("ijk,ijk->ij", scaled, scaled))
    return contrast, distance


def _mask_file(path: str | os.PathLike, size: tuple[int, int], work: tuple[int, int],
               mirror: bool = False) -> np.ndarray:
    from PIL import Image

    from fishgen.authoring.photo.image import load_photo

    m = load_photo(path, colours=False)
    if m.size != size:
        raise FishgenError(f"expected a mask the size of the photo ({size[0]} x {size[1]}), "
                           f"found {m.size[0]} x {m.size[1]}", path)
    grey = m.rgb.mean(axis=2)
    white = (grey >= 128) if m.alpha is None else (m.alpha >= 128) & (grey >= 128)
    if mirror:   # before any scaling, as the photo was mirrored before its working copy was made
        white = white[:, ::-1]
    if work != size:
        img = Image.fromarray(white.astype(np.uint8) * 255).resize(work, Image.Resampling.BILINEAR)
        white = np.asarray(img) >= 128
    return white


def _one_fish(raw: np.ndarray, photo: Photo, source: str) -> np.ndarray:
    h, w = raw.shape
    clean = ndimage.binary_opening(raw, structure=np.ones((3, 3), bool)) if source != "alpha" else raw
    # Close small gaps so a fin ray or a thin tail lobe stays joined to its fish.
    joined = ndimage.binary_closing(clean, structure=np.ones((5, 5), bool), border_value=0) | clean
    labels, count = ndimage.label(joined, structure=np.ones((3, 3), bool))
    if count == 0:
        raise FishgenError(f"expected a fish in the photo, found none ({_hint(source)})", photo.path)
    sizes = np.bincount(labels.ravel())[1:]
    order = np.argsort(sizes)[::-1]
    if sizes[order[0]] < MIN_FISH_FRACTION * h * w:
        raise FishgenError(f"expected a fish in the photo, found no object larger than "
                           f"{MIN_FISH_FRACTION:.1%} of the frame ({_hint(source)})", photo.path)
    if count > 1 and sizes[order[1]] >= SECOND_OBJECT * sizes[order[0]]:
        many = int((sizes >= SECOND_OBJECT * sizes[order[0]]).sum())
        # over a backdrop, most often one fish: fins that stand out, a body of the water's colour
        # between them (3607 in Blender, refused as 3 objects in PNG and JPEG alike)
        what = (" (several fish, or one whose body is nearly the backdrop's colour and only its fins "
                "stand out)") if source == "background model" else ""
        raise FishgenError(f"expected one fish, found {many} objects of similar size{what}; crop the "
                           "photo to one fish or give --mask", photo.path)
    # The closing decides what belongs together and which holes are holes (a pale eye ring on
    # the outline leaves a gap a few pixels wide); the outline itself is the unclosed one.
    closed = labels == order[0] + 1
    holes = ndimage.binary_fill_holes(closed) & ~closed
    fish = ndimage.binary_fill_holes((clean & closed) | holes)
    if source == "alpha" and photo.alpha is not None:
        fish = _open_holes(holes, clean, fish, photo.alpha)
    if source != "alpha":
        fish = fish | _slivers(raw & ~fish, fish)
    edges = {"top": fish[0].sum(), "bottom": fish[-1].sum(), "left": fish[:, 0].sum(),
             "right": fish[:, -1].sum()}
    cut = [name for name, n in edges.items() if n >= 2]
    if cut:
        raise FishgenError(f"expected the whole fish inside the frame, found it cut off at the "
                           f"{' and '.join(cut)} edge{'s' if len(cut) > 1 else ''}", photo.path)
    return fish


def _open_holes(holes: np.ndarray, clean: np.ndarray, fish: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """``fish`` with the holes an alpha channel shows the backdrop through left open, out to the
    fish's own pixels round them: the gap between a body and a fin that curls back towards it.

    A photo over a backdrop fills every hole, for there a hole is nearly always fish of the water's
    colour (143 of 144 over Blender's water photos, PNG and JPEG), and so does a mask file, whose
    unpainted spots or outline-only drawing are no backdrop (a review's masks: 25 spots of 6 px
    took a fit from 0.933 to 0.742). An alpha channel tells the backdrop from fish: a hole there
    is left open if its alpha averages under FAINT_ALPHA (a fin so translucent that it fell under
    ALPHA_CUTOFF is fish), it is at least OPEN_HOLE of the fish (a transparent eye a background
    remover left, 81 px, turned a review's fit 4 degrees; a spot of 254 px took it from 0.894 to
    0.865), and opening it leaves the fish in one piece (the closing had joined a fin across it).
    The hand-shaped tall fish's caudal lobe closes a hole of 1,582 px (6 %) over its body; filled,
    it set the fit's target 0.92 from the true silhouette."""
    labels, count = ndimage.label(holes, structure=np.ones((3, 3), bool))
    if count == 0:
        return fish
    index = np.arange(1, count + 1)
    backdrop = (np.asarray(ndimage.mean(alpha, labels, index)) < FAINT_ALPHA) & \
        (np.bincount(labels.ravel(), minlength=count + 1)[1:] >= OPEN_HOLE * fish.sum())
    if not backdrop.any():
        return fish
    seeds = np.isin(labels, index[backdrop])
    # the hole as the closing shrank it, grown back over what was not fish before the closing
    grown = ndimage.binary_propagation(seeds, mask=fish & ~clean | seeds, structure=np.ones((3, 3), bool))
    opened = fish & ~grown
    _, pieces = ndimage.label(opened, structure=np.ones((3, 3), bool))
    return opened if pieces == 1 else fish


def _slivers(dropped: np.ndarray, fish: np.ndarray) -> np.ndarray:
    """What the opening took off the fish and belongs to it: runs of ``dropped`` touching ``fish``.
    A fin seen almost edge-on, or the tapering tip of a long fin, is 1-2 px wide, and the opening
    that clears sensor noise clears it too; yet its tip sets the fish's height, which every
    measure normalises by. A speck of noise touching the outline comes back with it, but adds a
    pixel, not a fin."""
    labels, count = ndimage.label(dropped, structure=np.ones((3, 3), bool))
    if count == 0:
        return dropped
    # within two pixels: where a thread leaves its fin the two may blur apart by a pixel
    rim = ndimage.binary_dilation(fish, structure=np.ones((3, 3), bool), iterations=2) & dropped
    touching = np.unique(labels[rim])
    return np.isin(labels, touching[touching > 0])


def _hint(source: str) -> str:
    return {"alpha": "the alpha channel is empty",
            "background model": "nothing stands out from the background; try --mask",
            "mask file": "the mask is black"}[source]
