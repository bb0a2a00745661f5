"""CLI cases: `fishgen build/clouds/preview` argv with mutated option values.

Most cases are meant to be refused by option validation (cheap); a few are valid and do
the work, with tiny sizes (previews are 16..32 px a side) so renders stay fast.
"""
from __future__ import annotations

import random

from fishgen.fuzz import mutate

FLOATS = ["0", "-0", "1e-300", "5e-324", "1e-9", "0.001", "0.5", "1", "12", "30", "59.9", "60", "60.0001",
          "120", "999", "1000", "1000.0001", "9999", "1e4", "1e6", "1e300", "1e309", "nan", "NaN", "inf",
          "-inf", "-1", "", " ", "x", "1,5", "0x10", "1_0", "１"]
INTS = ["0", "1", "2", "3", "-1", "1000", "1001", "9223372036854775808", "99999999999999999999", "1.5",
        "", "x", "1e3"]


def _val(rng: random.Random, pool: list[str], good: list[str]) -> str:
    return rng.choice(good) if rng.random() < 0.4 else rng.choice(pool)


def cli_case(seeds, rng: random.Random) -> tuple[dict[str, bytes | int], list[str]]:
    command = rng.choices(["build", "clouds", "preview"], [4, 3, 3])[0]
    files: dict[str, bytes | int] = {}
    if command == "build":
        text = rng.choice(seeds.species)
        if rng.random() < 0.35:
            text = mutate.species_text(seeds.species, rng)
        files["fish.txt"] = text.encode("utf-8", "surrogatepass")
        files.update(_tiny_textures(text))
        argv = ["build", "fish.txt"]
        out = rng.choice(["out.glb", "out.glb", "out.gltf", "out.obj", "out.ply", "out.png", "out", "out.GLB",
                          "out.csv", "sub/out.glb", ""])
        if out:
            argv += ["-o", out]
        if rng.random() < 0.5:
            argv += ["--fps", _val(rng, FLOATS, ["30", "1", "0.5", "60", "1000", "1e-9", "1e-300"])]
        if rng.random() < 0.4:
            argv += ["--length", _val(rng, FLOATS, ["0.3", "1", "1e-9", "9999", "1e-300"])]
        if rng.random() < 0.3:
            argv += ["--fins", rng.choice(["blend", "mask", "opaque", "cutout", ""])]
        if rng.random() < 0.1:
            argv += ["--format", rng.choice(["glb", "gltf", "obj", "ply", "png", ""])]
        if rng.random() < 0.1:
            argv += ["--textures", rng.choice([".", "missing", "fish.txt", "/", ".."])]
        return files, argv
    if command == "clouds":
        n = rng.choice([1, 1, 1, 2])
        names = []
        for k in range(n):
            data = rng.choice(seeds.cubes)
            if rng.random() < 0.4:
                data = mutate.cubes_bytes(seeds.cubes, rng)
            names.append(f"c{k}.awn")
            files[names[-1]] = data
        argv = ["clouds", *names, "-o", rng.choice(["out.ply", "out.glb", "out.gltf", "out.csv", "out.npy",
                                                    "out.obj", "out", "out.PLY"])]
        if rng.random() < 0.6:  # keep the fill small: the bundled cube files hold 2000 particles
            argv += ["--max-particles", _val(rng, INTS, ["2000", "5000", "1"])]
        else:
            argv += ["--max-particles", "5000"]
        if rng.random() < 0.4:
            argv += ["--seed", _val(rng, INTS, ["0", "7"])]
        if rng.random() < 0.3:
            argv += ["--method", rng.choice(["paper", "uniform", "gauss", ""])]
        if rng.random() < 0.2:
            argv.append("--billboards")
        for _ in range(rng.choice([0, 0, 1, n, 3])):
            argv += ["--offset", rng.choice(["0,0,0", "1,2,3", "1e38,0,0", "3.5e38,0,0", "nan,0,0", "inf,1,1",
                                             "1,2", "1,2,3,4", "", "x,y,z", "1e300,1e300,1e300", "-0,-0,-0"])]
        return files, argv
    # preview: inputs from the seed files; options mostly invalid so that few cases render
    kind = rng.choice(["species", "cubes"])
    if kind == "species":
        text = rng.choice(seeds.species)
        files["fish.txt"] = text.encode("utf-8")
        files.update(_tiny_textures(text))
        inputs = ["fish.txt"]
    else:
        files["cloud.awn"] = rng.choice(seeds.cubes)
        inputs = ["cloud.awn"]
    out = rng.choice(["out.png", "out.png", "out.gif", "out.webp", "out.jpg", "out.bmp", "out", "out.PNG"])
    argv = ["preview", *inputs, "-o", out]
    render = rng.random() < 0.15  # the rest break at least one option
    size = rng.choice(["16x16", "32x32", "24x16"]) if render else rng.choice([
        "16x16", "15x16", "0x0", "8192x8193", "32", "32x", "x32", "-32x32", "32x32x32", "1e3x1e3",
        "32X32", " 32x32", "32×32", "99999999999999999999x32", "", "8192x8192", "32x0", "nanxnan"])
    argv += ["--size", size]
    bad = {
        "--fps": ["0", "0.5", "60.0001", "nan", "inf", "-1", "1e309", ""],
        "--frames": ["0", "1001", "-1", "1.5", "", "99999999999999999999"],
        "--duration": ["0", "-1", "600.0001", "nan", "inf", "1e309", ""],
        "--time": ["-1", "1e6", "nan", "inf", "1e309", ""],
        "--columns": ["0", "-1", "1.5", ""],
        "--background": ["#12345", "#gggggg", "", "transparentx", "#1234567890", "rgb(1,2,3)", "nan"],
        "--view": ["sideways", "", "SIDE"],
        "--seed": ["-1", "1.5", "", "99999999999999999999"],
        "--clip": ["", "missing", "\x00", "swim" * 100],
    }
    good = {"--fps": ["1", "12", "60", "1.5"], "--frames": ["1", "2"], "--duration": ["0.1", "1", "600"],
            "--time": ["0", "0.5", "999999"], "--columns": ["1", "3", "1000000"],
            "--background": ["#000000", "transparent", "white", "#11223344"],
            "--view": ["side", "top", "front", "three-quarter"], "--seed": ["0", "3"],
            "--clip": ["swim"]}
    options = rng.sample(sorted(good), rng.choice([0, 1, 2, 3]))
    broken = None if render else rng.choice(options or ["--size"])
    for opt in options:
        argv += [opt, rng.choice(bad[opt]) if opt == broken or rng.random() < 0.2 and not render
                 else rng.choice(good[opt])]
    if render and "--frames" in argv and out not in ("out.gif", "out.webp"):
        argv[argv.index("--frames") + 1] = "1"
    return files, argv


def _tiny_textures(text: str) -> dict[str, bytes | int]:
    """The species file's texture names as 8x8 PNGs beside it (builds need them, and small is fast)."""
    names: dict[str, bytes | int] = {}
    for line in text.splitlines():
        words = line.split()
        if len(words) == 2 and all(w.lower().endswith(".png") for w in words):
            for w in words:
                if "/" not in w and "\\" not in w and w not in ("..", "."):
                    names[w] = mutate.png_bytes(8, 8)
    return names
