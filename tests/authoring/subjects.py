"""Fish fishgen does not ship, to photograph (issue 25): sampled species and hand-made variants
with deep or slender bodies, forked or rounded tails and long dorsal fins.

Each subject is written as a species file with its painted texture and mask (the painter the
shipped textures use) into a folder, and loaded back, so it builds exactly as a user's file would.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from fishgen.authoring.painter import Palette
from fishgen.species.model import Species

PARAMS_DIR = Path(__file__).resolve().parents[2] / "params"
#: Sampled by `fishgen species --random --seed N`: a slender spline body, a deep one, a hawk.
SAMPLED = (7, 11, 104)


def _variant(base: str, **changes) -> Species:
    from fishgen.species.parser import load_species

    sp = load_species(PARAMS_DIR / f"{base}.txt")
    for key, value in changes.items():
        if isinstance(value, dict):
            changes[key] = replace(getattr(sp, key), **value)
    return replace(sp, texture_points=None, colour_texture=None, mask_texture=None, **changes)


def variants() -> dict[str, tuple[Species, Palette]]:
    """Hand-made variants of the shipped designs: what a photo of a real fish might show."""
    return {
        "deep": (_variant("centroberyx", shape_class="FishShapeAngel", shape_params=(),
                          scale=(0.22, 0.17, 0.06), dorsal={"start_length": 0.5, "proportion": 0.9}),
                 Palette((60, 60, 90), (220, 220, 235), (90, 90, 150), "bands", (20, 20, 30))),
        "slender": (_variant("threadfingoldie", scale=(0.14, 0.032, 0.018),
                             dorsal={"start_section": 8, "end_section": 16, "start_length": 0.8},
                             pelvic={"start_length": 0.2, "end_length": 0.5}),
                    Palette((40, 90, 60), (200, 230, 200), (120, 180, 120), "stripe", (240, 230, 60))),
        "forked": (_variant("bonybream", caudal={"top_line": 1.3, "bottom_line": 1.3, "middle_line": 0.2,
                                                 "top_angle": 32.0, "bottom_angle": 32.0}),
                   Palette((30, 70, 140), (225, 235, 245), (90, 140, 210), "scales", (240, 200, 40))),
        "rounded": (_variant("pineapplefish", body_sections=16, circle_sections=12,
                             dorsal={"start_section": 5, "end_section": 11},
                             anal={"start_section": 9, "end_section": 13},
                             pelvic={"start_section": 4, "end_section": 6},
                             pectoral={"start_section": 4},
                             caudal={"top_line": 0.55, "bottom_line": 0.55, "middle_line": 0.6,
                                     "top_angle": 50.0, "bottom_angle": 50.0,
                                     "top_triangles": 4, "bottom_triangles": 4}),
                    Palette((120, 60, 20), (240, 200, 150), (200, 120, 60), "spot", (20, 20, 20))),
        "long-dorsal": (_variant("bonybream", dorsal={"start_section": 3, "end_section": 13,
                                                      "start_length": 0.45, "end_length": 0.3,
                                                      "start_angle": 75.0, "proportion": 0.97},
                                 adipose={"start_length": 0.0, "end_length": 0.0}),
                        Palette((150, 30, 60), (245, 200, 210), (220, 90, 120), "bands", (60, 10, 20))),
    }


def shaped() -> dict[str, tuple[Species, Palette]]:
    """Issue 32's hand-shaped fish, for photos from Blender: a tall body, a long low one and a deep
    tail, none of them tuned on before."""
    return {
        "tall": (_variant("bonybream", shape_class="FishShapeSin", shape_params=(), scale=(0.2, 0.13, 0.05),
                          anal={"start_length": 0.5}),
                 Palette((110, 100, 40), (245, 240, 210), (180, 160, 70), "spot", (40, 30, 10))),
        "long": (_variant("centroberyx", scale=(0.4, 0.07, 0.04), body_sections=24,
                          dorsal={"start_section": 5, "end_section": 17},
                          anal={"start_section": 14, "end_section": 20},
                          pelvic={"start_section": 6, "end_section": 8},
                          pectoral={"start_section": 5}),
                 Palette((70, 80, 100), (215, 220, 230), (120, 130, 160), "stripe", (200, 60, 40))),
        "deep-tail": (_variant("pineapplefish", caudal={"top_line": 1.1, "bottom_line": 1.1,
                                                        "middle_line": 0.35, "top_angle": 62.0,
                                                        "bottom_angle": 62.0}),
                      Palette((160, 90, 20), (250, 225, 170), (230, 140, 40), "scales", (30, 20, 10))),
    }


def write_subjects(folder: Path, seeds: tuple[int, ...] = SAMPLED,
                   made: dict[str, tuple[Species, Palette]] | None = None) -> dict[str, Species]:
    """Every unseen subject (the samples of ``seeds`` and the ``made`` ones, by default
    :func:`variants`) written into ``folder`` and loaded back: name -> species."""
    from fishgen.authoring.painter import texture_files
    from fishgen.authoring.species_files import sample_files
    from fishgen.authoring.texture_points import project_texture_points
    from fishgen.species.parser import load_species
    from fishgen.species.writer import format_species

    folder.mkdir(parents=True, exist_ok=True)
    out = {}
    for seed in seeds:
        stem = f"sampled_{seed}"
        for name, data in sample_files(seed, stem).items():
            (folder / name).write_bytes(data)
        out[stem] = load_species(folder / f"{stem}.txt")
    for stem, (sp, palette) in (variants() if made is None else made).items():
        name = stem.replace("-", "_")
        sp = project_texture_points(replace(sp, name=name, textured=True), aspect=2.0)
        (folder / f"{name}.txt").write_text(format_species(sp, f"{name}.png", f"{name}_mask.png"))
        colour, mask = texture_files(sp, palette, 1)
        (folder / f"{name}.png").write_bytes(colour)
        (folder / f"{name}_mask.png").write_bytes(mask)
        out[stem] = load_species(folder / f"{name}.txt")
    return out
