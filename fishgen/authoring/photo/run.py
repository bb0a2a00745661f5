"""`fishgen texture`: a species file, its texture and fin mask from one side photo of a fish."""
from __future__ import annotations

import contextlib
import io
import os
import tempfile
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import numpy as np

from fishgen.authoring.photo import points as fixel
from fishgen.authoring.photo.anatomy import BodyOutline, body_outline, body_region, calibrate
from fishgen.authoring.photo.frame import Frame, faces_right, fish_frame
from fishgen.authoring.photo.image import (
    FINE_SIDE,
    SMALL_FISH,
    Photo,
    load_photo,
    measuring_side,
    mirror_image,
    working_copy,
)
from fishgen.authoring.photo.sideview import SideView, side_view, with_counts
from fishgen.authoring.photo.silhouette import GRAINY, Silhouette, pale_patches, silhouette
from fishgen.errors import FishgenError, UsageError, cannot
from fishgen.species.model import Species, TexturePoints

#: Largest texture written; a bigger photo is scaled down (texture points are fractions, unchanged).
MAX_TEXTURE_SIDE = 4096
#: Below this silhouette IoU the rebuilt fish does not look like the photographed one: say so.
ADVICE_IOU = 0.85
#: How far this command's half-coverage figure may read above Blender's for one rebuilt fish: on
#: 118 fits of three fresh sets (issue 32, docs/blender-photos.md) it read above by more than this
#: one time in twenty (the 95th percentile, +0.0185; the median gap either way 0.0065, this
#: constant's value until 0.2.17, which let a fish at 0.8596 fall to 0.849 unsaid). A fish that
#: clears ADVICE_IOU at half coverage by less is said to be near the line.
RENDERERS_DIFFER = 0.020
#: A loss this small from joining the pale patches is a few stray pixels, no doubt: the two
#: renderers' median gap either way (the figure RENDERERS_DIFFER held until 0.2.17).
STRAY_PIXELS = 0.006
#: A photo over a backdrop as grainy as a camera's (:data:`.silhouette.GRAINY`) may have lost a fin's
#: thin tips to the grain, from its silhouette and so from the command's own figure: the tallest fin's
#: tip 9-11 px short on Blender's photos given grain (1.5 levels) and JPEG 85, the box the overlap
#: crops to 4 % smaller, and their fits up to 0.10 under the command's figure in Blender.
#: Under ADVICE_IOU + GRAIN_MARGIN such a fit is said to be unsure.
GRAIN_MARGIN = 0.10
#: A JPEG rings round every sharp outline, and the thin fin tips and edges the overlap turns on blur
#: with it: on Blender's water photos saved as JPEG 90 (120 fits, issue 32) the command's own figure
#: read a median 0.021 above Blender's, 0.078 at the 90th percentile, where the same photos as PNG
#: read 0.007 and 0.022. A JPEG's fit under ADVICE_IOU + LOSSY_MARGIN is said to be unsure.
LOSSY_MARGIN = 0.07
#: Said to a JPEG keeping its colour at half size: Blender's water photos in JPEG 90 on seven sets
#: fitted 149 of 168 times at 0.85 saved with full-size colour (4:4:4), 131 with colour at half size
#: (4:2:0, Pillow's and most cameras' default) even redrawn (image.py; 127 before), docs/decisions.md.
HALVED_ADVICE = ", a JPEG saved with its colour at full size (4:4:4)"
#: --focal-length: how far the camera's distance, estimated from the fish's length in the photo
#: (:func:`.compare.camera_distance`), may be off: a turned fish's length is not its side-on one, and
#: another camera framing the rebuilt fish by its own extents stands elsewhere (issue 32: 2-6 % on
#: most Blender photos). A fit that matches from the estimate but not from this share nearer or
#: farther says so.
DISTANCE_UNSURE = 0.05
#: --fit-shape: a fish photographed turned off side-on has no one true level (its nose-to-tail line
#: is foreshortened, its far fins show): when the fit at the measured level matches under TURN_GOOD,
#: it is tried again with the photo turned these degrees further, in order, until one matches that
#: well; a level is kept only when its rebuilt fish matches at least TURN_GAIN better.
TURNS = (4.0, -4.0, 2.0, -2.0)
LEVELS = 2 + len(TURNS)
"""Levels --fit-shape may try: side-on at the measured level, at the second reading of it where
there is one (:func:`.frame.other_level`), then each of TURNS from the better."""
FITS = LEVELS + 1
"""A --fit-shape's steps for a progress bar: each level, then the rebuilt fish measured."""
TURN_GOOD = 0.87
TURN_GAIN = 0.01


@dataclass(frozen=True)
class TextureOptions:
    mask: Path | None = None
    fit_shape: bool = False
    body_sections: int | None = None
    circle_sections: int | None = None
    spacing: str = "projected"
    compare: Path | None = None
    fxl_in: Path | None = None
    fxl_out: Path | None = None
    focal_length: float | None = None   # mm on a 36 mm wide sensor; None: no perspective


@dataclass
class TextureResult:
    species: Species
    written: list[Path]
    angle: float
    mirrored: bool
    source: str
    unseen: list[str] = field(default_factory=list)
    iou: float | None = None    # the rebuilt fish against the photo's (None: no OpenGL to render it)
    level_mask: np.ndarray | None = field(default=None, repr=False)   # the silhouette, head left, level
    frame: Frame | None = field(default=None, repr=False)   # photo -> level_mask
    fitted: bool = False        # --fit-shape's geometry was kept
    fit_problems: list[str] = field(default_factory=list)   # why a fit was refused
    shape_fit: Any = field(default=None, repr=False)   # the fit tried (:class:`.fit.ShapeFit`)
    #: ``iou`` counting only the pixels the rebuilt fish covers at least half, the worst of the
    #: renders tried (None: not measured, as when ``iou`` is already under the line)
    half_covered: float | None = None


@dataclass(frozen=True)
class Measured:
    """Everything measured on the photo, in the photo's own pixels."""
    points: TexturePoints
    frame_mask: np.ndarray
    angle: float
    mirrored: bool
    unseen: tuple[str, ...]
    frame: Frame | None = None


@dataclass(frozen=True)
class Analysis:
    """The photo measured against one species' geometry, in the fish's frame."""
    view: SideView
    frame: Frame
    outline: BodyOutline
    body: np.ndarray                       # (B, C, 2) frame points
    fins: dict[str, fixel.FinResult]


def analyse(mask: np.ndarray, base: Species, spacing: str = "projected", search: float = 1 / 3,
            fit: Any = None, level_by: Species | None = None,
            seen_from: tuple[float, tuple[int, int]] | None = None) -> Analysis:
    """``fit``: a :class:`.fit.ShapeFit` of ``base`` to ``mask``; its frame and placement are used
    rather than measured again, so the points land on the fish where the fit put it. ``level_by``:
    the species whose tail calibrates how the photo is levelled (the base as its file gives it,
    when ``base`` is at another level of detail). ``seen_from``: (camera distance in fish lengths,
    render size) when the photo was taken in perspective (``--focal-length``): a fitted fish's fins
    then take their texture from where its render from there shows them (:func:`.compare.seen_fins`),
    as it was fitted; side-on, a paired fin standing out towards the camera lies elsewhere, and the
    fin mask cut the fin's parts there away (a fin tip, and with it the box the overlap crops to)."""
    view = side_view(base)
    seen: dict[str, np.ndarray] = {}
    if fit is not None:
        from fishgen.authoring.photo.fit import body_outline as fitted_outline

        fr = fit.frame
        outline = fitted_outline(fit, fr.mask.shape[1])
        if seen_from is not None:
            from fishgen.authoring.photo.compare import seen_fins

            seen = seen_fins(base, *seen_from[1], seen_from[0], fr.mask)
    else:
        ys, xs = np.nonzero(mask)
        length = float(max(np.ptp(xs), np.ptp(ys)))
        cal = calibrate(view, length)
        if level_by is not None and level_by is not base:
            # the photo's level is the photo's: at 3 body sections the blocky tail's drop turned a
            # level photo 6 degrees (its fit 0.575 where the file's own sections gave 0.87)
            cal = replace(cal, tail_drop=calibrate(side_view(level_by), length).tail_drop)
        fr = fish_frame(mask, cal.tail_drop)
        outline = body_outline(fr.mask, view, cal)
    body = fixel.body_points(outline, base.body_sections, base.circle_sections, spacing)
    region = body_region(outline, fr.mask.shape)
    fins = {name: fixel.fin_points(name, xy, view.fin_faces[name], outline, view, fr.mask, region, search,
                                   seen.get(name))
            for name, xy in view.fins.items()}
    if fit is not None:
        fins = {name: replace(res, points=_on_fish(res.points, fr.mask)) for name, res in fins.items()}
    return Analysis(view, fr, outline, body, fins)


def _on_fish(points: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Fin points that fall off the photographed fish moved onto its nearest pixel. A fitted fin
    follows the silhouette only as closely as its straight edges can; a tip a few pixels off would
    take backdrop, and the fin mask would cut it away."""
    from scipy import ndimage  # type: ignore[import-untyped]

    h, w = mask.shape
    _, (iy, ix) = ndimage.distance_transform_edt(~mask, return_indices=True)
    c = np.clip(np.floor(points).astype(int), 0, [w - 1, h - 1])
    off = ~mask[c[:, 1], c[:, 0]]
    out = points.copy()
    out[off] = np.stack([ix[c[off, 1], c[off, 0]], iy[c[off, 1], c[off, 0]]], 1) + 0.5
    return out


UV_DECIMALS = 9
"""Decimals a measured texture point keeps."""


def measure(photo: Photo, base: Species, mask: np.ndarray, spacing: str = "projected",
            fit: Any = None, level_by: Species | None = None,
            seen_from: tuple[float, tuple[int, int]] | None = None) -> Measured:
    """Fixel's points for ``base``'s geometry, measured on ``photo`` (where ``fit`` put it; see
    :func:`analyse` for ``seen_from``)."""
    a = analyse(mask, base, spacing, fit=fit, level_by=level_by, seen_from=seen_from)
    size = np.array(photo.size, float)

    def uv(frame_pts: np.ndarray) -> tuple[tuple[float, float], ...]:
        p = np.clip(a.frame.to_photo(frame_pts.reshape(-1, 2)) / size, 0.0, 1.0)
        # to UV_DECIMALS (1e-5 of a pixel of a 10,000-pixel photo): the products go through BLAS,
        # whose kernel follows the CPU, and a last bit of one point changed the species file
        p = np.round(p, UV_DECIMALS)
        return tuple((float(u), float(v)) for u, v in p)

    parts: dict[str, tuple[tuple[float, float], ...]] = {"body": uv(a.body)}
    for name in ("caudal", "dorsal", "adipose", "anal", "pectoral", "pelvic"):
        count = getattr(base, name).texture_point_count
        if name in a.fins:
            parts[name] = uv(a.fins[name].points)
        else:  # an absent fin still has its points in the file
            parts[name] = uv(np.tile(a.body[0, 0], (count, 1)))
    unseen = tuple(name for name, res in a.fins.items() if not res.seen)
    return Measured(TexturePoints(**parts), a.frame.mask, a.frame.angle, a.frame.mirrored, unseen, a.frame)


def texture_bytes(original: Photo, work: Photo, mask: np.ndarray,
                  threads: bool = False) -> tuple[bytes, bytes]:
    """(colour, mask) PNGs stored upside down as VRFish wants them (chapter 6), from the photo at
    up to MAX_TEXTURE_SIDE pixels a side. The background around the fish takes the nearest fish
    colour, so blended fin edges and mipmaps show fish, not the photo's backdrop; the mask keeps
    the true outline. ``mask`` is the silhouette measured on ``work``. With ``threads`` (a fitted
    fish's), a part of the outline under 3 px wide is a pixel wider each side in the mask: a fitted
    fin reaches out along the photo's thread, and a client filtering a 1-px thread (Blender:
    bilinear, clipped at half) reads it under half and trims the fin's tip."""
    from PIL import Image, ImageOps
    from scipy import ndimage

    colour = Image.fromarray(original.rgb, "RGB")
    longest = max(colour.size)
    if longest > MAX_TEXTURE_SIDE:
        k = MAX_TEXTURE_SIDE / longest
        colour = colour.resize((max(1, round(colour.size[0] * k)), max(1, round(colour.size[1] * k))),
                               Image.Resampling.LANCZOS)
    bw = Image.fromarray(mask.astype(np.uint8) * 255, "L")
    if bw.size != colour.size:   # measured on a smaller copy: a smooth edge, not blocks
        bw = bw.resize(colour.size, Image.Resampling.BILINEAR).point(lambda v: 255 if v >= 128 else 0)
    fish = np.asarray(bw) >= 128
    if threads:
        thin = fish & ~ndimage.binary_opening(fish, structure=np.ones((3, 3), bool))
        bw = Image.fromarray((fish | ndimage.binary_dilation(thin)).astype(np.uint8) * 255, "L")
    _, (iy, ix) = ndimage.distance_transform_edt(~fish, return_indices=True)
    colour = Image.fromarray(np.ascontiguousarray(np.asarray(colour)[iy, ix]), "RGB")
    out = []
    for img in (colour, bw):
        buf = io.BytesIO()
        ImageOps.flip(img).save(buf, "PNG", compress_level=6)
        out.append(buf.getvalue())
    return out[0], out[1]


def make_texture(photo_path: str | os.PathLike, base: Species, out: str | os.PathLike,
                 options: TextureOptions = TextureOptions(),
                 on_note: Callable[[str], None] | None = None,
                 progress: Callable[[int], None] | None = None) -> TextureResult:
    """Measure ``photo_path``, write the new species file beside its texture and mask, atomically.
    With ``fit_shape``, ``progress`` gets 1 as each level is fitted or skipped and as the rebuilt
    fish is measured: FITS in all."""
    try:
        return _make_texture(photo_path, base, out, options, on_note, progress)
    except FishgenError as err:
        if err.file is None and not isinstance(err, UsageError):  # about what the photo shows: say which
            raise FishgenError(err.message, photo_path) from None
        raise


def _measured_copy(original: Photo, options: TextureOptions,
                   mirror: bool = False) -> tuple[Photo, Silhouette]:
    """The copy of ``original`` the fish is measured on, and its silhouette (``mirror``: the photo
    is a mirror image, and so is the --mask file made to be)."""
    # At most MEASURE_SIDE pixels a side: a 64-megapixel photo would otherwise need gigabytes, and
    # a full-HD one's fit took twice as long for no better fish.
    photo = working_copy(original, measuring_side(original.size))
    try:
        sil = silhouette(photo, options.mask, original.size, mirror)
        # --body-sections asks for two pixels a section: as many as the larger copy gives
        small = int(sil.mask.any(axis=0).sum()) < max(SMALL_FISH, 2 * (options.body_sections or 0))
    except FishgenError:
        if photo is original:
            raise
        small = True   # said again below, from the larger copy, if it is the photo's fault
    if small and photo is not original:
        photo = working_copy(original, measuring_side(original.size, FINE_SIDE))
        sil = silhouette(photo, options.mask, original.size, mirror)
    return photo, sil


def check_out(out: str | os.PathLike) -> Path:
    """``out`` as the new species file's path, when it names one (.txt)."""
    out = Path(out)
    if out.suffix.lower() != ".txt":
        raise UsageError(f"expected -o to name a species file (.txt), found {out.suffix or 'no extension'!r}",
                         out)
    return out


def _make_texture(photo_path: str | os.PathLike, base: Species, out: str | os.PathLike,
                  options: TextureOptions, on_note: Callable[[str], None] | None,
                  progress: Callable[[int], None] | None = None) -> TextureResult:
    from fishgen.atomic import write_files
    from fishgen.authoring.photo import fxl

    out = check_out(out)
    if options.spacing not in fixel.SPACINGS:
        raise UsageError(f"expected --spacing {'|'.join(fixel.SPACINGS)}, found {options.spacing!r}")
    note = on_note or (lambda _text: None)
    original = load_photo(photo_path)
    photo, sil = _measured_copy(original, options)
    # A fish facing right is measured on the photo's mirror image from here on, so it gives the
    # files that image gives, texture and all (the texture then faces left, as every species' does).
    flipped = faces_right(sil.mask)
    if flipped:
        original = mirror_image(original)
        photo, sil = _measured_copy(original, options, mirror=True)
    span = int(sil.mask.any(axis=0).sum())  # the fish's length in the working copy's pixels
    if options.body_sections is not None and options.body_sections > max(3, span // 2):
        # more sections than the photo has pixels measures nothing, and --fit-shape took 31 s at 256
        w, h = photo.size
        where = "the photo" if photo is original else f"the {w} x {h} copy it is measured on"
        raise FishgenError(f"expected --body-sections of at most {max(3, span // 2)} for a fish {span} px "
                           f"long in {where} (two pixels a section), found {options.body_sections}",
                           photo_path)
    given = base
    base = with_counts(base, options.body_sections, options.circle_sections)
    imported = fxl.read_fxl(options.fxl_in) if options.fxl_in is not None else {}
    if flipped:   # points on the photo, as the texture is the photo's mirror image
        imported = {part: list(_mirrored_uv(values)) for part, values in imported.items()}
    textures = texture_bytes(original, photo, sil.mask)
    distance = None   # from the camera, in fish lengths: the perspective the rebuilt fish is seen in
    if options.focal_length is None and original.lens_35mm is not None:
        # not taken on trust: a cropped photo keeps its camera's figure, and the fit would be
        # measured in another perspective than the crop's
        exif = f"{original.lens_35mm:g}"
        note(f"the photo's EXIF gives a {exif} mm lens (as on 35 mm film): give --focal-length {exif} to "
             "measure the fish in that perspective, unless the photo was cropped")
    if options.focal_length is not None:
        from fishgen.authoring.photo.compare import camera_distance

        distance = camera_distance(options.focal_length, photo.size[0], sil.mask)
    # Pixels that may be fish though the silhouette left them out (a mask file is the truth):
    # found once, for the fit's target and for the second measure of the rebuilt fish.
    faint = None
    if options.mask is None:
        from fishgen.authoring.photo.silhouette import faint_edges

        faint = faint_edges(photo, sil.mask)
    chosen = _candidate(photo, sil.mask, base, out, options, imported, textures, level_by=given)
    shown: tuple[np.ndarray, float] | None = None   # the chosen fish rendered, and its IoU
    target_faint = None   # the faint edges the fit took as fish (over a backdrop)
    fitted, problems, fit = False, [], None
    step = progress if progress is not None and options.fit_shape else (lambda _n: None)
    if options.fit_shape:
        from fishgen.authoring.photo.checks import fit_problems
        from fishgen.authoring.photo.compare import render_scale
        from fishgen.authoring.photo.fit import fit_species, settled_in_perspective, settled_tips
        from fishgen.authoring.photo.frame import fish_frame, other_level

        tried: tuple[np.ndarray, float] | None = None
        as_it_stands = False   # the kept fit levels the fish as it stands (frame.other_level)
        chosen_fit: tuple[_Candidate, Any] | None = None
        # Over a backdrop the silhouette loses a translucent fin's last tips, and the fish fitted
        # without them was 0.85 in Blender where the command's own measure said 0.93: the fit
        # takes the faint edges too (an alpha channel keeps the tips; a mask file is the truth).
        target = sil.mask | faint if sil.source == "background model" and faint is not None else sil.mask
        target_faint = faint if target is not sil.mask else None
        # Told the lens, a fitted fin takes its texture where the render from there shows it
        # (compare.seen_fins), out to the faint edges it was fitted to; a mask texture cut from the
        # bare silhouette is transparent there and trims the tip (703 on BonyBream in Blender: 0.885
        # -> 0.777; its points moved onto the bare silhouette: 0.838, the tip's 1 px thread too thin
        # to hold). So that fit's mask is cut from its own target. Without the lens it stays bare:
        # three.js's water fits lost up to 0.03 with faint edges (docs/blender-photos.md).
        # A fitted fin reaches out along the photo's 1-px threads: its mask keeps them (threads=True).
        seen = target if distance is not None and target is not sil.mask else sil.mask
        seen_textures = texture_bytes(original, photo, seen, threads=True)
        # A second reading of the fish's level (tall fins' axis against its line as it stands:
        # frame.other_level) is always fitted too, as the silhouette cannot tell which is right;
        # the TURNS then turn the better of the two.
        first = fish_frame(target)
        second = other_level(target, first)
        best_level = first    # the level the kept fit was made at
        for k, turn in enumerate((0.0, 0.0, *TURNS)):
            if k > 1 and tried is not None and tried[1] >= TURN_GOOD:
                step(LEVELS - k + 1)  # the level just fitted, and those left unneeded
                break
            if k:
                step(1)           # the level before
            if k == 1 and second is None:
                continue          # no second reading of the fish's level
            level = second if k == 1 and second is not None else best_level
            attempt = fit_species(base, target, sections_fixed=options.body_sections is not None, turn=turn,
                                  level=level)
            attempt = settled_tips(attempt, render_scale(attempt.species, *_render_size(photo)))
            if distance is not None:
                attempt = settled_in_perspective(attempt, distance, _render_size(photo))
            found = fit_problems(attempt.species, attempt.work, attempt.placement)
            if k == 0:
                fit, problems = attempt, found
            if found:
                continue
            candidate = _candidate(photo, sil.mask, attempt.species, out, options, imported,
                                   seen_textures, attempt, distance=distance)
            rendered = _rendered(photo, candidate, out, distance)
            # another level is kept only for a clear gain: the renders differ by a little anyway
            if tried is None or rendered[1] >= tried[1] + TURN_GAIN:
                tried, chosen_fit, fit, problems = rendered, (candidate, attempt), attempt, []
                best_level = level if turn == 0.0 else best_level
                as_it_stands = level is second
        else:
            step(1)
        if chosen_fit is None:
            # A broken fish is never written: the base's geometry stays, and the command says why.
            note(f"fitted shape not kept: {problems[0]}")
        else:
            candidate, kept = chosen_fit
            assert tried is not None
            # Keep the fit only if the rebuilt fish matches the photo better than the base's geometry.
            shown = _rendered(photo, chosen, out, distance)
            iou_base, iou_fit = shown[1], tried[1]
            if iou_fit >= iou_base:
                note(f"fitted shape: silhouette IoU {iou_base:.3f} with the base's geometry -> {iou_fit:.3f}")
                if kept.turn:
                    note(f"note: the photographed fish is taken as turned {kept.turn:+.0f} degrees from "
                         "its nose-to-tail line (it is not side-on): that level matched best")
                if as_it_stands:
                    note("note: the fish is levelled by its nose-to-tail line as the photo stands "
                         f"({kept.frame.angle:+.0f} degrees), not by its fins' long axis "
                         f"({first.angle:+.0f}): that level matched best")
                for line in kept.notes:
                    note(f"note: {line}")
                chosen, shown, fitted = candidate, tried, True
            else:
                note(f"fitted shape not kept: silhouette IoU {iou_fit:.3f}, the base's geometry gives "
                     f"{iou_base:.3f}")
    for name in chosen.unseen:
        note(f"note: no {name} fin found in the photo; its texture is body skin near its attachment")
    if shown is None:
        try:
            shown = _rendered(photo, chosen, out, distance)
        except FishgenError:   # no OpenGL here: nothing to measure the rebuilt fish with
            shown = None
    unsure = None   # the rebuilt fish against the photo's outline with its faint edges
    if shown is not None and shown[1] >= ADVICE_IOU and faint is not None and faint.any() \
            and chosen.measured.frame is not None:
        unsure = _iou_with(chosen, sil.mask | faint, shown[0])
    faded = None    # the rebuilt fish counting only the pixels it covers at least half
    if shown is not None and shown[1] >= ADVICE_IOU and (unsure is None or unsure >= ADVICE_IOU):
        from fishgen.authoring.photo.compare import HALF_ALPHA, silhouette_iou

        # at half coverage by the multisampled render, and by one that alpha-tests every sample
        # (compare.half_covered_grids) at two grids of samples: the worst, since any of them may be
        # another renderer's (1502 on BonyBream: 0.882, 0.846; Blender 0.847)
        faded = min(silhouette_iou(chosen.measured.frame_mask, shown[0][:, :, 3] >= HALF_ALPHA),
                    *_half_covered_ious(photo, chosen, out, distance))
    # Fitted to the silhouette with its faint edges, the rebuilt fish is measured against them too;
    # against the bare silhouette it may score less (the faint pixels may not be fish), and counted
    # at half coverage less again, and against it with the pale patches joined to it
    # (silhouette.pale_patches: a translucent fin nearly the water's colour) less again. The faint
    # edges and half coverage are each said when they alone fall under the line; all the doubts at
    # once take their losses together, and the line names those that lose something (605
    # in Blender, a grey-blue fish over grey-blue water: 0.894 by its own figure, 0.857 bare, 0.874 at
    # half coverage, 0.840 in Blender; 2007 on BonyBream, a pale pelvic fin lost: 0.925, 0.877 bare,
    # 0.921 at half, 0.877 with the patches, 0.825 all together, 0.805 in Blender).
    doubt = None    # (IoU with every doubt taken, the bare silhouette's, at half coverage, with patches)
    if shown is not None and faded is not None and fitted and target_faint is not None:
        bare = _iou_with(chosen, sil.mask, shown[0])
        pale = pale_patches(photo, sil.mask | target_faint)
        paled = _iou_with(chosen, sil.mask | target_faint | pale, shown[0]) if pale.any() else shown[1]
        paled = paled if paled < shown[1] - STRAY_PIXELS else shown[1]
        doubt = (faded + bare + paled - 2 * shown[1], bare, faded, paled)
    apart = None    # (share, IoU): the rebuilt fish seen from another distance, the worse of two
    if shown is not None and distance is not None and faded is not None \
            and faded >= ADVICE_IOU + RENDERERS_DIFFER and (doubt is None or doubt[0] >= ADVICE_IOU):
        apart = min(((k, _rendered(photo, chosen, out, distance * (1 + k))[1])
                     for k in (-DISTANCE_UNSURE, DISTANCE_UNSURE)), key=lambda v: v[1])
    step(1)    # the bar's last step: the rebuilt fish measured (the slowest render of a fit)
    if shown is not None and unsure is not None and unsure < ADVICE_IOU:
        note(f"silhouette IoU {shown[1]:.3f}, but {unsure:.3f} if the faint pixels round the photo's "
             "outline are fish (thin translucent fin tips over the backdrop): the rebuilt fish may be "
             "unlike the photographed one; give --mask to be sure")
    elif shown is not None and faded is not None and faded < ADVICE_IOU + RENDERERS_DIFFER:
        near = faded >= ADVICE_IOU   # then four places: 0.8557 is near the line and reads so
        margin = (f", within {RENDERERS_DIFFER} of {ADVICE_IOU} (two renderers' figures can differ by "
                  "as much)" if near else "")
        note(f"silhouette IoU {shown[1]:.3f}, but {faded:.{4 if near else 3}f} counting only the pixels the "
             f"rebuilt fish covers at least half (thin or translucent fin parts fade out there){margin}: it "
             "may look unlike the photographed fish in another renderer; see --compare")
    elif shown is not None and doubt is not None and doubt[0] < ADVICE_IOU:
        note(f"silhouette IoU {shown[1]:.3f}, but {_doubts_said(shown[1], *doubt)}: the rebuilt fish may be "
             "unlike the photographed one; give --mask to be sure")
    elif shown is not None and apart is not None and apart[1] < ADVICE_IOU:
        note(f"silhouette IoU {shown[1]:.3f}, but {apart[1]:.3f} seen from {abs(apart[0]):.0%} "
             f"{'nearer' if apart[0] < 0 else 'farther'} (the camera's distance is estimated from the "
             "fish's length in the photo): it may look unlike the photographed fish; see --compare")
    elif shown is not None and shown[1] < ADVICE_IOU:
        # a photo in perspective (fishgen preview's own side view is a 50 mm one) reads as a misfit
        # side-on: BonyBream on its own geometry 0.875, 0.976 told the lens
        lens = ("" if options.focal_length is not None else
                "; if it was taken close up, give --focal-length (fishgen preview draws at about 50 mm, "
                "or none with --ortho)")
        note(_misfit_said(shown[1], traced=sil.source == "alpha" or options.mask is not None,
                          fit_shape=options.fit_shape, greyscale=_greyscale(photo), lens=lens))
    elif shown is not None and sil.source == "background model" and shown[1] < ADVICE_IOU + GRAIN_MARGIN \
            and sil.grain is not None and (grainy := sil.grain) >= GRAINY:
        note(f"silhouette IoU {shown[1]:.3f}, but the photo is grainy ({grainy:.1f} levels on its border): a "
             "fin's thin tips may be lost in the grain, from its outline and from this figure alike, and "
             "the rebuilt fish may look unlike the photographed one; give --mask to be sure")
    elif shown is not None and sil.source == "background model" and photo.lossy \
            and shown[1] < ADVICE_IOU + LOSSY_MARGIN:
        note(f"silhouette IoU {shown[1]:.3f}, but the photo is a JPEG, whose ringing blurs the thin fin tips "
             f"and edges this figure turns on (on JPEG photos it read over {LOSSY_MARGIN:.2f} above another "
             "renderer's for one fit in ten): the rebuilt fish may look unlike the photographed one; give a "
             f"PNG{HALVED_ADVICE if photo.colour_halved else ''} or --mask to be sure")
    files = dict(chosen.files)
    if options.fxl_out is not None:
        tp = chosen.species.texture_points
        assert tp is not None
        if flipped:   # on the photo, as --fxl-in reads them
            tp = TexturePoints(**{f.name: _mirrored_uv(getattr(tp, f.name)) for f in fields(tp)})
        files[Path(options.fxl_out)] = fxl.format_fxl(tp, chosen.species.circle_sections).encode()
    if options.compare is not None:
        if shown is None:
            shown = _rendered(photo, chosen, out, distance)
        files[Path(options.compare)], _ = _compare_png(photo, *shown, mirrored=flipped)
    write_files(files)
    frame = chosen.measured.frame
    assert frame is not None   # measure() always has one
    if flipped:
        frame = frame.of_mirror(photo.size[0])
    return TextureResult(chosen.species, list(files), frame.angle, frame.mirrored, sil.source,
                         list(chosen.unseen), None if shown is None else shown[1],
                         chosen.measured.frame_mask, frame, fitted, problems, fit, faded)


def _mirrored_uv(points: Iterable[tuple[float, float]]) -> tuple[tuple[float, float], ...]:
    """Texture points on a photo as on its mirror image, and back."""
    return tuple((round(1.0 - u, UV_DECIMALS), v) for u, v in points)


def _greyscale(photo: Photo) -> bool:
    """Whether every pixel of ``photo`` is grey (its three channels within one level)."""
    rgb = photo.rgb.astype(np.int16)
    return bool(np.abs(rgb[..., 0] - rgb[..., 1]).max() <= 1 and np.abs(rgb[..., 1] - rgb[..., 2]).max() <= 1)


@dataclass(frozen=True)
class _Candidate:
    species: Species
    files: dict[Path, bytes]
    measured: Measured

    @property
    def unseen(self) -> tuple[str, ...]:
        return self.measured.unseen


def _candidate(photo: Photo, mask: np.ndarray, base: Species, out: Path, options: TextureOptions,
               imported: dict[str, list[tuple[float, float]]], textures: tuple[bytes, bytes],
               fit: Any = None, level_by: Species | None = None,
               distance: float | None = None) -> _Candidate:
    """The species file (and its texture files) ``base``'s geometry gives with this photo (seen from
    ``distance`` fish lengths, when the lens is known)."""
    from fishgen.species.parser import parse_species
    from fishgen.species.writer import format_species

    seen_from = None if fit is None or distance is None else (distance, _render_size(photo))
    measured = measure(photo, base, mask, options.spacing, fit, level_by, seen_from)
    pts = measured.points
    for part, values in imported.items():
        want = len(getattr(pts, part))
        if len(values) != want:
            raise FishgenError(f"expected {want} //{part} points for {base.name}'s geometry, found "
                               f"{len(values)}", options.fxl_in)
        pts = replace(pts, **{part: tuple(values)})
    measured = replace(measured, unseen=tuple(n for n in measured.unseen if n not in imported))
    from fishgen.authoring.species_files import species_name, texture_names
    from fishgen.file_names import name_text

    name = species_name(out)
    names = texture_names(out)   # NEW.png and NEW_mask.png, unless a species file cannot name them
    colour_name, mask_name = names.colour, names.mask
    # A fitted fin's straight edges only approach the photographed fin; its mask carries the
    # outline. A base whose fins blend instead (Centroberyx: alpha 0.6) fades a fitted fin's thin
    # parts out of every other renderer's coverage, and its texture already holds the photo's own
    # translucency: a fitted fish's fins are cut by its mask.
    masked = base.masked or fit is not None
    species = replace(base, name=name, textured=True, masked=masked, texture_points=pts,
                      colour_texture=None, mask_texture=None, source=None)
    text = format_species(species, name_text(colour_name), name_text(mask_name))
    parse_species(text, out)   # what we write must read back (section ranges, counts)
    files = {out: text.encode(), out.with_name(colour_name): textures[0],
             out.with_name(mask_name): textures[1]}
    return _Candidate(species, files, measured)


def _rendered(photo: Photo, candidate: _Candidate, out: Path,
              distance: float | None = None) -> tuple[np.ndarray, float]:
    """The candidate rebuilt from its files and rendered side-on at about the photo's size (from
    ``distance`` fish lengths, in perspective, when the lens is known), and its silhouette IoU with
    the photo's fish (head left, level)."""
    from fishgen.authoring.photo.compare import DRAWN_ALPHA, render_side, silhouette_iou

    with _rebuilt(candidate, out) as rebuilt:
        render = render_side(rebuilt, *_render_size(photo), distance)
    return render, silhouette_iou(candidate.measured.frame_mask, render[:, :, 3] >= DRAWN_ALPHA)


@contextlib.contextmanager
def _rebuilt(candidate: _Candidate, out: Path) -> Iterator[Species]:
    """The candidate's species as its written files give it, read back from a scratch folder that
    lasts while it is used (its textures are read from there when it is built), so what is
    measured is what a user's renderer will load."""
    from fishgen.species.parser import load_species

    with tempfile.TemporaryDirectory(prefix="fishgen-texture-") as tmp:
        for path, data in candidate.files.items():
            try:
                (Path(tmp) / path.name).write_bytes(data)
            except OSError as err:  # a full scratch disk: say which output it was for, and where
                raise cannot(f"check {path} in the scratch folder", tmp, err) from None
        yield load_species(Path(tmp) / out.name)


def _half_covered_ious(photo: Photo, candidate: _Candidate, out: Path,
                       distance: float | None = None) -> list[float]:
    """The candidate rebuilt from its files, counted where it covers a pixel at least half with
    every sample alpha-tested (:func:`.compare.half_covered_grids`) at each of
    :data:`.compare.SAMPLE_GRIDS`, and its silhouette IoU with the photo's fish at each."""
    from fishgen.authoring.photo.compare import SAMPLE_GRIDS, half_covered_grids, silhouette_iou

    with _rebuilt(candidate, out) as rebuilt:
        return [silhouette_iou(candidate.measured.frame_mask, covered)
                for covered in half_covered_grids(rebuilt, *_render_size(photo), distance, SAMPLE_GRIDS)]


def _misfit_said(iou: float, *, traced: bool, fit_shape: bool, greyscale: bool, lens: str) -> str:
    """The line for a rebuilt fish whose silhouette IoU is under the target, with what to try: the
    silhouette (unless the photo's alpha or a --mask ``traced`` it), else the base."""
    if not traced and greyscale:
        # the base is seldom to blame: a grey head beside grey water is lost to the backdrop
        return (f"silhouette IoU {iou:.3f}: a greyscale photo, whose fish is told from the backdrop by "
                f"brightness alone, so its silhouette may be wrong; give --mask{lens}")
    if not fit_shape:
        return (f"silhouette IoU {iou:.3f}: the base's geometry does not match the photographed fish; "
                f"try --fit-shape{lens}")
    if traced:
        # over alpha the Blender misses were one base of four (2610 on Centroberyx, 902 on ThreadfinGoldie)
        return (f"silhouette IoU {iou:.3f}: the rebuilt fish is still unlike the photo's; another base "
                f"(--species) may take its shape{lens}")
    # most misses over a backdrop are fish near its colour (Blender 2601, blue on blue: the
    # silhouette 0.81 with the truth); few are busy backgrounds
    return (f"silhouette IoU {iou:.3f}: the rebuilt fish is still unlike the photo's; if the silhouette "
            f"is wrong (a fish near the backdrop's colour, or a busy background), give --mask{lens}")


def _doubts_said(iou: float, together: float, bare: float, faded: float, paled: float) -> str:
    """The doubts that lose something against ``iou``, each with its figure, and with two or more,
    their losses ``together``: what follows "but" in the command's line."""
    said = [f"{v:.3f} {what}" for v, what in (
        (bare, "without the faint pixels round the photo's outline"),
        (faded, "counting only the pixels the rebuilt fish covers at least half"),
        (paled, "if the pale patches joined to the photo's outline are fish")) if v < iou]
    listed = said[0] if len(said) == 1 else ", ".join(said[:-1]) + " and " + said[-1]
    if len(said) > 1:
        listed += f", {together:.3f} with {'both' if len(said) == 2 else 'all three'}"
    return listed + (" (a fish or a translucent fin near the backdrop's colour)" if paled < iou else
                     " (a fish near the backdrop's colour)")


def _iou_with(candidate: _Candidate, mask: np.ndarray, render: np.ndarray) -> float:
    """The rendered fish's silhouette IoU with ``mask``, another mask of the photo (its outline with
    the faint edges, say: a lost fin tip sets the box the IoU crops to, so a fish fitted without it
    can match the silhouette well and the photographed fish not), levelled as the fish is."""
    from fishgen.authoring.photo.compare import DRAWN_ALPHA, silhouette_iou

    assert candidate.measured.frame is not None
    return silhouette_iou(candidate.measured.frame.level(mask), render[:, :, 3] >= DRAWN_ALPHA)


def _render_size(photo: Photo) -> tuple[int, int]:
    """(width, height) the rebuilt fish is rendered at to measure it: the photo's, at most 1024 px."""
    w, h = photo.size
    k = min(1.0, 1024 / max(w, h))
    return max(64, round(w * k)), max(64, round(h * k))


def _compare_png(photo: Photo, render: np.ndarray, iou: float, mirrored: bool = False) -> tuple[bytes, float]:
    from PIL import Image

    from fishgen.authoring.photo.compare import compare_image

    rh, rw = render.shape[:2]
    opaque = np.full(photo.rgb.shape[:2], 255, np.uint8)
    rgba = np.dstack([photo.rgb, opaque if photo.alpha is None else photo.alpha])
    small = np.asarray(Image.fromarray(rgba, "RGBA").resize((rw, rh), Image.Resampling.LANCZOS))
    sheet = compare_image(small, render, f"fishgen texture: rebuilt (silhouette IoU {iou:.3f})",
                          "photo, mirrored" if mirrored else "photo")
    buf = io.BytesIO()
    sheet.save(buf, "PNG")
    return buf.getvalue(), iou
