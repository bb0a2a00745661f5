"""`fishgen clouds`: cube files (.awn) to a particle cloud scene in one command.

numpy and the cloud package are imported inside the command, so `fishgen --help`
never pays for them.
"""
from __future__ import annotations

import click

from fishgen.cli.params import Triple

DEFAULT_MAX_PARTICLES = 50_000_000  # mirrors fishgen.clouds.model without importing numpy


@click.command("clouds", context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("inputs", nargs=-1, required=True, metavar="CUBES.awn...")
@click.option("-o", "--output", required=True, metavar="PATH",
              help="Output file; the extension picks the format: .ply (binary), .glb, .gltf "
                   "(+ .bin), .csv or .npy.")
@click.option("--offset", "offsets", multiple=True, type=Triple(),
              help="Where to place each input cloud in the scene, given once per input in the "
                   "same order.  [default: 0,0,0 for every input]")
@click.option("--seed", default=0, show_default=True, type=click.IntRange(min=0),
              help="Random seed (0 or more); the same seed gives byte-identical output. "
                   "Input number i is filled with seed+i.")
@click.option("--method", type=click.Choice(["paper", "uniform"]), default="paper",
              show_default=True,
              help="paper: the report's sine phase shifts with rejection (clumped); "
                   "uniform: plain uniform positions and radii.")
@click.option("--billboards", is_flag=True, default=False,
              help="glTF only: one textured quad per particle (Gaussian alpha sprite, alpha "
                   "blended) instead of points.  [default: off, points]")
@click.option("--max-particles", default=DEFAULT_MAX_PARTICLES, show_default=True, type=click.IntRange(min=1),
              help="Refuse scenes with more particles than this, before allocating anything.")
def clouds(inputs: tuple[str, ...], output: str, offsets: tuple[tuple[float, float, float], ...], seed: int,
           method: str, billboards: bool, max_particles: int) -> None:
    """Fill cloud cube files (.awn) with particles and export them.

    Each CUBES.awn file (RekAwan editor format: total particles, number of cubes,
    then per cube: particles, x y z size, centre x y z, maximum radius) becomes
    one cloud; several files with --offset make one scene.

    \b
    Examples:
      fishgen clouds params/clouds/table_4_3.awn -o cloud.ply
      fishgen clouds a.awn b.awn --offset 0,0,0 --offset 25,3,-10 -o sky.glb --billboards
    """
    import warnings

    from fishgen.cli.params import check_inputs
    from fishgen.clouds import (
        CubeFileWarning,
        check_output,
        export_cloud,
        fill_cloud,
        load_cubes,
        merge_clouds,
    )
    from fishgen.errors import FishgenError
    from fishgen.exchange.registry import FORMATS

    check_inputs(inputs, "clouds", [FORMATS["cubes"]], default=FORMATS["cubes"])
    check_output(output, billboards)
    if offsets and len(offsets) != len(inputs):
        raise FishgenError(f"expected one --offset per input ({len(inputs)}), "
                           f"found {len(offsets)}")
    places = list(offsets) or [(0.0, 0.0, 0.0)] * len(inputs)

    files = []
    for path in inputs:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", CubeFileWarning)
            files.append(load_cubes(path, max_particles=max_particles))
        for note in caught:
            click.echo(str(note.message), err=True)
    total = sum(f.total for f in files)
    if total > max_particles:
        raise FishgenError(f"expected at most {max_particles:,} particles in the scene (raise "
                           f"the limit with --max-particles), found {total:,} in {len(files)} files")
    check_output(output, billboards, particles=total)  # before filling: a glTF buffer holds 4 GiB

    cloud = merge_clouds([fill_cloud(f, seed=seed + i, method=method, offset=place)
                          for i, (f, place) in enumerate(zip(files, places, strict=True))])
    export_cloud(cloud, output, billboards=billboards)
    click.echo(f"{output}: {len(cloud):,} particles in {_plural(len(cloud.cube_bounds), 'cube')} "
               f"from {_plural(len(files), 'file')} ({method} fill, seed {seed})")


def _plural(count: int, noun: str) -> str:
    return f"{count:,} {noun}{'s' * (count != 1)}"
