"""Sampled species as files: the species text, its painted texture and fin mask, written atomically."""
from __future__ import annotations

import re
from pathlib import Path

from fishgen.errors import FishgenError


def sample_files(seed: int, stem: str) -> dict[str, bytes]:
    """File name -> bytes of sample ``seed`` written as ``stem``.txt/.png/_mask.png."""
    from dataclasses import replace

    from fishgen.authoring.painter import texture_files
    from fishgen.authoring.sampler import sample_species
    from fishgen.species.parser import parse_species
    from fishgen.species.writer import format_species

    sample = sample_species(seed, stem)
    sp = replace(sample.species, name=stem)
    text = format_species(sp, f"{stem}.png", f"{stem}_mask.png")
    parse_species(text, f"{stem}.txt")   # a sample the parser would refuse is a bug here, not the user's
    colour, mask = texture_files(sp, sample.palette, seed)
    return {f"{stem}.txt": text.encode(), f"{stem}.png": colour, f"{stem}_mask.png": mask}


def write_samples(seed: int, count: int, output: Path, folder: bool | None = None) -> list[Path]:
    """Write ``count`` sampled species from ``seed`` on: into the folder ``output`` when ``folder``
    (default: when it has no extension), else as the one species file ``output``."""
    from fishgen.atomic import write_files

    if folder is None:
        folder = not output.suffix
    if not folder:
        if count != 1 or output.suffix.lower() != ".txt":
            raise FishgenError(f"expected -o to name one species file (.txt) or a folder, found "
                               f"{output.name!r}")
        where, stems = output.parent, [_stem(output.stem)]
    else:
        if output.exists() and not output.is_dir():
            raise FishgenError("expected a folder, found a file", output)
        where, stems = output, [f"species_{seed + k}" for k in range(count)]
    written: list[Path] = []
    for k, stem in enumerate(stems):
        write_files({where / name: data for name, data in sample_files(seed + k, stem).items()})
        written.append(where / f"{stem}.txt")
    return written


def _stem(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_]+", "_", text).strip("_") or "species"
