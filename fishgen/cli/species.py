"""`fishgen species`: sample plausible new species, painted and ready to build."""
from __future__ import annotations

from pathlib import Path

import click


@click.command("species", context_settings={"show_default": True, "help_option_names": ["-h", "--help"]})
@click.option("--random", "random_", is_flag=True, required=True,
              help="Sample species at random (the only mode so far; say it so a typo never samples).")
@click.option("--seed", type=click.IntRange(0, 2**63 - 1), default=0, help="Seed of the first species.")
@click.option("--count", type=click.IntRange(1, 10_000), default=1,
              help="Species to write; more than one go into the folder -o names, seeds seed..seed+K-1.")
@click.option("-o", "--output", required=True, type=click.Path(path_type=Path), metavar="OUT",
              help="Species file (.txt) for one species, a folder for --count above 1. Textures "
                   "(NAME.png, NAME_mask.png) are written beside each species file.")
def species(random_: bool, seed: int, count: int, output: Path) -> None:
    """Write new VRFish species: body shape and profile, level of detail, fins and their
    sizes, fin technique and swimming, all within the ranges the thesis' and the
    shipped species span (docs/decisions.md), with a painted skin.

    \b
    Examples:
      fishgen species --random --seed 7 -o out/reef/fish7.txt
      fishgen species --random --seed 100 --count 16 -o out/reef
    """
    from fishgen.authoring.species_files import write_samples

    for path in write_samples(seed, count, output):
        click.echo(f"wrote {path}")
