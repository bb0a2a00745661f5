"""`fishgen clouds`: cube files (.awn) and texture clouds (.awa) to one lit cloud scene."""
from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import click

from fishgen.clouds.lighting import Lighting
from fishgen.clouds.model import DEFAULT_MAX_PARTICLES, DEFAULT_VOXEL_SIZE, METHODS
from fishgen.commands import QUIET, Command, Events, Inputs, Made, Output
from fishgen.exchange.registry import POINTS, extensions, formats
from fishgen.options import (
    Triple,
    cloud_textures_option,
    group,
    max_particles_option,
    option,
    seed_option,
    voxel_size_option,
)

BILLBOARD_TRIANGLES = 6  # fishgen.clouds.scene.TRIANGLES_PER_BILLBOARD, without numpy (a test checks)


@dataclass(frozen=True)
class CloudsOptions:
    offset: tuple[tuple[float, float, float], ...] = option(
        Triple(), "Where to place each input cloud in the scene, given once per input in the same order.",
        (), shown_default="0,0,0 for every input", multiple=True)
    seed: int | None = seed_option("Input number i is filled with seed+i.", None,
                                   shown_default="0; in a batch, derived from the output's name")
    method: str = option(click.Choice(METHODS), "paper: the report's sine phase shifts with rejection "
                         "(clumped); uniform: plain uniform positions and radii.", "paper")
    billboards: bool = option(click.BOOL,
                              f"glTF only: three crossed quads per particle ({BILLBOARD_TRIANGLES} "
                              "triangles, 12 vertices), an alpha-blended Gaussian sprite, instead of points; "
                              "a texture cloud (.awa) is always billboards, with its PNGs, and so are "
                              ".awn clouds given with one.", False, flag=True)
    max_particles: int = max_particles_option(DEFAULT_MAX_PARTICLES)
    voxel_size: float | None = voxel_size_option(DEFAULT_VOXEL_SIZE)
    textures: Path | None = cloud_textures_option()
    lighting: Lighting = group(Lighting)
    light: bool = option(click.BOOL, "Bake the sunlight into each particle's colour (and its _LIGHT "
                         "attribute); off skips the lighting and writes the particles white, for "
                         "positions, radii and density only.", True, flag=True, off="--no-light")


def check_options(options: CloudsOptions, output: str | os.PathLike | None = None) -> None:
    """Options that would be ignored or cannot be met, refused before any work (and at a manifest
    job's line, before any job runs)."""
    from fishgen.errors import UsageError

    if not options.light and options.lighting != Lighting():
        from dataclasses import fields

        def flag(name: str, value: object) -> str:   # a switch given off reads --no-NAME
            return f"--{'no-' if value is False else ''}{name.replace('_', '-')}"

        given = [flag(f.name, getattr(options.lighting, f.name)) for f in fields(Lighting)
                 if getattr(options.lighting, f.name) != getattr(Lighting(), f.name)]
        raise UsageError(f"expected no lighting options with --no-light, found {', '.join(given)}")
    if options.billboards and output is not None:
        from fishgen.commands.paths import output_at_fault
        from fishgen.exchange.clouds import check_output

        with output_at_fault():     # the options' fault, not the file's: a manifest job's line
            check_output(output, billboards=True)
    if options.voxel_size is not None and output is not None:
        from fishgen.exchange.clouds import VOLUME_FORMATS

        suffix = Path(output).suffix.lower()
        if suffix not in VOLUME_FORMATS:
            raise UsageError(f"expected a {' or '.join(sorted(VOLUME_FORMATS))} output with --voxel-size, "
                             f"found {suffix or 'no extension'!r}", output)


COMMAND = Command(
    name="clouds",
    summary="Fill cloud cube files (.awn, .awa) with particles, lit by the sun, and export them.",
    help="""Fill cloud cube files (.awn, or texture clouds .awa) with particles, light them and export them.

    Each CUBES.awn file (RekAwan editor format: total particles, number of cubes,
    then per cube: particles, x y z size, centre x y z, maximum radius) becomes
    one cloud; several files with --offset make one scene. The scene is lit by the
    sun as RekAwan's renderer lit it (Harris's multiple forward scattering, baked
    into each particle's colour and its _LIGHT attribute). A texture cloud (.awa:
    each cube line also names its PNG) becomes textured billboards. A .vdb or
    .nvdb output is the cloud as a volume: a "density" grid (extinction per
    unit, the particles' Gaussians as the lighting sees them) and a "light"
    grid (the baked sunlight), in voxels of --voxel-size.

    \b
    Examples:
      fishgen clouds params/clouds/table_4_3.awn -o out/cloud.ply
      fishgen clouds params/clouds/table_4_3.awn params/clouds/table_4_4.awn \\
          --offset 0,0,0 --offset 25,3,-10 -o out/sky.glb --billboards
      fishgen clouds params/clouds/table_4_4.awn -o out/cloud.glb --billboards --sun 1,0.3,0
      fishgen clouds params/clouds/sky.awa -o out/texture-sky.glb
      fishgen clouds params/clouds/table_4_4.awn -o out/cloud.vdb --voxel-size 0.1
    """,
    options=CloudsOptions,
    run="fishgen.commands.clouds:clouds",
    inputs=Inputs("CUBES.awn|CLOUD.awa..."),
    output=Output(f"Output file; the extension picks the format: "
                  f"{', '.join(extensions(formats(writable=True, holding=[POINTS])))}.", holds=(POINTS,)),
    batch=True,
    check=check_options,
)


@dataclass(frozen=True)
class CloudFacts:
    particles: int
    cubes: int
    files: int
    billboards: bool
    lighting: Lighting


def clouds(inputs: Sequence[Path], output: str | os.PathLike, options: CloudsOptions = CloudsOptions(),
           events: Events = QUIET) -> Made:
    """Fill every cube file, light them together (so clouds shadow each other) and write them as one
    scene; input i is filled with seed + i. A texture cloud (.awa) becomes textured billboards."""
    inputs = COMMAND.given(inputs, options)
    from fishgen.clouds.pipeline import check_total, cloud_steps, cloud_textures, cube_clouds, read_cube_files
    from fishgen.commands.paths import check_inputs, check_targets, output_at_fault
    from fishgen.errors import UsageError, plural
    from fishgen.exchange.clouds import VOLUME_FORMATS, check_output, export_cloud
    from fishgen.exchange.registry import FORMATS

    inputs = tuple(Path(p) for p in inputs)
    output = Path(output)
    kinds = check_inputs(inputs, "clouds", [FORMATS["cubes"], FORMATS["texture cubes"]],
                         default=FORMATS["cubes"])
    textured = any(kind is FORMATS["texture cubes"] for kind in kinds)
    billboards = options.billboards or (textured and output.suffix.lower() in (".glb", ".gltf"))
    with output_at_fault():
        check_output(output, billboards)
    check_options(options, output)
    check_targets([output], inputs)
    if options.offset and len(options.offset) != len(inputs):
        raise UsageError(f"expected one --offset per input ({len(inputs)}), found {len(options.offset)}")
    files = read_cube_files(inputs, max_particles=options.max_particles, textures_dir=options.textures,
                            note=events.note, raise_with="--max-particles")
    textures = cloud_textures(files)
    if textures and not billboards:
        events.note(f"{output}: {output.suffix.upper()[1:]} holds no textures; the billboards' centres are "
                    "written as particles")
    check_targets([output], textures)
    with output_at_fault():     # a glTF buffer holds 4 GiB
        check_output(output, billboards, particles=sum(f.total for f in files))
    from fishgen.clouds.memory import check_fits

    check_fits(sum(f.total for f in files), output.suffix, billboards)    # before anything is filled
    volume = output.suffix.lower() in VOLUME_FORMATS
    voxel_size = options.voxel_size if options.voxel_size is not None else DEFAULT_VOXEL_SIZE
    if volume:
        from fishgen.clouds.volume import check_cube_files
        from fishgen.errors import FishgenError

        try:
            check_cube_files(files, options.offset, voxel_size)
        except FishgenError as err:     # too fine a --voxel-size: the option's fault, not the output's
            raise UsageError(err.message) from None
    seed = options.seed or 0
    check_total(files, options.max_particles)     # before the bar: a refusal is the command's one line
    with events.progress("filling and lighting" if options.light else "filling",
                         cloud_steps(files, light=options.light)) as bar:
        made = cube_clouds(files, seed=seed, method=options.method, offsets=options.offset,
                           lighting=options.lighting, light=options.light,
                           max_particles=options.max_particles, advance=bar.update)
    if options.light:
        cloud = made.cloud
        sun = "sun " + ",".join(f"{v:g}" for v in options.lighting.sun)
    else:
        from fishgen.clouds.fill import merge_clouds

        cloud, sun = merge_clouds(made.clouds), "unlit"
    if volume:      # splatting 10^6 particles into voxels took 20 s, after the fill's bar was full
        with events.progress("voxelizing", len(cloud)) as bar:
            written = export_cloud(cloud, output, billboards=billboards, voxel_size=voxel_size,
                                   advance=bar.update)
    else:
        written = export_cloud(cloud, output, billboards=billboards, voxel_size=voxel_size)
    line = (f"{output}: {plural(len(cloud), made.noun)} in {plural(len(cloud.cube_bounds), 'cube')} "
            f"from {plural(len(files), 'file')} ({options.method} fill, seed {seed}, {sun}"
            f"{f', voxels of {voxel_size:g}' * volume})")
    facts = CloudFacts(len(cloud), len(cloud.cube_bounds), len(files), billboards, options.lighting)
    return Made(tuple(written), (*inputs, *textures), (line,), facts)

