"""`fishgen build`: species files -> textured, fin-animated fish assets."""
from __future__ import annotations

from pathlib import Path

import click

FORMATS = ("glb", "gltf", "obj", "ply")


@click.command("build", context_settings={"show_default": True})
@click.argument("species_files", nargs=-1, required=True,
                type=click.Path(dir_okay=False, path_type=Path), metavar="SPECIES_FILE...")
@click.option("-o", "--output", type=click.Path(path_type=Path), default=None,
              help="Output file for one species (its extension picks the format: .glb, .gltf, .obj, "
                   ".ply), or a folder for several. [default: out/<species file stem>.<format>]")
@click.option("--format", "fmt", type=click.Choice(FORMATS), default="glb",
              help="Format when writing into a folder.")
@click.option("--fins", type=click.Choice(["blend", "mask", "opaque"]), default=None,
              help="Fin technique (thesis ch. 5): translucent, mask cut-out or opaque. "
                   "[default: mask if the file says masked, else blend]")
@click.option("--length", type=float, default=None, metavar="METRES",
              help="Nose-to-tail length in metres. [default: world scale x scaleX x 0.05 m for the body]")
@click.option("--fps", type=float, default=30.0,
              help="Frames per second; fins move step size degrees per frame.")
@click.option("--textures", "textures_dir", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Folder texture names resolve in (and may not leave). "
                   "[default: the species file's folder, then the textures/ folder beside it]")
def build(species_files: tuple[Path, ...], output: Path | None, fmt: str, fins: str | None,
          length: float | None, fps: float, textures_dir: Path | None) -> None:
    """Build SPECIES_FILE (VRFish parameter files) into game-ready fish.

    glTF outputs carry the node hierarchy, materials, textures and a looping
    `swim` clip; OBJ and PLY carry the rest pose. Axes: +Y up, head towards +Z,
    metres. Outputs are written atomically: a failed run leaves no file. With
    several species every good file is built, each bad one is reported on its
    own line, and the exit status is non-zero if any failed.
    """
    from fishgen.assembly.fish import build_fish
    from fishgen.errors import FishgenError
    from fishgen.exchange import WRITERS, export
    from fishgen.species.parser import load_species

    single_file = (len(species_files) == 1 and output is not None
                   and output.suffix.lower() in WRITERS)
    if len(species_files) == 1 and output is not None and output.suffix and not single_file:
        raise FishgenError(f"expected an output ending in {', '.join(WRITERS)} (or a folder), "
                           f"found {output.name!r}")
    folder = output if output is not None else Path("out")
    if len(species_files) > 1:
        if output is not None and output.suffix.lower() in WRITERS:
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
            asset = build_fish(load_species(species_file, textures_dir), fins=fins, length=length, fps=fps)
            written = export(asset, target)
        except FishgenError as err:
            if len(species_files) == 1:
                raise
            click.echo(str(err), err=True)
            failures += 1
            continue
        lo, hi = asset.bounds()
        click.echo(f"{target}: {asset.name}, {sum(len(p.mesh.faces) for p in asset.parts)} triangles, "
                   f"{hi[2] - lo[2]:.3f} m long, fins {asset.fin_mode}, swim loop {asset.clip_seconds:.2f} s"
                   + (f" (+{len(written) - 1} files)" if len(written) > 1 else ""), err=True)
    if failures:
        raise SystemExit(2)
