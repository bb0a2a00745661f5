"""`fishgen build`: species file -> textured, fin-animated fish asset."""
from __future__ import annotations

from pathlib import Path

import click

FORMATS = ".glb, .gltf, .obj or .ply"


@click.command("build", context_settings={"show_default": True})
@click.argument("species_file", type=click.Path(dir_okay=False, path_type=Path))
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help=f"Output file; its extension picks the format ({FORMATS}). "
                   "[default: out/<species file name>.glb]")
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
def build(species_file: Path, output: Path | None, fins: str | None, length: float | None,
          fps: float, textures_dir: Path | None) -> None:
    """Build SPECIES_FILE (a VRFish parameter file) into a game-ready fish.

    glTF outputs carry the node hierarchy, materials, textures and a looping
    `swim` clip; OBJ and PLY carry the rest pose. Axes: +Y up, head towards +Z,
    metres. The output is written atomically: a failed run leaves no file.
    """
    from fishgen.assembly.fish import build_fish
    from fishgen.exchange import WRITERS, export
    from fishgen.errors import FishgenError
    from fishgen.species.parser import load_species

    if output is None:
        output = Path("out") / f"{species_file.stem}.glb"
    if output.suffix.lower() not in WRITERS:
        raise FishgenError(f"expected an output ending in {FORMATS}, found {output.name!r}")
    species = load_species(species_file, textures_dir)
    asset = build_fish(species, fins=fins, length=length, fps=fps)
    written = export(asset, output)
    lo, hi = asset.bounds()
    size = hi - lo
    click.echo(f"{output}: {asset.name}, {sum(len(p.mesh.faces) for p in asset.parts)} triangles, "
               f"{size[2]:.3f} m long, fins {asset.fin_mode}, swim loop {asset.clip_seconds:.2f} s"
               + (f" (+{len(written) - 1} files)" if len(written) > 1 else ""), err=True)
