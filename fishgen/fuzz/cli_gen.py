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


# -- issue 26: `fishgen texture` photos, `fishgen sky` / `fishgen fly` options, build --lods/--clips ------
def texture_case(seeds, rng: random.Random) -> tuple[dict[str, bytes | int], list[str]]:
    """`fishgen texture photo.png -s base.txt -o new.txt`: a generated photo (odd sizes, aspect ratios,
    modes, truncated) and its options, sometimes a mutated --fxl-in or a --mask."""
    from fishgen.fuzz import structured

    photo = seeds.new["photo"]["bonybream-side.png"]
    base = rng.choice(seeds.species)
    files: dict[str, bytes | int] = {"photo.png": structured.photo_bytes(photo, rng),
                                     "base.txt": base.encode("utf-8"), **_tiny_textures(base)}
    out = rng.choice(["new.txt"] * 8 + ["new", "sub/new.txt", "new.png"])
    argv = ["texture", "photo.png", "-s", "base.txt", "-o", out]
    if rng.random() < 0.3:
        argv += ["--body-sections", _val(rng, INTS + ["3", "4", "5", "7", "256", "257"],
                                         ["3", "4", "7", "12"])]
    if rng.random() < 0.3:
        argv += ["--circle-sections", _val(rng, INTS + ["3", "4", "256", "257"], ["3", "6", "12"])]
    if rng.random() < 0.2:
        argv += ["--spacing", rng.choice(["projected", "even", "", "odd"])]
    if rng.random() < 0.1:
        argv.append("--fit-shape")
    if rng.random() < 0.15:
        texts = seeds.texts("fxl", ".fxl")
        fxl = rng.choice(texts) if rng.random() < 0.4 else structured.fxl_text(texts, rng)
        files["in.fxl"] = fxl.encode("utf-8", "surrogatepass")
        argv += ["--fxl-in", rng.choice(["in.fxl"] * 6 + ["missing.fxl", ".", "photo.png"])]
    if rng.random() < 0.1:
        argv += ["--fxl-out", rng.choice(["out.FXL", "out.fxl", "photo.png", "base.txt", "."])]
    if rng.random() < 0.08:
        files["mask.png"] = structured.photo_bytes(photo, rng)
        argv += ["--mask", "mask.png"]
    if rng.random() < 0.03:
        argv += ["--compare", rng.choice(["cmp.png", "cmp.txt"])]
    return files, argv


LODS = ["8x6", "8x6,4x4", "16x12,8x6,4x4", "3x3", "2x2", "0x0", "256x256", "257x3", "3x257", "1000x1000",
        "8x6,8x6", "4x4,8x6", "8x6,", ",", "", "8X6", "8x", "x6", "8x6x2", "-8x6", "1e1x6", "8.5x6", "８x６",
        "8x6;4x4", "99999999999999999999x3", ",".join(["8x6"] * 100), "8 x 6", " 8x6", "8x6,4x4,3x3,3x3",
        "64x64,32x32,16x16,8x8,4x4,3x3", "nanx6", "8×6"]
CLIPS = ["swim", "idle", "sprint", "turn_left,turn_right", "burst", "swim,swim", "", ",", "Swim", "swim,",
         "fly", "swim,idle,sprint,turn_left,turn_right,burst", "swim ", "\x00", "swim;idle",
         ",".join(["swim"] * 1000), "idle,burst", "turn_left"]
PAIRS = ["400,400", "1,1", "0,0", "-1,5", "1e6,1e6", "1e7,1e7", "nan,1", "inf,1", "1,2,3", "1", "", "x,y",
         "1e309,1", "0.001,0.001", "100,100"]
ALTITUDES = ["40,80", "0,0", "80,40", "-10,10", "1e6,1e7", "nan,1", "1", "", "0,1e308", "5,5"]
TRIPLES = ["1,0.4,0.2", "0,0,0", "0,1,0", "1e308,1e308,1e308", "nan,0,0", "inf,1,1", "1,2", "1,2,3,4", "",
           "x,y,z", "-1,-1,-1", "1e-300,0,0"]


def _light(rng: random.Random, argv: list[str]) -> None:
    for opt, pool, good in (("--sun", TRIPLES, ["1,0.4,0.2", "0,1,0"]), ("--sun-color", TRIPLES, ["1,1,1"]),
                            ("--sky-color", TRIPLES, ["0.2,0.3,0.4"]),
                            ("--albedo", FLOATS, ["0.9", "0", "1"]), ("--extinction", FLOATS, ["1", "8"]),
                            ("--solid-angle", FLOATS, ["0.1", "0.5"]),
                            ("--anisotropy", FLOATS + ["0.99", "-0.99"], ["0.5", "0"])):
        if rng.random() < 0.08:
            argv += [opt, _val(rng, pool, good)]
    if rng.random() < 0.05:
        argv.append(rng.choice(["--scattering", "--no-scattering"]))


def options_case(seeds, rng: random.Random) -> tuple[dict[str, bytes | int], list[str]]:
    """`fishgen sky` (small --particles, so each run is fast), `fishgen fly` (never served: the runner
    stops it where it would bind its server) and `fishgen build --lods/--clips`."""
    command = rng.choices(["sky", "fly", "build"], [4, 3, 3])[0]
    files: dict[str, bytes | int] = {}
    awa = seeds.new["awa"]
    if command == "build":
        text = rng.choice(seeds.species)
        files["fish.txt"] = text.encode("utf-8")
        files.update(_tiny_textures(text))
        argv = ["build", "fish.txt", "-o", rng.choice(["out.glb", "out.glb", "out.gltf", "out.obj",
                                                       "out.ply"])]
        if rng.random() < 0.7:
            argv += ["--lods", rng.choice(LODS)]
        if rng.random() < 0.7:
            argv += ["--clips", rng.choice(CLIPS)]
        for flag in ("--merge", "--compact"):
            if rng.random() < 0.2:
                argv.append(flag)
        if rng.random() < 0.1:
            argv += ["--swim", rng.choice(["body", "fins", "tail"])]
        return files, argv
    inputs: list[str] = []
    for _ in range(rng.choice([0, 0, 1, 1, 2])):
        kind = rng.choice(["small.awn", "sky.awa", "mutant.awn", "mutant.awa", "missing.awn", "fish.txt"])
        if kind in ("small.awn", "sky.awa"):
            files[kind] = awa[kind]
        elif kind == "mutant.awn":
            files[kind] = mutate.cubes_bytes([awa["small.awn"]], rng)
        elif kind == "mutant.awa":
            from fishgen.fuzz.structured import awa_bytes
            files[kind] = awa_bytes([awa["sky.awa"]], rng)
        elif kind == "fish.txt":
            files[kind] = seeds.species[0].encode("utf-8")
        inputs.append(kind)
    if any(n.endswith(".awa") for n in inputs):
        for name in ("billow", "cumulus", "wisp"):
            files[f"{name}.png"] = mutate.png_bytes(8, 8)
        for n in inputs:  # the names in the shipped file are clouds/NAME.png: resolve them beside it
            if n.endswith(".awa") and isinstance(files[n], bytes):
                files[n] = files[n].replace(b"clouds/", b"")  # type: ignore[union-attr]
    if command == "sky":
        argv = ["sky", "-o", rng.choice(["out.glb"] * 6 + ["out.gltf", "out.obj", "out", "out.ply"])]
        argv += ["--particles", _val(rng, ["0", "-1", "50000001", "1e3", "x", "", "1", "2"],
                                     ["200", "500", "1000", "60", "16", "2000"])]
        for flag in inputs:
            argv += ["--clouds", flag]
        if rng.random() < 0.5:
            argv += ["--mode", rng.choice(["thin", "thin", "medium", "thick", "", "THIN", "dense"])]
        if rng.random() < 0.3:
            argv += ["--area", _val(rng, PAIRS, ["400,400", "100,100"])]
        if rng.random() < 0.3:
            argv += ["--altitude", _val(rng, ALTITUDES, ["40,80", "5,5"])]
        if rng.random() < 0.3:
            argv += ["--seed", _val(rng, INTS, ["0", "7"])]
        if rng.random() < 0.3:
            argv += ["--noise", _val(rng, FLOATS + ["0.9", "0.9001"], ["0", "0.5", "0.9"])]
        if rng.random() < 0.2:
            argv += ["--shadow-map", rng.choice(["cloud", "sky", "sky", "", "none"])]
        if rng.random() < 0.2:
            argv.append(rng.choice(["--lod", "--no-lod"]))
        if rng.random() < 0.15:
            argv.append("--billboards")
        if rng.random() < 0.15:
            argv += ["--max-particles", _val(rng, INTS, ["1", "100", "5000"])]
        if rng.random() < 0.1:
            argv += ["--textures", rng.choice([".", "missing", "/", "..", "small.awn"])]
        _light(rng, argv)
        return files, argv
    # fly: every option path up to where it would serve (the runner stops it there)
    argv = ["fly", *inputs]
    if rng.random() < 0.4:
        argv += ["--mode", rng.choice(["thin", "medium", "thick", "", "THICK", "1"])]
    if rng.random() < 0.4:
        argv += ["--size", rng.choice(["800x600", "1x1", "0x0", "16384x16384", "16385x2", "800", "800x",
                                       "x600", "-800x600", "800x600x1", "1e3x1e3", "800X600", "８00x600", "",
                                       " 800x600", "99999999999999999999x1", "nanxnan", "800×600"])]
    if rng.random() < 0.4:
        argv += ["--timeout", _val(rng, FLOATS + ["86400", "86400.001"], ["1", "10", "0.5", "86400"])]
    if rng.random() < 0.35:
        argv += ["--report", rng.choice(["r.json", "r.csv", "r.txt", "r", "small.awn", ".", "sub/r.json",
                                         "r.JSON", ""])]
    if rng.random() < 0.2:
        argv.append("--headless")
    if rng.random() < 0.25:
        argv += ["--warmup", _val(rng, FLOATS, ["0", "2", "600"])]
    if rng.random() < 0.3:
        argv += ["--cloud-resolution", _val(rng, FLOATS + ["0.1", "0.0999", "1.0001"], ["0.1", "0.5", "1"])]
    if rng.random() < 0.15:
        argv += ["--webgl", rng.choice(["swiftshader", "llvmpipe", "", "gpu"])]
    if rng.random() < 0.15:
        argv += ["--seed", _val(rng, INTS, ["0", "5"])]
    if rng.random() < 0.15:
        argv += ["--port", _val(rng, INTS + ["65535", "65536", "80"], ["0"])]
    if rng.random() < 0.1:
        argv += ["--max-particles", _val(rng, INTS, ["1", "100"])]
    if rng.random() < 0.05:
        argv += ["-o", "x.glb"]
    _light(rng, argv)
    return files, argv
