"""`fishgen clouds`: cube files (.awn) to a particle cloud scene in one command.

numpy and the cloud package are imported inside the command, so `fishgen --help`
never pays for them.
"""
from __future__ import annotations

import click

DEFAULT_MAX_PARTICLES = 50_000_000  # mirrors fishgen.clouds.model without importing numpy
FLOAT32_MAX = 3.4028234663852886e38  # particle coordinates are float32


@click.command("clouds", context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("inputs", nargs=-1, required=True, metavar="CUBES.awn...")
@click.option("-o", "--output", required=True, metavar="PATH",
              help="Output file; the extension picks the format: .ply (binary), .glb, .gltf "
                   "(+ .bin), .csv or .npy.")
@click.option("--offset", "offsets", multiple=True, metavar="X,Y,Z",
              help="Where to place each input cloud in the scene, given once per input in the "
                   "same order.  [default: 0,0,0 for every input]")
@click.option("--seed", default=0, show_default=True, type=int,
              help="Random seed (0 or more); the same seed gives byte-identical output. "
                   "Input number i is filled with seed+i.")
@click.option("--method", type=click.Choice(["paper", "uniform"]), default="paper",
              show_default=True,
              help="paper: the report's sine phase shifts with rejection (clumped); "
                   "uniform: plain uniform positions and radii.")
@click.option("--billboards", is_flag=True, default=False,
              help="glTF only: one textured quad per particle (Gaussian alpha sprite, alpha "
                   "blended) instead of points.  [default: off, points]")
@click.option("--max-particles", default=DEFAULT_MAX_PARTICLES, show_default=True, type=int,
              help="Refuse scenes with more particles than this, before allocating anything.")
def clouds(inputs: tuple[str, ...], output: str, offsets: tuple[str, ...], seed: int,
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

    from fishgen.clouds import (CubeFileWarning, check_output, export_cloud, fill_cloud,
                                load_cubes, merge_clouds)
    from fishgen.errors import FishgenError, describe

    check_output(output, billboards)
    if seed < 0:
        raise FishgenError(f"expected a --seed of 0 or more, found {seed}")
    if max_particles < 1:
        raise FishgenError(f"expected a --max-particles of 1 or more, found {max_particles}")
    if offsets and len(offsets) != len(inputs):
        raise FishgenError(f"expected one --offset per input ({len(inputs)}), "
                           f"found {len(offsets)}")
    places = [_offset(text, describe) for text in offsets] or [(0.0, 0.0, 0.0)] * len(inputs)

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

    cloud = merge_clouds([fill_cloud(f, seed=seed + i, method=method, offset=place)
                          for i, (f, place) in enumerate(zip(files, places))])
    export_cloud(cloud, output, billboards=billboards)
    click.echo(f"{output}: {len(cloud):,} particles in {_plural(len(cloud.cube_bounds), 'cube')} "
               f"from {_plural(len(files), 'file')} ({method} fill, seed {seed})")


def _plural(count: int, noun: str) -> str:
    return f"{count:,} {noun}{'s' * (count != 1)}"


def _offset(text: str, describe) -> tuple[float, float, float]:
    import math

    from fishgen.errors import FishgenError

    parts = text.replace(" ", "").split(",")
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise FishgenError(f"expected --offset X,Y,Z with three finite numbers, "
                           f"found {describe(text)}")
    if not all(abs(v) <= FLOAT32_MAX for v in values):  # particles are float32
        raise FishgenError(f"expected --offset X,Y,Z within float32 range (-{FLOAT32_MAX:.3g} "
                           f"to {FLOAT32_MAX:.3g}), found {describe(text)}")
    return values  # type: ignore[return-value]
