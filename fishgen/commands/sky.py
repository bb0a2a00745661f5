"""`fishgen sky`: a sky of many lit clouds (Pakawan's thin, medium and thick modes) for engines."""
from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import click

from fishgen.clouds.lighting import Lighting
from fishgen.clouds.model import DEFAULT_MAX_PARTICLES
from fishgen.commands import QUIET, Command, Events, Made, Output
from fishgen.options import (
    FILE,
    FiniteRange,
    Numbers,
    cloud_textures_option,
    group,
    max_particles_option,
    option,
    seed_option,
)
from fishgen.sky.modes import ALTITUDE, AREA, MODES, NOISE, SHIPPED_CUBES


def _modes_help() -> str:
    return "; ".join(f"{m.name}: {m.clouds} clouds, {m.particles:,} particles, "
                     f"scale {m.scale[0]:g}-{m.scale[1]:g}"
                     for m in MODES.values())


def _least_help() -> str:
    return ", ".join(f"{m.name} {m.clouds * SHIPPED_CUBES:,}" for m in MODES.values())


@dataclass(frozen=True)
class SkyOptions:
    mode: str = option(click.Choice(tuple(MODES)), f"Pakawan's sky modes ({_modes_help()}).", "medium")
    area: tuple[float, float] = option(Numbers(2, "W,D", 1.0, 1e6, positive=True),
                                       "Width (x) and depth (z) of the sky, centred on the origin, in "
                                       "cube-file units.", AREA, metavar="W,D")
    altitude: tuple[float, float] = option(Numbers(2, "LOW,HIGH", -1e6, 1e6, ordered=True), "Range of the "
                                           "clouds' base heights (y, up).", ALTITUDE, metavar="LOW,HIGH")
    seed: int = seed_option("It picks every cloud's model, scale, turn, place, fill and noise.")
    clouds: tuple[Path, ...] = option(FILE, "A cube file (.awn) or texture cloud (.awa) to draw the clouds "
                                      "from, each varied (scaled, turned, re-filled, noise); give it once "
                                      "per file.", (), shown_default="the report's two cumulus files "
                                      "(Tables 4.3, 4.4)", multiple=True, path=True, metavar="CUBES")
    noise: float = option(FiniteRange(0, 0.9), "Seeded 3D noise on particle sizes and densities: each is "
                          "scaled by 1 + NOISE x fBm (mostly within +-0.4); 0 turns it off.", NOISE,
                          metavar="AMOUNT")
    particles: int | None = option(click.IntRange(1, DEFAULT_MAX_PARTICLES), "Particles in the whole sky, "
                                   "shared by the clouds by volume; at least one for each cube of every "
                                   "cloud: the mode's clouds times the most cubes in a --clouds file "
                                   f"(with the shipped files, {_least_help()}).", shown_default="the mode's",
                                   metavar="N")
    shadow_map: str = option(click.Choice(("cloud", "sky")), "cloud: each cloud lit on its own shadow map, "
                             "the clouds between it and the sun as occluders (fine, 3-10x slower); sky: one "
                             "map for the whole sky (coarse).", "cloud")
    lod: bool = option(click.BOOL, "Give each cloud lower levels of detail for distance: one particle in 8 "
                       "(below 0.8 of the view's height) and in 64 (below 0.2), larger (MSFT_lod; Unity "
                       "_LOD0/_LOD1/_LOD2 names).", True, flag=True, off="--no-lod")
    billboards: bool = option(click.BOOL, "Particle clouds as crossed-quad billboards instead of points "
                              "(texture clouds always are).", False, flag=True)
    max_particles: int = max_particles_option(DEFAULT_MAX_PARTICLES, "skies")
    textures: Path | None = cloud_textures_option()
    lighting: Lighting = group(Lighting)


COMMAND = Command(
    name="sky",
    summary="Compose a sky of many lit clouds (thin, medium, thick) for engines.",
    help="""Compose a sky of many clouds, lit by one sun, as one glTF file.

    Each cloud is a variation of a cloud model (the shipped cumulus files, or
    --clouds): scaled, turned about the vertical, re-filled with the report's
    randomized algorithm and roughened by seeded 3D noise, placed in the area
    and altitude band. The whole sky is lit by one sun (Harris's method, as
    `fishgen clouds`), clouds shadowing clouds. Each cloud is its own node with
    its bounds, so engines cull it as one; a distant cloud can switch to its
    lower level of detail (MSFT_lod; Unity's _LOD0/_LOD1 names).

    \b
    Examples:
      fishgen sky --mode thick -o out/sky.glb
      fishgen sky --mode thin --seed 7 --area 600,600 --altitude 60,90 -o out/thin.glb
      fishgen sky --clouds params/clouds/table_4_4.awn --clouds params/clouds/sky.awa -o out/mixed.glb
      fishgen sky --mode medium --sun 1,0.2,0 --noise 0.8 -o out/evening.glb
    """,
    options=SkyOptions,
    run="fishgen.commands.sky:sky",
    output=Output("Output file: .glb or .gltf (nodes, levels of detail and the lighting need glTF)."),
)


@dataclass(frozen=True)
class SkyFacts:
    mode: str
    clouds: int
    particles: int
    distant_particles: int    # in the lower levels of detail, besides `particles`
    bytes: int
    seed: int


def sky(inputs: Sequence[Path], output: str | os.PathLike, options: SkyOptions = SkyOptions(),
        events: Events = QUIET) -> Made:
    """Build the sky and write it atomically; the summary says its clouds, particles and size."""
    inputs = COMMAND.given(inputs, options)
    from fishgen.commands.paths import check_inputs, check_targets, output_at_fault, read_beside
    from fishgen.errors import UsageError
    from fishgen.exchange import export
    from fishgen.exchange.clouds import check_output
    from fishgen.exchange.registry import FORMATS

    output = Path(output)
    if output.suffix.lower() not in (".glb", ".gltf"):
        raise UsageError(f"expected a .glb or .gltf output (a sky's nodes and levels of detail need glTF), "
                         f"found {output.suffix or 'no extension'!r}", output)
    models = tuple(Path(p) for p in options.clouds)
    kinds = check_inputs(models, "sky", [FORMATS["cubes"], FORMATS["texture cubes"]],
                         default=FORMATS["cubes"])
    check_targets([output], [*models, *read_beside(models, kinds, options.textures)])
    total = options.particles if options.particles is not None else MODES[options.mode].particles
    with output_at_fault():
        check_output(output, options.billboards, particles=total)
    from fishgen.clouds.memory import check_fits

    check_fits(total, output.suffix, options.billboards, sky=True)    # before anything is filled
    from fishgen.sky.build import build_sky, steps

    with events.progress("building the sky", steps(options.mode)) as bar:
        built = build_sky(options.mode, seed=options.seed, area=options.area, altitude=options.altitude,
                          models=models, noise=options.noise, particles=options.particles,
                          lighting=options.lighting,
                          shadow_map=options.shadow_map, billboards=options.billboards, lod=options.lod,
                          textures_dir=options.textures, max_particles=options.max_particles,
                          advance=bar.update)
    written = export(built.scene, output)
    size = sum(p.stat().st_size for p in written)
    sun = ",".join(f"{v:g}" for v in options.lighting.sun)
    line = (f"{output}: {built.mode} sky, {len(built.clouds)} clouds, {built.particles:,} particles"
            + (f" (+{built.distant_particles:,} in distant levels)" if built.distant_particles else "")
            + f", {f'{size / 1e6:.1f} MB' if size >= 50_000 else f'{size / 1e3:.0f} KB'}"  # not "0.0 MB"
            + f" (seed {options.seed}, sun {sun})")
    facts = SkyFacts(built.mode, len(built.clouds), built.particles, built.distant_particles, size,
                     options.seed)
    return Made(tuple(written), (*built.models, *built.textures), (line,), facts)
