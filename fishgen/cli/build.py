"""`fishgen build`: species files -> textured, fin-animated fish assets."""
from __future__ import annotations

from pathlib import Path

import click

from fishgen.assembly.fin_modes import FIN_MODES
from fishgen.assembly.swim_modes import DEFAULT_SPEED, SWIM_MODES
from fishgen.cli.common import error_line
from fishgen.cli.params import FiniteRange
from fishgen.exchange.registry import MESHES, extensions, formats

FISH_FORMATS = formats(writable=True, holding=[MESHES])


@click.command("build", context_settings={"show_default": True})
@click.argument("species_files", nargs=-1, required=True,
                type=click.Path(path_type=Path), metavar="SPECIES_FILE...")
@click.option("-o", "--output", type=click.Path(path_type=Path), default=None,
              help=f"Output file for one species (its extension picks the format: "
                   f"{', '.join(extensions(FISH_FORMATS))}), or a folder for several. "
                   "[default: out/<species file stem>.<format>]")
@click.option("--format", "fmt", type=click.Choice([f.name for f in FISH_FORMATS]), default="glb",
              help="Format when writing into a folder.")
@click.option("--fins", type=click.Choice(FIN_MODES), default=None,
              help="Fin technique (thesis ch. 5): translucent, mask cut-out or opaque. "
                   "[default: mask if the file says masked, else blend]")
@click.option("--length", type=FiniteRange(0.001, 1e4), default=None,
              metavar="METRES",
              help="Nose-to-tail length in metres. [default: world scale x scaleX x 0.05 m for the body]")
@click.option("--fps", type=FiniteRange(1, 1000), default=30.0,
              help="Frames per second; fins move step size degrees per frame.")
@click.option("--swim", type=click.Choice(SWIM_MODES), default="body",
              help="body: a travelling body wave (carangiform, tail-beat frequency from --speed) under "
                   "the fin swings; fins: a rigid body, only the fins move (VRFish's fish).")
@click.option("--speed", type=FiniteRange(0.01, 100), default=DEFAULT_SPEED, metavar="BL/S",
              help="Cruising speed of the swim loop in body lengths per second; the tail beats at "
                   "Strouhal number 0.3, rounded to a whole number of beats in the loop.")
@click.option("--textures", "textures_dir", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Folder texture names resolve in (and may not leave). "
                   "[default: the species file's folder, then the textures/ folder beside it]")
def build(species_files: tuple[Path, ...], output: Path | None, fmt: str, fins: str | None,
          length: float | None, fps: float, swim: str, speed: float, textures_dir: Path | None) -> None:
    """Build SPECIES_FILE (VRFish parameter files) into game-ready fish.

    glTF outputs carry the node hierarchy, materials, textures and a looping
    `swim` clip; OBJ and PLY carry the rest pose. Axes: +Y up, head towards +Z,
    metres. Outputs are written atomically: a failed run leaves no file. With
    several species every good file is built, each bad one is reported on its
    own line, and the exit status is non-zero if any failed.
    """
    from fishgen.assembly.fish import build_fish
    from fishgen.cli.params import check_inputs
    from fishgen.errors import FishgenError
    from fishgen.exchange import export
    from fishgen.exchange.registry import FORMATS, by_extension, output_format
    from fishgen.species.parser import load_species

    check_inputs(species_files, "build", [FORMATS["species"]], default=FORMATS["species"])
    suffix = output.suffix.lower() if output is not None else ""
    single_file = len(species_files) == 1 and output is not None and by_extension(output) is not None
    if single_file:
        output_format(output, [MESHES])  # type: ignore[arg-type]
    elif len(species_files) == 1 and suffix:
        output_format(output, [MESHES], what="output (or a folder)")  # type: ignore[arg-type]
    folder = output if output is not None else Path("out")
    if len(species_files) > 1:
        if output is not None and by_extension(output) is not None:
            raise FishgenError(f"expected a folder for {len(species_files)} species files, found "
                               f"{output.name!r} (name a folder and pick the format with --format)")
        seen: dict[str, Path] = {}
        for species_file in species_files:
            if species_file.stem in seen:
                raise FishgenError(f"expected species files with distinct names for one folder, found "
                                   f"{seen[species_file.stem]} and {species_file} (both make "
                                   f"{species_file.stem}.{fmt})")
            seen[species_file.stem] = species_file

    failures = 0
    for species_file in species_files:
        target = output if single_file else folder / f"{species_file.stem}.{fmt}"
        try:
            scene = build_fish(load_species(species_file, textures_dir), fins=fins, length=length, fps=fps,
                               swim=swim, speed=speed)
            written = export(scene, target, require=[MESHES])  # type: ignore[arg-type]
        except FishgenError as err:
            if len(species_files) == 1:
                raise
            # each bad file on its own line, as --json asks: the others still build
            click.echo(error_line(str(err), 2, file=err.file, line=err.line), err=True)
            failures += 1
            continue
        click.echo(summary(scene, target, written))  # type: ignore[arg-type]
    if failures:
        raise SystemExit(2)


def summary(scene, target: Path, written: list[Path]) -> str:
    """One line: what was built, and what the format could not keep (said once)."""
    from fishgen.exchange.registry import by_extension, lost
    from fishgen.scene.pose import bounds

    lo, hi = bounds(scene)
    fmt = by_extension(target)
    dropped = lost(fmt, scene) if fmt is not None else []
    clip = scene.clip("swim")
    animated = clip is not None and "node animation" not in dropped
    motion = (f"swim loop {clip.duration:.2f} s" if animated and clip is not None
              else "rest pose only" if clip is not None else "no animation")
    if animated and "tail_beat_hz" in scene.info:
        motion += f", body wave {scene.info['tail_beat_hz']:.2f} Hz"
    listed = ", ".join(dropped[:-1]) + (" or " if len(dropped) > 1 else "") + dropped[-1] if dropped else ""
    note = f" ({fmt.extensions[0][1:].upper()} holds no {listed})" if dropped and fmt else ""
    return (f"{target}: {scene.name}, {scene.counts()['triangles']} triangles, {hi[2] - lo[2]:.3f} m long, "
            f"fins {scene.info.get('fin_mode')}, {motion}{note}"
            + (f" (+{len(written) - 1} files)" if len(written) > 1 else ""))
