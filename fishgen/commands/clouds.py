"""`fishgen clouds`: cube files (.awn) to one particle cloud scene."""
from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import click

from fishgen.clouds.model import DEFAULT_MAX_PARTICLES, METHODS
from fishgen.commands import QUIET, Command, Events, Inputs, Made, Output
from fishgen.exchange.registry import POINTS, extensions, formats
from fishgen.options import Triple, option, seed_option


@dataclass(frozen=True)
class CloudsOptions:
    offset: tuple[tuple[float, float, float], ...] = option(
        Triple(), "Where to place each input cloud in the scene, given once per input in the same order.",
        (), shown_default="0,0,0 for every input", multiple=True)
    seed: int | None = seed_option("Input number i is filled with seed+i.", None,
                                   shown_default="0; in a batch, derived from the output's name")
    method: str = option(click.Choice(METHODS), "paper: the report's sine phase shifts with rejection "
                         "(clumped); uniform: plain uniform positions and radii.", "paper")
    billboards: bool = option(click.BOOL, "glTF only: one textured quad per particle (Gaussian alpha sprite, "
                              "alpha blended) instead of points.", False, flag=True)
    max_particles: int = option(click.IntRange(min=1), "Refuse scenes with more particles than this, "
                                "before allocating anything.", DEFAULT_MAX_PARTICLES)


COMMAND = Command(
    name="clouds",
    summary="Fill cloud cube files (.awn) with particles and export them.",
    help="""Fill cloud cube files (.awn) with particles and export them.

    Each CUBES.awn file (RekAwan editor format: total particles, number of cubes,
    then per cube: particles, x y z size, centre x y z, maximum radius) becomes
    one cloud; several files with --offset make one scene.

    \b
    Examples:
      fishgen clouds params/clouds/table_4_3.awn -o out/cloud.ply
      fishgen clouds a.awn b.awn --offset 0,0,0 --offset 25,3,-10 -o out/sky.glb --billboards
    """,
    options=CloudsOptions,
    run="fishgen.commands.clouds:clouds",
    inputs=Inputs("CUBES.awn..."),
    output=Output(f"Output file; the extension picks the format: "
                  f"{', '.join(extensions(formats(writable=True, holding=[POINTS])))}.", holds=(POINTS,)),
    batch=True,
)


def clouds(inputs: Sequence[Path], output: str | os.PathLike,
           options: CloudsOptions = CloudsOptions(),
           events: Events = QUIET) -> Made:
    """Fill every cube file and write them as one scene; input i is filled with seed + i."""
    inputs = tuple(Path(p) for p in inputs)
    output = Path(output)
    from fishgen.clouds.export import check_output, export_cloud
    from fishgen.clouds.fill import fill_cloud, merge_clouds
    from fishgen.clouds.parser import CubeFileWarning, load_cubes
    from fishgen.commands.paths import check_inputs, check_targets
    from fishgen.errors import UsageError
    from fishgen.exchange.registry import FORMATS

    check_inputs(inputs, "clouds", [FORMATS["cubes"]], default=FORMATS["cubes"])
    check_output(output, options.billboards)
    check_targets([output], inputs)
    if options.offset and len(options.offset) != len(inputs):
        raise UsageError(f"expected one --offset per input ({len(inputs)}), found {len(options.offset)}")
    places = list(options.offset) or [(0.0, 0.0, 0.0)] * len(inputs)
    limit = options.max_particles
    files = []
    for path in inputs:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", CubeFileWarning)
            files.append(load_cubes(path, max_particles=limit))
        for note in caught:
            events.note(str(note.message))
    total = sum(f.total for f in files)
    if total > limit:
        raise UsageError(f"expected at most {limit:,} particles in the scene (raise the limit with "
                         f"--max-particles), found {total:,} in {len(files)} files")
    check_output(output, options.billboards, particles=total)  # before filling: a glTF buffer holds 4 GiB
    seed = options.seed or 0
    cloud = merge_clouds([fill_cloud(f, seed=seed + i, method=options.method, offset=place)
                          for i, (f, place) in enumerate(zip(files, places, strict=True))])
    written = export_cloud(cloud, output, billboards=options.billboards)
    line = (f"{output}: {len(cloud):,} particles in {_plural(len(cloud.cube_bounds), 'cube')} "
            f"from {_plural(len(files), 'file')} ({options.method} fill, seed {seed})")
    return Made(tuple(written), tuple(inputs), (line,), cloud)


def _plural(count: int, noun: str) -> str:
    return f"{count:,} {noun}{'s' * (count != 1)}"
