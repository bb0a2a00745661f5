"""Make the committed seed corpus (fishgen/fuzz/seeds/, shipped as package data) from the
parameter files of a source checkout.

    python -m fishgen.fuzz.corpus [DEST]

Species and cube files are copied from params/; assets are built once with `fishgen build`
and `fishgen clouds` (8x8 textures and a 60-particle cloud keep the corpus small and the
readers fast), plus a few hand-written ASCII OBJ/PLY files for the text paths.
"""
from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

from fishgen.fuzz.inputs import DEFAULT_CORPUS
from fishgen.fuzz.mutate import png_bytes

#: The source checkout's params/ (an installed fishgen has none: it fuzzes with the corpus it ships).
PARAMS = Path(__file__).resolve().parents[2] / "params"
SMALL_CLOUD = b"60\n3\n20, 4.0, 3.0, 2.0, 0.0, 0.0, 0.0, 1.0\n20, 2.0, 2.0, 2.0, 5.0, 1.0, -2.0, 0.8\n" \
              b"20 3.0, 1.0, 1.0, -4.0, 0.5, 1.0, 0.5\n"
#: The thesis' Appendix B.10 sample as printed (the first line runs header, count and points together).
APPENDIX_B_FXL = """//dorsal 14 0.228515625 0.00390625 0.13671875 0.31640625
0.396484375 0.328125
0.439453125 0.1796875
0.181640625 0.29296875
0.22265625 0.2890625
0.263671875 0.29296875
0.3125 0.30078125
0.353515625 0.30859375
0.2265625 0.01953125
0.23046875 0.02734375
0.234375 0.0390625
0.244140625 0.046875
0.25 0.05859375
//anal
8
0.40625 0.875
0.37890625 0.71875
0.5390625 0.65625
0.59765625 0.76171875
0.431640625 0.69921875
0.486328125 0.6796875
0.41015625 0.84765625
0.41796875 0.83203125
"""
ASCII_PLY_CLOUD = """ply
format ascii 1.0
comment particles: position, radius, density, sRGB colour
element vertex 4
property float x
property float y
property float z
property float radius
property float density
property uchar red
property uchar green
property uchar blue
end_header
0 0 0 0.5 1 255 255 255
1 0 0 0.25 0.5 200 210 220
0 1 0 1.0 0.1 10 20 30
0 0 1 0.1 0.9 0 0 0
"""
ASCII_PLY_MESH = """ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
property uchar red
property uchar green
property uchar blue
property uchar alpha
element face 2
property list uchar int vertex_indices
end_header
0 0 0 255 0 0 255
1 0 0 0 255 0 255
1 1 0 0 0 255 128
0 1 0 255 255 255 0
3 0 1 2
3 0 2 3
"""
QUAD_OBJ = """mtllib quad.mtl
o quad
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
usemtl skin
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
usemtl glass
f 4/4/1 3/3/1 2/2/1
"""
QUAD_MTL = """newmtl skin
Kd 0.8 0.7 0.6
map_Kd skin.png
map_d -imfchan m skin.png
newmtl glass
Kd 1 1 1
d 0.4
"""


def make_corpus(dest: Path = DEFAULT_CORPUS) -> None:
    from fishgen.cli import main

    if not (PARAMS / "assets.toml").is_file():
        raise SystemExit(f"expected a source checkout's params/ at {PARAMS}, found none: the corpus is "
                         "made from it")
    if dest.exists():
        shutil.rmtree(dest)
    for sub in ("species", "cubes"):
        (dest / sub).mkdir(parents=True)
    for p in sorted(PARAMS.glob("*.txt")):
        shutil.copy(p, dest / "species" / p.name)
    for p in sorted((PARAMS / "clouds").glob("*.awn")):
        shutil.copy(p, dest / "cubes" / p.name)
    (dest / "cubes" / "small.awn").write_bytes(SMALL_CLOUD)

    with tempfile.TemporaryDirectory() as tmp:
        textures = Path(tmp) / "textures"
        textures.mkdir()
        for name in ("pineapplefish", "threadfingoldie"):
            for suffix in ("", "_mask"):
                (textures / f"{name}{suffix}.png").write_bytes(png_bytes(8, 8))
        cloud = Path(tmp) / "small.awn"
        cloud.write_bytes(SMALL_CLOUD)

        def run(*argv: str) -> None:
            try:
                main(list(argv))
            except SystemExit as stop:
                if stop.code:
                    raise RuntimeError(f"fishgen {' '.join(argv)} failed") from None

        fish = str(PARAMS / "pineapplefish.txt")
        for target, out in (("gltf", "pineapplefish_glb/pineapplefish.glb"),
                            ("gltf", "pineapplefish_gltf/pineapplefish.gltf"),
                            ("obj", "pineapplefish/pineapplefish.obj"),
                            ("ply", "pineapplefish/pineapplefish.ply")):
            path = dest / target / out
            path.parent.mkdir(parents=True, exist_ok=True)
            run("build", fish, "-o", str(path), "--textures", str(textures))
        for target, out, extra in (("gltf", "cloud_points/cloud.glb", ()),
                                   ("gltf", "cloud_billboards/cloud.glb", ("--billboards",)),
                                   ("ply", "cloud/cloud.ply", ())):
            path = dest / target / out
            path.parent.mkdir(parents=True, exist_ok=True)
            run("clouds", str(cloud), "-o", str(path), *extra)
    for folder, files in (("ply/ascii_cloud", {"cloud.ply": ASCII_PLY_CLOUD}),
                          ("ply/ascii_mesh", {"mesh.ply": ASCII_PLY_MESH}),
                          ("obj/quad", {"quad.obj": QUAD_OBJ, "quad.mtl": QUAD_MTL})):
        (dest / folder).mkdir(parents=True)
        for name, text in files.items():
            (dest / folder / name).write_text(text)
    (dest / "obj/quad/skin.png").write_bytes(png_bytes(4, 4))
    add_new_inputs(dest)


#: A scene file using every key of issue 24's school (couzin, variety, warm-up, pre-roll, length,
#: bounds) and a target path read from a CSV.
FULL_SCENE = """# Every scene key: couzin zones, variety, warm-up, pre-roll, length, bounds, a CSV path.
model = "couzin"
frames = 60
fps = 30
seed = 3
bounds = [[-3.0, -1.0, -3.0], [3.0, 1.0, 3.0]]
layout = "ring"
warmup = 1.0
preroll = 2.0
length = 0.3

[[species]]
file = "bonybream.txt"
count = 20
speed = 3.0

[[species]]
file = "threadfingoldie.txt"
count = 10

[target]
path = "path.csv"

[predator]
path = "figure8"
radius = 2.5
period = 20.0
centre = [0.0, 0.5, 0.0]

[couzin]
preset = "dynamic parallel"
repulsion = 0.75
blind_angle = 60.0
neighbours = 20

[variety]
size = 0.1
tints = 3
tint = 0.2
"""
PATH_CSV = "t,x,y,z\n0,0,0,0\n1,1,0.2,0\n2,1,0.4,1\n3,0,0.2,1\n4,0,0,0\n"


def add_new_inputs(dest: Path) -> None:
    """The inputs of issue 26's targets: scene files (+ a path CSV), the batch manifest, .FXL
    files, a small photo, the .awa texture cloud with 8x8 textures."""
    from PIL import Image

    from fishgen.authoring.photo.fxl import format_fxl
    from fishgen.species.parser import parse_species

    for sub in ("scene", "manifest", "fxl", "photo", "awa"):
        if (dest / sub).exists():
            shutil.rmtree(dest / sub)
        (dest / sub).mkdir(parents=True)
    for name in ("reef.toml", "bait-ball.toml"):
        shutil.copy(PARAMS / name, dest / "scene" / name)
    (dest / "scene" / "full.toml").write_text(FULL_SCENE)
    (dest / "scene" / "path.csv").write_text(PATH_CSV)
    for name in ("bonybream.txt", "threadfingoldie.txt"):   # the species the scene files name
        shutil.copy(PARAMS / name, dest / "scene" / name)
    shutil.copy(PARAMS / "assets.toml", dest / "manifest" / "assets.toml")
    for p in sorted(PARAMS.glob("*.txt")):
        sp = parse_species(p.read_text(), str(p))
        if sp.texture_points is not None:
            (dest / "fxl" / f"{p.stem}.fxl").write_text(format_fxl(sp.texture_points, sp.circle_sections))
    (dest / "fxl" / "appendix_b.fxl").write_text(APPENDIX_B_FXL)
    with Image.open(PARAMS / "photos" / "bonybream-side.png") as im:
        small = im.resize((160, 80), Image.Resampling.LANCZOS)
        small.save(dest / "photo" / "bonybream-side.png", optimize=True)
    shutil.copy(PARAMS / "clouds" / "sky.awa", dest / "awa" / "sky.awa")
    for name in ("billow", "cumulus", "wisp"):
        (dest / "awa" / f"{name}.png").write_bytes(png_bytes(8, 8))
    (dest / "awa" / "small.awn").write_bytes(SMALL_CLOUD)   # the editor's and sky's particle cloud


if __name__ == "__main__":
    make_corpus(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_CORPUS)
