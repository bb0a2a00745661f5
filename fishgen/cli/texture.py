"""`fishgen texture`: Fixel's texture points, measured on a side photo of a fish."""
from __future__ import annotations

from pathlib import Path

import click

SPACINGS = ("projected", "even")   # mirrors fishgen.authoring.photo.points (no numpy at --help time)


@click.command("texture", context_settings={"show_default": True, "help_option_names": ["-h", "--help"]})
@click.argument("photo", type=click.Path(path_type=Path))
@click.option("-s", "--species", "base", required=True, type=click.Path(path_type=Path), metavar="BASE.txt",
              help="Species file whose geometry (body, fins, level of detail) the new species starts from.")
@click.option("-o", "--output", required=True, type=click.Path(path_type=Path), metavar="NEW.txt",
              help="New species file; NEW.png (texture) and NEW_mask.png (fin mask) are written beside it.")
@click.option("--mask", type=click.Path(path_type=Path), default=None, metavar="MASK.png",
              help="Hand-made silhouette (white fish on black), the photo's size, for hard photos. "
                   "[default: the photo's alpha, else a model of the background]")
@click.option("--fit-shape", is_flag=True, default=False,
              help="Also fit the body profile, its proportions and the fin sizes to the photo.")
@click.option("--body-sections", type=click.IntRange(3, 256), default=None, metavar="N",
              help="BodySections of the new species. [default: the base species']")
@click.option("--circle-sections", type=click.IntRange(3, 256), default=None, metavar="M",
              help="CircleSections of the new species. [default: the base species']")
@click.option("--spacing", type=click.Choice(SPACINGS), default="projected",
              help="Points on each vertical line: where a side view shows the ring's points, or "
                   "evenly spaced as in the thesis' BonyBream listing.")
@click.option("--compare", type=click.Path(path_type=Path), default=None, metavar="OUT.png",
              help="Also write the photo beside the rebuilt fish, rendered the same way.")
@click.option("--fxl-in", type=click.Path(path_type=Path), default=None, metavar="POINTS.FXL",
              help="Take the parts a Fixel .FXL file holds from it instead of measuring them.")
@click.option("--fxl-out", type=click.Path(path_type=Path), default=None, metavar="POINTS.FXL",
              help="Also write the points as a Fixel .FXL file.")
def texture(photo: Path, base: Path, output: Path, mask: Path | None, fit_shape: bool,
            body_sections: int | None, circle_sections: int | None, spacing: str, compare: Path | None,
            fxl_in: Path | None, fxl_out: Path | None) -> None:
    """Make a species from PHOTO, a side view of one fish on a plain or transparent background.

    The head may point left or right and the fish may lie up to about 10 degrees
    off level. fishgen finds the silhouette, the body under the fins, the nose
    and the tail base, and places every texture point Fixel's user would have
    clicked (thesis chapter 6, Appendix B). The photo becomes the texture, stored
    upside down as VRFish expects.

    \b
    Examples:
      fishgen texture snapper.jpg -s params/centroberyx.txt -o out/snapper.txt
      fishgen texture snapper.jpg -s params/centroberyx.txt -o out/snapper.txt \
        --fit-shape --compare out/cmp.png
    """
    from fishgen.authoring.photo.run import TextureOptions, make_texture
    from fishgen.species.parser import load_species

    species = load_species(base)
    options = TextureOptions(mask=mask, fit_shape=fit_shape, body_sections=body_sections,
                             circle_sections=circle_sections, spacing=spacing, compare=compare,
                             fxl_in=fxl_in, fxl_out=fxl_out)
    result = make_texture(photo, species, output, options, on_note=lambda text: click.echo(text, err=True))
    turned = []
    if result.mirrored:
        turned.append("head on the right")
    if result.angle:
        turned.append(f"turned {result.angle:+.1f} degrees")
    how = f" ({', '.join(turned)})" if turned else ""
    click.echo(f"silhouette from the {result.source}{how}", err=True)
    if result.iou is not None:
        click.echo(f"silhouette IoU of the rebuilt fish: {result.iou:.3f}", err=True)
    for path in result.written:
        click.echo(f"wrote {path}")
