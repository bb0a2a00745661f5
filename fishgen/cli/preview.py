"""`fishgen preview`: render species, cube files or assets to PNG, contact sheets or loops."""
from __future__ import annotations

import sys

import click

from fishgen.cli.params import FiniteRange

VIEW_NAMES = ("side", "top", "front", "three-quarter")


@click.command(context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("inputs", nargs=-1, required=True, metavar="INPUT...")
@click.option("-o", "--output", required=True, metavar="OUT",
              help="Image to write: .png, .jpg, .webp, or .gif/.webp for a loop.")
@click.option("--view", type=click.Choice(VIEW_NAMES), default="three-quarter", show_default=True,
              help="Camera direction; fish face left in side, top and three-quarter views.")
@click.option("--size", default="800x600", show_default=True, metavar="WxH",
              help="Pixel size of one render (each tile of a contact sheet), 16 to 8192 a side. "
                   "A contact sheet may hold at most 2^28 pixels, all frames and sheets together 2^30.")
@click.option("--time", "time_", type=FiniteRange(0, 1e6, max_open=True), default=None,
              metavar="SECONDS",
              help="Pose the animation at this time  [default: rest pose; a loop's start]")
@click.option("--clip", default=None, metavar="NAME",
              help="Animation clip to pose or loop  [default: the first, `swim` for fishgen fish]")
@click.option("--background", default="#8cadcc", show_default=True, metavar="COLOUR",
              help="Background colour (#rrggbb, #rrggbbaa, a CSS name) or `transparent` (PNG/WebP).")
@click.option("--frames", type=click.IntRange(1, 1000), default=None, metavar="N",
              help="Frames of an animated .gif/.webp, spread over --duration; frames x inputs x W x H "
                   "at most 2^30 pixels  [default: duration x fps for .gif, 1 otherwise]")
@click.option("--fps", "loop_fps", type=FiniteRange(1, 60), default=12.0, show_default=True,
              help="Frames per second of an animated .gif/.webp.")
@click.option("--duration", type=FiniteRange(0, 600, min_open=True), default=None, metavar="SECONDS",
              help="Seconds of the clip a loop shows (a turntable turns once in them)  "
                   "[default: the clip, or its first 4 s if longer; 4 s for a turntable]")
@click.option("--columns", type=click.IntRange(min=1), default=None, metavar="N",
              help="Columns of a contact sheet of several inputs  [default: about a square grid]")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Random seed (0 or more) for filling .awn cube files, as `fishgen clouds` uses it.")
@click.option("--textures", type=click.Path(file_okay=False), default=None, metavar="DIR",
              help="Folder of species textures  [default: as `fishgen build` resolves them]")
@click.option("--ortho", is_flag=True, default=False,
              help="Orthographic camera: no perspective, e.g. a side view to use as a photo for "
                   "`fishgen texture`.")
def preview(inputs, output, view, size, time_, clip, background, frames, loop_fps, duration, columns, seed,
            textures, ortho):
    """Render INPUT... to an image, as a game engine would show it.

    INPUT is a species file (.txt), a cloud cube file (.awn) or an asset
    (.glb, .gltf, .obj, .ply) written by fishgen or anything else. Several
    inputs make a labelled contact sheet; a .gif or .webp with --frames makes
    an animated swim loop (a turntable for assets without animation).

    \b
    Examples:
      fishgen preview params/bonybream.txt -o out/bonybream.png
      fishgen preview params/*.txt -o out/sheet.png --view side
      fishgen preview out/bonybream.glb -o out/swim.gif --duration 8
    """
    from fishgen.cli.params import check_inputs
    from fishgen.preview.inputs import input_formats
    from fishgen.preview.pipeline import PreviewOptions, parse_background, parse_size
    from fishgen.preview.pipeline import preview as run

    check_inputs(inputs, "preview", input_formats())
    width, height = parse_size(size)
    options = PreviewOptions(view=view, width=width, height=height, time=time_,
                             background=parse_background(background), frames=frames, fps=loop_fps,
                             duration=duration, columns=columns, clip=clip, seed=seed, textures_dir=textures,
                             ortho=ortho)
    bar = None

    def start(total: int) -> None:
        nonlocal bar
        # A bar only helps a person watching; logs and CI get none.
        if total > 1 and sys.stderr.isatty():
            bar = click.progressbar(length=total, label="rendering", file=sys.stderr)
            bar.__enter__()

    try:
        out = run(inputs, output, options, progress=lambda n: bar.update(n) if bar else None,
                  on_loaded=start, on_note=lambda text: click.echo(text, err=True))
    finally:
        if bar is not None:
            bar.__exit__(None, None, None)
    click.echo(f"wrote {out}")
