"""`fishgen species`: sample plausible new species, painted and ready to build."""
from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import click

from fishgen.commands import QUIET, Command, Events, Made, Output
from fishgen.options import option

MAX_SEED = 2**63 - 1
"""The last seed (documented as 0..2^63-1); a --count running past it is refused."""


@dataclass(frozen=True)
class SpeciesOptions:
    random: bool = option(click.BOOL,
                          "Sample species at random (the only mode so far; say it so a typo never "
                          "samples).", False, flag=True, required=True)
    seed: int = option(click.IntRange(0, MAX_SEED), "Seed of the first species; seed + count - 1 may "
                       "not pass 2^63-1.", 0)
    count: int = option(click.IntRange(1, 10_000), "Species to write; more than one go into the folder -o "
                        "names, seeds seed..seed+K-1.", 1)


COMMAND = Command(
    name="species",
    summary="Sample plausible new species (shape, fins, motion) with painted textures.",
    help="""Write new VRFish species: body shape and profile, level of detail, fins and their
    sizes, fin technique and swimming, all within the ranges the thesis' and the
    shipped species span (docs/decisions.md), with a painted skin.

    \b
    Examples:
      fishgen species --random --seed 7 -o out/reef/fish7.txt
      fishgen species --random --seed 100 --count 16 -o out/reef/
    """,
    options=SpeciesOptions,
    run="fishgen.commands.species:species",
    output=Output("Species file (.txt) for one species, written exactly there; or a folder (an existing "
                  "one, or a name ending in /) for any count, holding species_SEED.txt. Beside OUT.txt go "
                  "OUT.png (texture) and OUT_mask.png (fin mask); where a species file cannot name those "
                  "(whitespace, / or \\, not UTF-8, over 255 bytes), each such run becomes _ and a note "
                  "says so, and a derived name that is a file already there, not named by OUT.txt, is "
                  "refused; so is a texture another species file beside it names (X.txt's X_mask.png). "
                  "Every file lands, or none.",
                  metavar="OUT", folder=True),
    together=True,
)


def species(inputs: Sequence[Path], output: str | os.PathLike, options: SpeciesOptions = SpeciesOptions(),
            events: Events = QUIET) -> Made:
    """Sample ``count`` species from ``seed`` on and write them: every file of every species, or none."""
    inputs = COMMAND.given(inputs, options)
    from fishgen.authoring.species_files import write_samples
    from fishgen.commands.paths import names_folder
    from fishgen.errors import UsageError

    if not options.random:
        raise UsageError("expected --random (the only way to make species so far), found none")
    folder = names_folder(output)
    path = Path(output)
    if not folder and options.count > 1:
        raise UsageError(f"expected a folder for --count {options.count} (an existing folder, or a name "
                         f"ending in /), found {os.fspath(output)!r}")
    if not folder and path.suffix.lower() != ".txt":
        raise UsageError(f"expected -o to name a species file (.txt) or a folder (an existing one, or a name "
                         f"ending in /), found {path.suffix or 'no extension'!r}", path)
    last = options.seed + options.count - 1
    if last > MAX_SEED:  # refused, not wrapped: species_0.txt after the last seed would be a surprise
        raise UsageError(f"expected seeds within 0..2^63-1 (--seed {MAX_SEED - options.count + 1} at most "
                         f"for --count {options.count}), found --seed {options.seed} --count {options.count} "
                         f"reaching {last}")
    # a bar for several: 2,000 species take about a minute
    with events.progress("sampling", options.count if options.count > 1 else 0) as bar:
        written = write_samples(options.seed, options.count, path, folder=folder, note=events.note,
                                progress=bar.update)
    return Made(tuple(written), (), tuple(f"wrote {p}" for p in written))
