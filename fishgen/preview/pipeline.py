"""From inputs and options to finished images: stills, contact sheets and loops.

The CLI is a thin layer over ``preview`` here; tests and docs/make_renders.py
call it too.
"""
from __future__ import annotations

import io
import math
import os
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from fishgen.errors import FishgenError, UsageError
from fishgen.preview.camera import VIEWS, Camera, frame, turned
from fishgen.scene.model import Scene

if TYPE_CHECKING:
    from fishgen.clouds.lighting import Lighting

OUTPUTS = (".png", ".webp", ".gif", ".jpg", ".jpeg")
ANIMATED = (".gif", ".webp")
LOOP_FPS = 12.0
"""Frames per second of an animated .gif/.webp: fast enough that fins and bodies read as motion."""
LOOP_SECONDS = 4.0
"""A loop's default length: the whole clip when shorter, else its first 4 s (fishgen fish loop
seamlessly within that in practice; --duration picks another); one turn of a static asset's turntable."""
MAX_LOOP_SECONDS = 600.0
"""Longest --duration: GIF frames can last at most 655.35 s."""
MAX_PIXELS = 8192
"""Largest side of one render (--size)."""
MAX_FRAMES = 1000
MAX_TOTAL_PIXELS = 1 << 30
"""All pixels one preview holds at once: every render (inputs x frames x W x H) plus every
contact-sheet frame; 2^30 pixels is 4 GiB as RGBA. Checked before anything is loaded or drawn."""
MAX_SHEET_PIXELS = 1 << 28
"""One contact-sheet frame (W x H of the whole sheet, label strips included): 1 GiB as RGBA."""


@dataclass
class PreviewOptions:
    view: str = "three-quarter"
    width: int = 800
    height: int = 600
    time: float | None = None          # seconds into the clip; None: a school's warm-up, else rest pose
    background: tuple[int, int, int, int] = (140, 173, 204, 255)  # sRGB 0-255, a=0 transparent
    frames: int | None = None         # None: duration x fps for a loop, 1 for a still
    fps: float = LOOP_FPS
    duration: float | None = None      # None: LOOP_SECONDS, or the clip's length if shorter
    columns: int | None = None
    clip: str | None = None
    seed: int = 0
    textures_dir: str | os.PathLike | None = None
    ortho: bool = False                # orthographic camera (no perspective)
    lighting: Lighting | None = None   # the sun cube files are lit by (None: the default sun)


def parse_size(text: str) -> tuple[int, int]:
    """``"800x600"`` -> (800, 600)."""
    m = re.fullmatch(r"\s*(\d+)\s*[xX×]\s*(\d+)\s*", text)
    if not m or not (16 <= int(m[1]) <= MAX_PIXELS and 16 <= int(m[2]) <= MAX_PIXELS):
        raise FishgenError(f"expected --size WxH with 16 to {MAX_PIXELS} pixels a side, found {text!r}")
    return int(m[1]), int(m[2])


def parse_background(text: str) -> tuple[int, int, int, int]:
    """A CSS colour (``#8cadcc``, ``#rrggbbaa``, ``white``) or ``transparent``."""
    import click

    from fishgen.options import Colour

    try:
        return Colour().convert(text, None, None)
    except click.BadParameter:
        raise UsageError(f"expected --background as a colour (#8cadcc, white) or transparent, "
                           f"found {text!r}") from None


def check_output(out: Path, options: PreviewOptions, inputs: int = 1, particles: bool = False) -> int:
    """Validate the output name against the options; returns the number of frames to render.
    ``particles``: an input may hold particles (anything but a species file), which are blended
    in finer colour (:class:`~fishgen.preview.render.Renderer`).

    Also refuses, before anything is allocated, a request whose contact sheet
    would exceed ``MAX_SHEET_PIXELS`` or whose frames and sheets for ``inputs``
    inputs would together exceed ``MAX_TOTAL_PIXELS``.
    """
    ext = out.suffix.lower()
    if ext not in OUTPUTS:
        raise UsageError(f"expected an output ending in {', '.join(OUTPUTS)}, "
                         f"found {out.suffix or 'no extension'!r}", out)
    frames = options.frames
    if frames is not None and not 1 <= frames <= MAX_FRAMES:
        raise UsageError(f"expected --frames from 1 to {MAX_FRAMES}, found {frames}")
    if frames is None:  # the most a loop can have: the pixel budget is checked before loading
        frames = (max(2, math.ceil((options.duration or LOOP_SECONDS) * options.fps))
                  if ext == ".gif" else 1)
    if frames > MAX_FRAMES:
        raise UsageError(f"expected at most {MAX_FRAMES} frames, found {frames} "
                           f"(--duration x --fps); use a shorter --duration or a lower --fps")
    if frames > 1 and ext not in ANIMATED:
        raise UsageError(f"expected a .gif or .webp output for --frames {frames}, found {out.suffix!r}", out)
    if options.view not in VIEWS:
        raise UsageError(f"expected --view {'|'.join(VIEWS)}, found {options.view!r}")
    if ext in (".gif", ".jpg", ".jpeg") and options.background[3] < 255:
        raise UsageError(f"expected an opaque --background for {ext} (it has no alpha channel), "
                           "found transparent")
    if inputs > 1:
        w, h = sheet_size(options, inputs)
        if w * h > MAX_SHEET_PIXELS:
            raise UsageError(f"expected a contact sheet of at most {MAX_SHEET_PIXELS} pixels (2^28), "
                               f"found {w}x{h} = {w * h} for {inputs} inputs at {options.width}x"
                               f"{options.height}; use a smaller --size or fewer --columns")
    total = total_pixels(options, frames, inputs)
    if total > MAX_TOTAL_PIXELS:
        raise UsageError(f"expected at most {MAX_TOTAL_PIXELS} pixels (2^30) in all frames and "
                           f"contact sheets, found {total} for {inputs} input(s) x {frames} frame(s) "
                           f"at {options.width}x{options.height}; use a smaller --size or fewer --frames")
    from fishgen.preview.memory import check_fits

    check_fits(options.width, options.height, total if frames > 1 or inputs > 1 else 0, fine=particles)
    return frames


def sheet_size(options: PreviewOptions, inputs: int) -> tuple[int, int]:
    """Pixel size of one contact-sheet frame for ``inputs`` tiles, as ``contact_sheet`` lays it out."""
    from fishgen.preview.sheet import grid, label_height

    columns, rows = grid(inputs, options.columns)
    return columns * options.width, rows * (options.height + label_height(options.height))


def total_pixels(options: PreviewOptions, frames: int, inputs: int = 1) -> int:
    """Pixels held at once: every render of every input, plus each contact-sheet frame."""
    per_frame = inputs * options.width * options.height
    if inputs > 1:
        w, h = sheet_size(options, inputs)
        per_frame += w * h
    return frames * per_frame


def subject_points(scene: Scene, times: Sequence[float | None],
                   clip: str | None) -> tuple[np.ndarray, np.ndarray]:
    """Every vertex and particle centre the camera must keep in frame, at each of ``times``, and how
    far each reaches round it: (points (N, 3), reach (N,)), a particle's world radius, else 0."""
    from fishgen.preview.posing import poser_for
    from fishgen.preview.render import particles

    poser = poser_for(scene, clip)
    points = [(node, prim) for node, prim in scene.drawn() if prim.mode == "POINTS"]
    out, reach = [], []
    for t in times:
        posed, worlds = poser.frame(t, keep=True)  # the renderer draws these same vertices
        for node, prim in points:
            c, r, _ = particles(scene, node, prim, posed)
            out.append(c)
            reach.append(r)
        out += [pos for pos, _ in worlds]
        reach += [np.zeros(len(pos)) for pos, _ in worlds]
    if not out:
        return np.zeros((1, 3)), np.zeros(1)
    return np.concatenate(out), np.concatenate(reach)


def _check_framed(camera: Camera, scene: Scene) -> None:
    """The renderer's matrices are float32: a scene whose camera stands past its range (a cloud
    3e38 across) would draw from infinities, and one too small for float32 at its distance from
    the origin (1e-8 across at 1,1,1: the eye and the target one float) from nothing; each is
    refused, not drawn as noise or a blank picture."""
    reach = float(np.abs(camera.eye).max()) + camera.far
    if not reach < 1e30:
        raise FishgenError(f"expected a scene a float32 camera can frame (within 1e30 of the origin), found "
                           f"one whose camera stands {reach:.3g} away", scene.source or scene.name)
    away = float(np.linalg.norm(camera.eye - camera.target))
    where = float(np.abs(camera.target).max())
    if away < 4 * float(np.finfo(np.float32).eps) * where:
        raise FishgenError(f"expected a scene large enough for a float32 camera at its distance from the "
                           f"origin, found the camera {away:.3g} from a scene {where:.3g} from the origin",
                           scene.source or scene.name)


def frame_scene(scene: Scene, view: str, aspect: float, times: Sequence[float | None] = (None,),
                clip: str | None = None, *, azimuths: tuple[float, ...] = (0.0,),
                ortho: bool = False) -> Camera:
    """A camera on ``view`` that keeps all of ``scene`` in frame at each of ``times``, particles'
    quads whole (:func:`subject_points`, :func:`fishgen.preview.camera.frame`)."""
    points, reach = subject_points(scene, times, clip)
    return frame(points, view, aspect, azimuths=azimuths, ortho=ortho, reach=reach)


def start_time(scene: Scene, options: PreviewOptions) -> float | None:
    """When a still is posed and a loop starts: ``--time``, else the end of a school file's warm-up
    (its fish start facing every way), else None (a still's rest pose, a loop's 0 s)."""
    if options.time is not None:
        return options.time
    if not scene.extras:
        return None
    from fishgen.school.run import school_extras

    record = school_extras(scene)
    clip = scene.clip(options.clip)
    if record is None or clip is None:
        return None
    return min(float(record["warmup"]), clip.duration)


def _frame_plan(scene: Scene, options: PreviewOptions, frames: int):
    """(times, azimuths, seconds per frame) for one scene.

    A loop samples ``duration`` seconds of the clip at ``fps`` (or spreads
    ``--frames`` over it) from ``start_time``; a static scene turns once in that time.
    """
    clip = scene.clip(options.clip)
    time = start_time(scene, options)
    start = time or 0.0
    if frames == 1:
        return [time], [0.0], 0.0
    length = clip.duration if clip is not None else 0.0  # a property that reads every channel
    animated = length > 0
    duration = options.duration or (min(length, LOOP_SECONDS) if animated else LOOP_SECONDS)
    count = options.frames or max(2, round(duration * options.fps))
    step = duration / count
    if animated:
        return [(start + k * step) % length for k in range(count)], [0.0] * count, step
    return [time] * count, [2 * math.pi * k / count for k in range(count)], step


def render_frames(scenes: list[Scene], options: PreviewOptions, frames: int,
                  progress: Callable[[int], None] | None = None,
                  on_planned: Callable[[int], None] | None = None):
    """Render each scene's frames; returns (frames[scene][k] as PIL images, seconds per frame).

    ``on_planned`` hears how many renders there will be, ``progress`` is called with 1 after each."""
    from PIL import Image

    from fishgen.preview.posing import poser_for
    from fishgen.preview.render import Renderer

    if options.clip is not None and not any(scene.clips for scene in scenes):
        # a clip-less input in a sheet of fish keeps its pose; with no clip anywhere, --clip did nothing
        whose = "the input has no" if len(scenes) == 1 else "none of the inputs has"
        found = f"{options.clip!r}, but {whose} clips"
        raise FishgenError(f"expected --clip to name an animation clip, found {found}",
                           (scenes[0].source or scenes[0].name) if len(scenes) == 1 else None)
    for scene in scenes:
        if options.clip is not None and scene.clips and scene.clip(options.clip) is None:
            names = ", ".join(a.name for a in scene.clips)
            raise FishgenError(f"expected --clip to name one of {names}, found {options.clip!r}",
                               scene.source or scene.name)
    plans = [_frame_plan(scene, options, frames) for scene in scenes]
    if on_planned:
        on_planned(sum(len(times) for times, _, _ in plans))
    renderer = Renderer(options.width, options.height, fine_blending=any(map(_has_particles, scenes)))
    r, g, b, a = (c / 255.0 for c in options.background)
    bg = (r, g, b, a)
    out, seconds = [], []
    try:
        for scene, (times, azimuths, step) in zip(scenes, plans, strict=True):
            seconds.append(step)
            base = frame_scene(scene, options.view, options.width / options.height,
                               sorted(set(times), key=lambda t: -1 if t is None else t), options.clip,
                               azimuths=tuple(sorted(set(azimuths))), ortho=options.ortho)
            _check_framed(base, scene)
            images = []
            shots = [(turned(base, options.view, az) if az else base, t)
                     for t, az in zip(times, azimuths, strict=True)]
            for image in renderer.render_all(scene, shots, bg, options.clip):
                images.append(Image.fromarray(image))
                if progress:
                    progress(1)
            poser_for(scene, options.clip).forget()  # the vertices kept from framing are drawn
            out.append(images)
    finally:
        renderer.release()
    return out, max(seconds)


def _has_particles(scene: Scene) -> bool:
    """Points, or a cloud's billboards (unlit, alpha-blended quads): many faint layers over a pixel,
    to blend in finer colour than 8 bits."""
    def particle(prim) -> bool:
        material = scene.materials[prim.material] if prim.material is not None else None
        return prim.mode == "POINTS" or (material is not None and material.alpha_mode == "BLEND"
                                         and material.unlit)
    return any(particle(prim) for _, prim in scene.drawn())


def compose(per_scene: list[list], labels: list[str], options: PreviewOptions) -> list:
    """One image per frame: the render itself, or a contact sheet of all inputs."""
    from fishgen.preview.sheet import contact_sheet

    if len(per_scene) == 1:
        return per_scene[0]
    n = max(len(f) for f in per_scene)
    return [contact_sheet([f[k % len(f)] for f in per_scene], labels, options.columns,
                          options.background) for k in range(n)]


def frame_durations(frames: int, seconds_per_frame: float, unit: int) -> list[int]:
    """Each frame's time in milliseconds, in steps of ``unit`` ms (a GIF counts in 10 ms), rounded
    where the clip has got to so far, not frame by frame: 38 frames of 84.2 ms are a 3.2 s loop,
    not 38 x 80 ms = 3.04 s. At least 20 ms a frame (browsers slow shorter GIF frames down)."""
    edges = [round(k * seconds_per_frame * 1000 / unit) * unit for k in range(frames + 1)]
    return [max(20, b - a) for a, b in zip(edges[:-1], edges[1:], strict=True)]


def encode(images: list, out: Path, seconds_per_frame: float) -> bytes:
    """The bytes of ``out`` in the format its extension names."""
    ext = out.suffix.lower()
    buf = io.BytesIO()
    if ext in (".jpg", ".jpeg"):
        images[0].convert("RGB").save(buf, "JPEG", quality=92)
    elif ext == ".png":
        images[0].save(buf, "PNG", optimize=False)
    elif ext == ".webp":
        kwargs: dict[str, object] = dict(lossless=False, quality=90, method=4)
        if len(images) > 1:
            kwargs.update(save_all=True, append_images=images[1:], loop=0,
                          duration=frame_durations(len(images), seconds_per_frame, 1))
        images[0].save(buf, "WEBP", **kwargs)
    else:  # gif: one shared palette keeps the loop from flickering between frames
        from PIL import Image

        rgb = [im.convert("RGB") for im in images]
        palette = rgb[0].quantize(colors=255, method=2)
        # no error diffusion: it spreads from the moving fish into the flat background and leaves
        # faint dotted trails that differ frame to frame
        frames = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in rgb]
        frames[0].save(buf, "GIF", save_all=True, append_images=frames[1:], loop=0,
                       duration=frame_durations(len(frames), seconds_per_frame, 10), disposal=1)
    return buf.getvalue()


def preview(inputs: Sequence[str | os.PathLike], out: str | os.PathLike, options: PreviewOptions,
            progress: Callable[[int], None] | None = None,
            on_loaded: Callable[[int], None] | None = None,
            on_note: Callable[[str], None] | None = None) -> Path:
    """Render ``inputs`` to ``out`` (still, contact sheet, or loop); written atomically.

    ``on_loaded`` hears the number of renders once the inputs are read and planned; ``progress``
    is called with 1 after each render (a progress bar's ``update``)."""
    from fishgen.atomic import write_bytes
    from fishgen.preview.inputs import load_input

    out = Path(out)
    if not inputs:
        raise FishgenError("expected at least one input, found none")
    # only a species file is sure to hold no particles before it is read
    frames = check_output(out, options, len(inputs), any(Path(p).suffix.lower() != ".txt" for p in inputs))
    scenes = [load_input(p, textures_dir=options.textures_dir, seed=options.seed, lighting=options.lighting)
              for p in inputs]
    # a scene built from a species or cube file names no file of its own: its errors name the input
    scenes = [scene if scene.source else replace(scene, source=os.fspath(p))
              for scene, p in zip(scenes, inputs, strict=True)]
    for scene in scenes:  # e.g. a cloud previewed with fewer particles than it holds
        if on_note and scene.note:
            on_note(scene.note)
    per_scene, step = render_frames(scenes, options, frames, progress, on_loaded)
    images = compose(per_scene, [Path(p).name for p in inputs], options)
    write_bytes(out, encode(images, out, step))
    return out
