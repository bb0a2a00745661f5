"""Generate the shipped species files and their colour + mask textures.

    python textures/generate.py        # rewrites params/*.txt (but BonyBream) and textures/*.png

BonyBream's texture points come from the thesis (Appendix A); the other three
species are designed here and get Fixel-style texture points from
``fishgen.authoring.texture_points``. Every texture is painted from its species' texture
points by ``fishgen.authoring.painter``, so fins and body land where the geometry
expects them. As VRFish did, the files are stored upside down (chapter 6); fishgen
flips them on load.
"""
from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fishgen.authoring.painter import texture_files  # noqa: E402
from fishgen.authoring.texture_points import project_texture_points  # noqa: E402
from fishgen.species.model import Behaviour, CaudalFin, PectoralFin, PelvicFin, Species, VerticalFin  # noqa: E402
from fishgen.species.parser import parse_species  # noqa: E402
from fishgen.species.writer import format_species  # noqa: E402

SIZE = (512, 256)   # fishgen.authoring.painter.SIZE


# ---------------------------------------------------------------- species designs
def _behaviour(speed: float) -> Behaviour:
    return Behaviour((0.000009, 0.0000075, 0.0000071), 0.04, 0.35, 0.01, 0.15, speed, 50.0, 0.0015,
                     (0.04, 10.0))


DESIGNS = {
    # Monocentris japonica: short, rotund, armoured; the thesis' low level of detail (8 x 6).
    "pineapplefish": dict(
        sp=Species(
            name="pineapplefish", world_scale=16.0, urge_factor=0.008, start_position=(2.0, 3.0, -8.0),
            cube_size=10.0, colour=(1.0, 0.78, 0.2), shape_class="FishShapeSpline",
            shape_params=(0.08, 0.36, 0.3, 0.5, 0.6, 0.44, 0.82, 0.24, 0.93, 0.12),
            body_sections=8, circle_sections=6, textured=True, masked=True, turn_test=False,
            catchfish_test=False, scale=(0.19, 0.13, 0.09),
            caudal=CaudalFin(0.42, 0.36, 40.0, 2, (0.92, 0.0, 0.0), 0.0, 0.42, 40.0, 2, 12.0, 1.5),
            adipose=VerticalFin(5, 6, 0.0, 0.0, 0.0, 0.5),
            dorsal=VerticalFin(2, 6, 0.45, 0.08, 80.0, 0.85),
            pelvic=PelvicFin(5, 2, 3, 0.5, 0.3, 60.0, 5.0, 1.25),
            anal=VerticalFin(4, 6, 0.3, 0.06, -70.0, 0.9),
            pectoral=PectoralFin(2, 1, 2, 0.45, 10.0, 0.7, 0.0, 8.0, 2.0),
            transparency=1.0, behaviour=_behaviour(0.5)),
        palette=dict(back=(150, 95, 20), belly=(255, 226, 120), fin=(240, 190, 70), pattern="scales",
                     accent=(60, 30, 10))),
    # Centroberyx affinis (redfish): deep perch-like body, big eye, blended fins, 32 x 24.
    "centroberyx": dict(
        sp=Species(
            name="centroberyx", world_scale=20.0, urge_factor=0.009, start_position=(-3.0, 5.0, -6.0),
            cube_size=10.0, colour=(0.85, 0.2, 0.15), shape_class="FishShapeSpline",
            shape_params=(0.06, 0.3, 0.25, 0.5, 0.5, 0.47, 0.78, 0.24, 0.92, 0.12),
            body_sections=32, circle_sections=24, textured=True, masked=False, turn_test=False,
            catchfish_test=False, scale=(0.4, 0.16, 0.07),
            caudal=CaudalFin(0.62, 0.3, 32.0, 4, (0.93, 0.0, 0.0), 0.0, 0.62, 32.0, 4, 9.0, 0.75),
            adipose=VerticalFin(20, 22, 0.0, 0.0, 0.0, 0.5),
            dorsal=VerticalFin(9, 24, 0.55, 0.12, 75.0, 0.93),
            pelvic=PelvicFin(19, 9, 12, 0.35, 0.45, 55.0, 6.0, 1.0),
            anal=VerticalFin(19, 26, 0.45, 0.1, -70.0, 0.88),
            pectoral=PectoralFin(8, 1, 4, 0.55, 12.0, 0.7, 0.0, 6.0, 1.5),
            transparency=0.6, behaviour=_behaviour(0.7)),
        palette=dict(back=(150, 20, 25), belly=(250, 150, 130), fin=(235, 70, 60), pattern="bands",
                     accent=(110, 10, 15))),
    # Threadfin goldie (an anthias): slender, orange, lyre tail and a threadlike dorsal, 24 x 16.
    "threadfingoldie": dict(
        sp=Species(
            name="threadfingoldie", world_scale=17.0, urge_factor=0.01, start_position=(0.0, 2.0, -4.0),
            cube_size=8.0, colour=(1.0, 0.55, 0.1), shape_class="FishShapeHawk", shape_params=(),
            body_sections=24, circle_sections=16, textured=True, masked=True, turn_test=False,
            catchfish_test=False, scale=(0.12, 0.05, 0.025),
            caudal=CaudalFin(1.3, 0.35, 28.0, 4, (0.94, 0.0, 0.0), 0.0, 1.3, 28.0, 4, 15.0, 2.5),
            adipose=VerticalFin(19, 20, 0.0, 0.0, 0.0, 0.5),
            dorsal=VerticalFin(5, 19, 1.3, 0.15, 62.0, 0.7),
            pelvic=PelvicFin(14, 6, 8, 0.3, 1.1, 70.0, 8.0, 2.0),
            anal=VerticalFin(14, 19, 0.6, 0.1, -60.0, 0.85),
            pectoral=PectoralFin(6, 2, 3, 0.8, 8.0, 0.72, 0.0, 10.0, 2.5),
            transparency=1.0, behaviour=_behaviour(0.9)),
        palette=dict(back=(220, 90, 10), belly=(255, 200, 120), fin=(255, 140, 40), pattern="stripe",
                     accent=(200, 40, 140))),
}
BONYBREAM_PALETTE = dict(back=(70, 90, 70), belly=(225, 225, 205), fin=(180, 170, 120), pattern="spot",
                         accent=(30, 40, 60))


def save_pair(sp: Species, palette: dict, seed: int, colour_name: str, mask_name: str) -> None:
    colour, mask = texture_files(sp, palette, seed)
    (ROOT / "textures" / colour_name).write_bytes(colour)
    (ROOT / "textures" / mask_name).write_bytes(mask)


def main() -> None:
    bony = parse_species((ROOT / "params" / "bonybream.txt").read_text(), "params/bonybream.txt")
    save_pair(bony, BONYBREAM_PALETTE, 1, "bonybream.png", "bonybream_mask.png")
    for seed, (name, design) in enumerate(DESIGNS.items(), start=2):
        sp = project_texture_points(design["sp"], aspect=SIZE[0] / SIZE[1])
        (ROOT / "params" / f"{name}.txt").write_text(
            format_species(sp, f"{name}.png", f"{name}_mask.png"))
        save_pair(sp, design["palette"], seed, f"{name}.png", f"{name}_mask.png")
        print(f"params/{name}.txt, textures/{name}.png, textures/{name}_mask.png")
    print("textures/bonybream.png, textures/bonybream_mask.png")


if __name__ == "__main__":
    main()
