"""`fishgen texture`: Fixel's texture points, measured on a side photo of a fish."""
from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import click

from fishgen.authoring.photo import FOCAL_LENGTHS
from fishgen.commands import QUIET, Command, Events, Inputs, Made, Output
from fishgen.options import FILE, FiniteRange, option

SPACINGS = ("projected", "even")   # fishgen.authoring.photo.points.SPACINGS, without numpy


@dataclass(frozen=True)
class TextureCommandOptions:
    species: Path = option(FILE, "Species file whose geometry (body, fins, level of detail) the new species "
                           "starts from.", None, required=True, short="-s", metavar="BASE.txt")
    mask: Path | None = option(FILE, "Hand-made silhouette (white fish on black), the photo's size, for hard "
                               "photos.", shown_default="the photo's alpha, else a model of the background",
                               metavar="MASK.png")
    fit_shape: bool = option(click.BOOL,
                             "Also fit the body profile, its proportions and the fin sizes to the "
                             "photo.", False, flag=True)
    body_sections: int | None = option(click.IntRange(3, 256), "BodySections of the new species.",
                                       shown_default="the base species'", metavar="N")
    circle_sections: int | None = option(click.IntRange(3, 256), "CircleSections of the new species.",
                                         shown_default="the base species'", metavar="M")
    spacing: str = option(click.Choice(SPACINGS), "Points on each vertical line: where a side view shows the "
                          "ring's points, or evenly spaced as in the thesis' BonyBream listing.", "projected")
    compare: Path | None = option(FILE,
                                  "Also write the photo beside the rebuilt fish, rendered the same way.",
                                  shown_default="none", metavar="OUT.png")
    fxl_in: Path | None = option(FILE, "Take the parts a Fixel .FXL file holds from it instead of measuring "
                                 "them.", shown_default="none", metavar="POINTS.FXL")
    fxl_out: Path | None = option(FILE, "Also write the points as a Fixel .FXL file.", shown_default="none",
                                  metavar="POINTS.FXL")
    focal_length: float | None = option(
        FiniteRange(*FOCAL_LENGTHS), "The photo's focal length in mm on a 36 mm wide sensor (EXIF's "
        "FocalLengthIn35mmFilm): the rebuilt fish is measured in that perspective and, with --fit-shape, "
        "its fins are refined in it.", shown_default="none: seen from afar, no perspective", metavar="MM")


COMMAND = Command(
    name="texture",
    summary="Make a species from a side photo of a fish: texture, texture points, fin mask.",
    help="""Make a species from PHOTO, a side view of one fish on a plain or transparent background.

    The head may point left or right and the fish may lie up to about 10 degrees
    off level. fishgen finds the silhouette, the body under the fins, the nose
    and the tail base, and places every texture point Fixel's user would have
    clicked (thesis chapter 6, Appendix B). The photo becomes the texture, stored
    upside down as VRFish expects.

    \b
    Examples:
      fishgen texture params/photos/bonybream-side.png -s params/bonybream.txt -o out/bream.txt
      fishgen texture params/photos/bonybream-side.png -s params/centroberyx.txt -o out/bream.txt \\
        --fit-shape --compare out/cmp.png
    """,
    options=TextureCommandOptions,
    run="fishgen.commands.texture:texture",
    inputs=Inputs("PHOTO", many=False),
    output=Output("New species file, written exactly there; NEW.png (texture) and NEW_mask.png (fin mask) "
                  "go beside it. Where a species file cannot name those (whitespace, / or \\, not UTF-8, "
                  "over 255 bytes), each such run becomes _ and a note says so, and a derived name that is "
                  "another output or a file already there, not named by NEW.txt, is refused; so is a "
                  "texture another species file beside it names (X.txt's X_mask.png). The species "
                  "file, its textures and --compare/--fxl-out land together, or none.",
                  metavar="NEW.txt"),
)


def texture(inputs: Sequence[Path], output: str | os.PathLike, options: TextureCommandOptions,
            events: Events = QUIET) -> Made:
    """Measure the photo and write the new species, its texture and mask (and the extras asked)."""
    inputs = COMMAND.given(inputs, options)
    output = Path(output)
    from fishgen.authoring.photo.run import FITS, TextureOptions, check_out, make_texture
    from fishgen.authoring.species_files import check_texture_names, texture_names
    from fishgen.commands.paths import check_targets, suffix_of
    from fishgen.errors import UsageError
    from fishgen.species.parser import load_species

    (photo,) = inputs
    check_out(output)   # first: no other refusal about derived names hides it
    # the comparison is a PNG and the points Fixel text, whatever the name: refused, not mislabelled
    if options.compare is not None:
        suffix_of(options.compare, [".png"], "--compare")
    if options.fxl_out is not None:
        suffix_of(options.fxl_out, [".fxl"], "--fxl-out")
    if options.species is None:
        raise UsageError("expected -s/--species BASE.txt, the species to start from, found none")
    sides = [options.mask, options.fxl_in]
    outputs = [output, options.compare, options.fxl_out]  # and NEW.png, NEW_mask.png beside NEW.txt
    given = [p for p in sides if p is not None]
    check_targets(outputs, [photo, options.species, *given])  # before the base species is even read
    species = load_species(options.species, textures_needed=False)   # its geometry is all it gives
    check_targets(outputs, species.side_files)  # the textures it names are inputs too
    names = texture_names(output)
    check_texture_names(names, [options.compare, options.fxl_out, photo, options.species, *sides])
    check_targets(names.paths, [photo, options.species, *given, *species.side_files])  # before the fit
    settings = TextureOptions(mask=options.mask, fit_shape=options.fit_shape,
                              body_sections=options.body_sections,
                              circle_sections=options.circle_sections, spacing=options.spacing,
                              compare=options.compare, fxl_in=options.fxl_in, fxl_out=options.fxl_out,
                              focal_length=options.focal_length)
    if names.note is not None:
        events.note(names.note)
    # --fit-shape takes seconds, up to a minute on a photo that fits badly: a bar over its levels
    with events.progress("fitting", FITS if options.fit_shape else 0) as bar:
        result = make_texture(photo, species, output, settings, on_note=events.note, progress=bar.update)
    turned = (["head on the right"] if result.mirrored else []) + (
        [f"turned {result.angle:+.1f} degrees"] if result.angle else [])
    # the summary, on stdout (and silenced by --quiet); a warning about the fit stays a note
    lines = [f"silhouette from the {result.source}" + (f" ({', '.join(turned)})" if turned else "")]
    if result.iou is not None:
        lines.append(f"silhouette IoU of the rebuilt fish: {result.iou:.3f}")
    lines += [f"wrote {p}" for p in result.written]
    read = [photo, options.species, *species.side_files, *given]
    return Made(tuple(result.written), tuple(read), tuple(lines), result)
