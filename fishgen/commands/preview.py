"""`fishgen preview`: render species, cube files or assets to PNG, contact sheets or loops."""
from __future__ import annotations

import os
from collections.abc import Sequence
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path

import click

from fishgen.clouds.lighting import Lighting
from fishgen.commands import QUIET, Command, Events, Inputs, Made, Output
from fishgen.options import Colour, FiniteRange, Size, group, option, seed_option, textures_option

VIEW_NAMES = ("side", "top", "front", "three-quarter")  # fishgen.preview.camera.VIEWS, without numpy


@dataclass(frozen=True)
class PreviewCommandOptions:
    view: str = option(click.Choice(VIEW_NAMES), "Camera direction; fish face left in side, top and "
                       "three-quarter views.", "three-quarter")
    size: tuple[int, int] = option(Size(16, 8192), "Pixel size of one render (each tile of a contact sheet), "
                                   "16 to 8192 a side. A contact sheet may hold at most 2^28 pixels, all "
                                   "frames "
                                   "and sheets together 2^30.", (800, 600), shown_default="800x600")
    time: float | None = option(FiniteRange(0, 1e6, max_open=True),
                                "Pose the animation at this time, or start a loop there. A school written "
                                "by `fishgen school` records its warm-up, when its fish still face every "
                                "way: its preview starts after it.",
                                shown_default="a school's warm-up, else the rest pose (a loop: 0)",
                                metavar="SECONDS")
    clip: str | None = option(click.STRING, "Animation clip to pose or loop.",
                              shown_default="the first, `swim` for fishgen fish", metavar="NAME")
    background: tuple[int, int, int, int] = option(
        Colour(), "Background colour (#rrggbb, #rrggbbaa, a CSS name) or `transparent` (PNG/WebP).",
        (140, 173, 204, 255), shown_default="#8cadcc")
    frames: int | None = option(click.IntRange(1, 1000), "Frames of an animated .gif/.webp, spread over "
                                "--duration; frames x inputs x W x H at most 2^30 pixels.",
                                shown_default="duration x fps for .gif, 1 otherwise", metavar="N")
    fps: float = option(FiniteRange(1, 60), "Frames per second of an animated .gif/.webp.", 12.0)
    duration: float | None = option(FiniteRange(0, 600, min_open=True), "Seconds of the clip a loop shows (a "
                                    "turntable turns once in them).", shown_default="the clip, or its "
                                                                                    "first 4 s "
                                    "if longer; 4 s for a turntable", metavar="SECONDS")
    columns: int | None = option(click.IntRange(min=1), "Columns of a contact sheet of several inputs.",
                                 shown_default="about a square grid", metavar="N")
    seed: int = seed_option("Fills .awn cube files as `fishgen clouds` does.")
    textures: Path | None = textures_option("as `fishgen build` resolves them")
    lighting: Lighting = group(Lighting)
    ortho: bool = option(click.BOOL,
                         "Orthographic camera: no perspective, e.g. a side view to use as a photo "
                         "for `fishgen texture`.", False, flag=True)


COMMAND = Command(
    name="preview",
    summary="Render inputs or assets to PNG, contact sheets or swim loops.",
    help="""Render INPUT... to an image, as a game engine would show it.

    INPUT is a species file (.txt), a cloud cube file (.awn), a texture
    cloud (.awa) or an asset
    (.glb, .gltf, .obj, .ply) written by fishgen or anything else. Several
    inputs make a labelled contact sheet; a .gif or .webp with --frames makes
    an animated swim loop (a turntable for assets without animation).

    \b
    Examples:
      fishgen preview params/bonybream.txt -o out/bonybream.png
      fishgen preview params/*.txt -o out/sheet.png --view side
      fishgen preview out/bonybream.glb -o out/swim.gif --duration 8
    """,
    options=PreviewCommandOptions,
    run="fishgen.commands.preview:preview",
    inputs=Inputs("INPUT...", path=True),
    output=Output("Image to write: .png, .jpg, .webp, or .gif/.webp for a loop.", metavar="OUT"),
)


def preview(inputs: Sequence[Path], output: str | os.PathLike,
            options: PreviewCommandOptions = PreviewCommandOptions(),
            events: Events = QUIET) -> Made:
    """Render the inputs to one image or loop."""
    inputs = COMMAND.given(inputs, options)
    output = Path(output)
    from fishgen.atomic import protecting
    from fishgen.commands.paths import check_inputs, check_targets, read_beside
    from fishgen.preview.inputs import input_formats
    from fishgen.preview.pipeline import PreviewOptions
    from fishgen.preview.pipeline import preview as render

    beside = read_beside(inputs, check_inputs(inputs, "preview", input_formats()), options.textures)
    check_targets([output], [*inputs, *beside])
    width, height = options.size
    settings = PreviewOptions(view=options.view, width=width, height=height, time=options.time,
                              background=options.background, frames=options.frames, fps=options.fps,
                              duration=options.duration, columns=options.columns, clip=options.clip,
                              seed=options.seed, textures_dir=options.textures, ortho=options.ortho,
                              lighting=options.lighting)
    with ExitStack() as stack:
        stack.enter_context(protecting(beside))
        bar: list = []

        def start(total: int) -> None:  # a bar over the frames of a loop or sheet, not one still
            if total > 1:
                bar.append(stack.enter_context(events.progress("rendering", total)))

        out = render(inputs, output, settings, progress=lambda n: bar[0].update(n) if bar else None,
                     on_loaded=start, on_note=events.note)
    if options.duration is not None and options.frames is None and output.suffix.lower() != ".gif":
        # said once it is written: a failed run's one line stays its only one
        events.note(f"{output}: a still; --duration makes a loop in a .gif, or in a .webp with --frames")
    if options.lighting != Lighting() and not any(p.suffix.lower() in (".awn", ".awa") for p in inputs):
        # an asset's light is baked into it; the preview shows it as the file says
        events.note(f"{output}: the lighting options light cube files (.awn, .awa) only; "
                    "an asset shows the light it was written with")
    return Made((out,), (*inputs, *beside), (f"wrote {out}",))
