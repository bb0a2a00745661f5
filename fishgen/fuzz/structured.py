"""Structure-aware generators for the inputs of the newer commands (issue 26).

Each takes valid seeds from the corpus and a ``random.Random`` and returns a new input: school
scene TOML (and their target/predator path CSVs), batch manifests, `.FXL` point files, photos for
`fishgen texture`, `.awa` texture cloud files, and HTTP requests to the editor's server. TOML
inputs are mutated as data (keys deleted, values replaced by edge values of every TOML type,
known optional tables added, unknown keys) and written back with :func:`toml_text`, then
sometimes damaged as text. Nothing here touches the disk.
"""

from __future__ import annotations

import copy
import io
import json
import math
import random
from typing import Any

from fishgen.fuzz import mutate

# -- TOML ------------------------------------------------------------------------------------------
BIG_INT = int("9" * 400)
TOML_VALUES: list[Any] = [
    0,
    1,
    -1,
    2,
    3,
    7,
    1000,
    100_000,
    100_001,
    2**31,
    2**63 - 1,
    -(2**63),
    10**12,
    0.0,
    -0.0,
    1e-300,
    5e-324,
    0.001,
    0.05,
    0.5,
    1.5,
    3.0,
    20.0,
    20.0001,
    360.0,
    1e4,
    1.0001e4,
    1e6,
    1e300,
    math.nan,
    math.inf,
    -math.inf,
    True,
    False,
    "",
    "x",
    "nan",
    "1",
    "circle",
    "figure8",
    "spline",
    "none",
    "sphere",
    "box",
    "line",
    "ring",
    "boids",
    "pso",
    "couzin",
    "torus",
    "swarm",
    "dynamic parallel",
    "../secret.txt",
    "/etc/passwd",
    "missing.txt",
    "bonybream.txt",
    "path.csv",
    "../path.csv",
    "a" * 300,
    "\u0000",
    "é",
    "\U0001f41f",
    [],
    [0],
    [1, 2, 3],
    [[0, 0, 0], [1, 1, 1]],
    [[1, 1, 1], [0, 0, 0]],
    [[-1e308, 0, 0], [1e308, 1, 1]],
    [math.nan, 0, 0],
    ["a", "b"],
    [1, "a"],
    {},
    {"x": 1},
    [{}],
]
#: A TOML integer of thousands of digits (int-string limit), written as a raw token.
HUGE_INT_TOKENS = ["9" * 5000, "-" + "9" * 4301, "1" + "0" * 4300, "0x" + "f" * 1200]


MAX_TABLES = 2000
"""Most entries an array of tables is repeated to: a manifest of 2,000 jobs tests the size, and
the mutants stay small enough to generate in milliseconds (the generator's time is the case's)."""


class RawToken(str):
    """A value written into the TOML text verbatim (numbers TOML parsers choke on)."""


def toml_value(value: Any) -> str:
    if isinstance(value, RawToken):
        return str(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value) if abs(value) < 10**4000 else str(value)[:4000]
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_key(k)} = {toml_value(v)}" for k, v in value.items()) + "}"
    return json.dumps(str(value))


def _key(key: str) -> str:
    if key and all(c.isalnum() and c.isascii() or c in "-_" for c in key):
        return key
    return json.dumps(key, ensure_ascii=False)


def toml_text(doc: dict[str, Any]) -> str:
    """``doc`` as TOML: top-level values, then ``[table]`` and ``[[array of tables]]``."""
    head, tail = [], []
    for k, v in doc.items():
        if isinstance(v, dict) and not isinstance(v, RawToken):
            tail.append(f"\n[{_key(k)}]")
            tail += [f"{_key(kk)} = {toml_value(vv)}" for kk, vv in v.items()]
        elif isinstance(v, list) and v and all(isinstance(e, dict) for e in v):
            for e in v:
                tail.append(f"\n[[{_key(k)}]]")
                tail += [f"{_key(kk)} = {toml_value(vv)}" for kk, vv in e.items()]
        else:
            head.append(f"{_key(k)} = {toml_value(v)}")
    return "\n".join(head + tail) + "\n"


def _containers(doc: Any, out: list) -> list:
    """(container, key) pairs of every value in ``doc``."""
    if isinstance(doc, dict):
        for k, v in doc.items():
            out.append((doc, k))
            _containers(v, out)
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            out.append((doc, i))
            _containers(v, out)
    return out


def _edge_value(rng: random.Random, old: Any = None) -> Any:
    roll = rng.random()
    if isinstance(old, (int, float)) and not isinstance(old, bool) and roll < 0.35:
        factor = rng.choice([0, -1, 10, 0.1, 1e3, 1e-3, 1e6, 1e30, 2, 0.5, 1.0001, 0.9999])
        new = old * factor
        return int(new) if isinstance(old, int) and abs(new) < 1e18 else float(new)
    if roll < 0.05:
        return RawToken(rng.choice(HUGE_INT_TOKENS))
    return copy.deepcopy(rng.choice(TOML_VALUES))


def mutate_doc(doc: dict[str, Any], rng: random.Random, additions: list[tuple[list[str], Any]]) -> None:
    """1-5 mutations of a TOML document in place; ``additions`` are (path, value) pairs of known
    optional keys and tables that may be added."""
    for _ in range(rng.choice([1, 1, 2, 3, 5])):
        op = rng.random()
        places = _containers(doc, [])
        if op < 0.35 and places:
            parent, key = rng.choice(places)
            parent[key] = _edge_value(rng, parent[key])
        elif op < 0.45 and places:
            parent, key = rng.choice(places)
            del parent[key]
        elif op < 0.75 and additions:
            path, value = rng.choice(additions)
            target = doc
            for part in path[:-1]:
                nxt = target.get(part) if isinstance(target, dict) else None
                if isinstance(nxt, list) and nxt and isinstance(nxt[0], dict):
                    nxt = rng.choice(nxt)
                if not isinstance(nxt, dict):
                    nxt = {}
                    target[part] = nxt
                target = nxt
            target[path[-1]] = copy.deepcopy(value() if callable(value) else value)
        elif op < 0.82:  # an unknown key, top level or in a table
            tables = [v for v in doc.values() if isinstance(v, dict)] + [doc]
            rng.choice(tables)[rng.choice(["colour", "Count", "frames ", "", "species.file", "x" * 80])] = 1
        elif op < 0.9:  # an array of tables repeated / emptied
            arrays = [k for k, v in doc.items() if isinstance(v, list) and v and isinstance(v[0], dict)]
            if arrays:
                k = rng.choice(arrays)
                doc[k] = rng.choice([[], (doc[k] * rng.choice([2, 50, 400]))[:MAX_TABLES], doc[k][:1]])
        else:  # a table replaced by a value of another type, or a value by a table
            places = [(p, k) for p, k in places if isinstance(p, dict)]
            if places:
                parent, key = rng.choice(places)
                parent[key] = rng.choice([{}, [], "x", 1, [{}], {"a": {"b": 1}}])


def toml_mutant(seed_text: str, rng: random.Random, additions: list[tuple[list[str], Any]]) -> str:
    """A mutant of a valid TOML seed: as data (most), then sometimes damaged as text."""
    from fishgen.tomlfile import loads

    doc = loads(seed_text, "<seed>")
    if rng.random() < 0.85:
        mutate_doc(doc, rng, additions)
    text = toml_text(doc)
    if rng.random() < 0.2:
        text = mutate.mutate_text(text, rng, ops=rng.choice([1, 2]))
    if rng.random() < 0.03:
        text = rng.choice(["\ufeff", "\x00", "[[species]]\n", "a = 1\na = 2\n", "= 1\n", "[a]\n[a]\n"]) + text
    return text


# -- scene files and path CSVs ---------------------------------------------------------------------
def _zones() -> list[tuple[list[str], Any]]:
    from fishgen.school.model import COUZIN_PRESETS, COUZIN_RANGES, VARIETY_RANGES

    out: list[tuple[list[str], Any]] = [(["couzin", "preset"], p) for p in [*COUZIN_PRESETS, "Torus", ""]]
    for key, (lo, hi) in COUZIN_RANGES.items():
        out += [(["couzin", key], v) for v in (lo, hi, hi * 1.0001 + 1e-9, lo - 1e-9, (lo + hi) / 2)]
    for key, (lo, hi) in VARIETY_RANGES.items():
        out += [(["variety", key], v) for v in (lo, hi, hi + 1, -1, (lo + hi) / 2)]
    return out


SCENE_ADDITIONS: list[tuple[list[str], Any]] = [
    (["warmup"], 0.0),
    (["warmup"], 3.0),
    (["warmup"], 1e4),
    (["warmup"], 10000.5),
    (["warmup"], -1.0),
    (["preroll"], 0.0),
    (["preroll"], 600.0),
    (["preroll"], 600.5),
    (["preroll"], -1.0),
    (["preroll"], "60"),
    (["length"], 0.3),
    (["length"], 0.01),
    (["length"], 100.0),
    (["length"], 1e-3),
    (["length"], 1e9),
    (["bounds"], [[-3.0, -1.0, -3.0], [3.0, 1.0, 3.0]]),
    (["bounds"], [[-1e4, -1e4, -1e4], [1e4, 1e4, 1e4]]),
    (["bounds"], [[0, 0, 0], [0, 0, 0]]),
    (["bounds"], [[1, 1, 1], [-1, -1, -1]]),
    (["bounds"], [1, 2, 3, 4, 5, 6]),
    (["bounds"], [[-1e5, 0, 0], [1, 1, 1]]),
    (["bounds"], [[0, 0], [1, 1]]),
    (["model"], "couzin"),
    (["model"], "pso"),
    (["model"], "boids"),
    (["layout"], "ring"),
    (["frames"], 2),
    (["frames"], 100_000),
    (["frames"], 1),
    (["fps"], 1),
    (["fps"], 1000),
    (["fps"], 0.5),
    (["seed"], 0),
    (["seed"], 2**63 - 1),
    (["seed"], 2**63),
    (["seed"], -1),
    (["target", "path"], "path.csv"),
    (["target", "path"], "circle"),
    (["target", "path"], "spline"),
    (["target", "path"], "../path.csv"),
    (["target", "path"], "missing.csv"),
    (["target", "path"], "."),
    (["target", "centre"], [0, 0, 0]),
    (["target", "centre"], [1e4, 0, 0]),
    (["target", "centre"], [1e5, 0, 0]),
    (["target", "radius"], 3.0),
    (["target", "radius"], 1e4),
    (["target", "period"], 0.1),
    (["target", "seed"], 3),
    (["predator", "path"], "path.csv"),
    (["predator", "path"], "figure8"),
    (["predator", "radius"], 0.01),
    (["predator", "period"], 1e6),
    (["predator", "centre"], [0, 1e4, 0]),
    (["pso", "inertia"], 0.7),
    (["pso", "inertia"], 1e3),
    (["pso", "cognitive"], 1.5),
    (["pso", "social"], -1),
    (["species", "count"], 1),
    (["species", "count"], 100_000),
    (["species", "count"], 100_001),
    (["species", "speed"], 0.05),
    (["species", "speed"], 20.0),
    (["species", "file"], "threadfingoldie.txt"),
    (["species", "file"], "missing.txt"),
    (["species", "file"], "../species.txt"),
    (["species", "file"], ""),
    (["species", "file"], "path.csv"),
    (["species", "file"], "scene.toml"),
]


def scene_text(seeds: list[str], rng: random.Random) -> str:
    return toml_mutant(rng.choice(seeds), rng, SCENE_ADDITIONS + _zones())


PATH_VALUES = [
    "0",
    "1",
    "-1",
    "0.5",
    "1e4",
    "10000.0001",
    "-1e4",
    "1e7",
    "10000001",
    "1e308",
    "-1e308",
    "1e309",
    "nan",
    "inf",
    "-inf",
    "5e-324",
    "",
    " ",
    "x",
    "1_0",
    "１",
    "0x10",
    "1e-300",
    "+1",
    ".5",
]


def path_csv(rng: random.Random) -> bytes:
    """A target/predator path ``t,x,y,z``: a valid loop, then mutated (values, rows, header, size)."""
    n = rng.choice([2, 3, 5, 12, 40])
    rows = [f"{t * 0.5!r},{math.cos(t):.4f},{0.2 * math.sin(2 * t):.4f},{math.sin(t):.4f}" for t in range(n)]
    if rng.random() < 0.5:
        rows.insert(0, rng.choice(["t,x,y,z", "time,x,y,z", "t;x;y;z", "#t,x,y,z"]))
    text = "\n".join(rows) + "\n"
    roll = rng.random()
    if roll < 0.55:
        lines = text.split("\n")
        for _ in range(rng.choice([1, 1, 2, 4])):
            k = rng.randrange(max(1, len(lines) - 1))
            cells = lines[k].split(",")
            cells[rng.randrange(len(cells))] = rng.choice(PATH_VALUES)
            lines[k] = ",".join(cells)
        text = "\n".join(lines)
    elif roll < 0.8:
        text = mutate.mutate_text(text, rng, sep=",")
    elif roll < 0.88:  # many rows (a long path), or one
        m = rng.choice([1, 1000, 200_000])
        text = "".join(f"{t},{t % 7},{t % 3},{t % 5}\n" for t in range(m))
    elif roll < 0.94:  # reversed / repeated times
        lines = [ln for ln in text.split("\n") if ln]
        text = "\n".join(reversed(lines) if rng.random() < 0.5 else lines + lines[-1:]) + "\n"
    else:
        text = rng.choice(["", "\n", "t,x,y,z\n", "0,0,0,0\n", "0,0,0\n1,1,1\n", "\x00\x01\x02"])
    data = text.encode("utf-8", "surrogatepass")
    if rng.random() < 0.05:
        data = mutate.mutate_bytes(data, rng)
    return data


# -- manifests -------------------------------------------------------------------------------------
def manifest_additions() -> list[tuple[list[str], Any]]:
    out: list[tuple[list[str], Any]] = [
        (["out"], v) for v in ("out", "", ".", "..", "/", "../../x", "a/b", 1, ["x"])
    ]
    out += [
        (["build", "output"], v)
        for v in (
            "x.glb",
            "x.gltf",
            "x.obj",
            "x.ply",
            "x.png",
            "x",
            "../x.glb",
            "/x.glb",
            "",
            ".",
            "a/../../x.glb",
            "x.GLB",
            "a\\..\\x.glb",
            "fish/bonybream.glb",
        )
    ]
    out += [(["build", "input"], v) for v in ("bonybream.txt", "missing.txt", "../x.txt", "", "/etc/passwd")]
    out += [(["build", "inputs"], v) for v in (["bonybream.txt"], ["a.txt", "b.txt"], [], [1], "x")]
    out += [(["clouds", "inputs"], v) for v in (["clouds/table_4_4.awn", "clouds/sky.awa"], [""])]
    out += [
        (["clouds", "offset"], v)
        for v in (
            [[0, 0, 0]],
            [[0, 0, 0], [1, 2, 3]],
            [0, 0, 0],
            [[math.nan, 0, 0]],
            [[1e39, 0, 0]],
            [["a", 0, 0]],
            [],
        )
    ]
    out += [(["school", "input"], v) for v in ("reef.toml", "bonybream.txt", "missing.toml")]
    out += [(["school", "inputs"], v) for v in (["reef.toml", "bonybream.txt"], ["bonybream.txt"] * 3)]
    values = [
        0,
        1,
        -1,
        2,
        0.5,
        1e-3,
        30,
        1000,
        1001,
        2**63,
        math.nan,
        math.inf,
        True,
        "",
        "x",
        "8x6,4x4",
        "swim,idle",
        "mask",
        "blend",
        "torus",
        "couzin",
        [1, 2, 3],
        [1.0, 0.4, 0.2],
        [1, 2, 3, 4, 5, 6],
        ".",
        "..",
        "/",
        "textures",
    ]
    try:
        from fishgen.commands.batch import job_kinds
        from fishgen.options import manifest_options

        for kind in job_kinds():
            for key in manifest_options(kind.options):
                out += [([kind.name, key], v) for v in values]
    except Exception:  # noqa: BLE001 - the generator works without the declarations too
        pass
    return out


_MANIFEST_ADDITIONS: list[tuple[list[str], Any]] = []


def manifest_text(seeds: list[str], rng: random.Random) -> str:
    if not _MANIFEST_ADDITIONS:
        _MANIFEST_ADDITIONS.extend(manifest_additions())
    return toml_mutant(rng.choice(seeds), rng, _MANIFEST_ADDITIONS)


# -- .FXL ------------------------------------------------------------------------------------------
FXL_VALUES = [
    "0",
    "1",
    "0.5",
    "1.0001",
    "-0",
    "-0.0001",
    "nan",
    "inf",
    "1e-300",
    "9" * 400,
    "1" + "0" * 6,
    "100000",
    "100001",
    "3.0",
    "2.5",
    "-1",
    "",
    "x",
    "１",
    "0x1",
    "1_0",
    "1e0",
    "0.",
    ".5",
]


def fxl_text(seeds: list[str], rng: random.Random) -> str:
    """A mutant of a valid .FXL file: counts and indices (section, circle) and coordinates replaced,
    lines swapped/reversed/dropped, parts repeated or renamed, the OCR-joined first line."""
    text = rng.choice(seeds)
    lines = text.split("\n")
    for _ in range(rng.choice([1, 1, 2, 3, 6])):
        roll = rng.random()
        k = rng.randrange(len(lines)) if lines else 0
        if not lines:
            lines = [""]
        if roll < 0.4:
            toks = lines[k].split()
            if toks:
                toks[rng.randrange(len(toks))] = rng.choice(FXL_VALUES)
                lines[k] = " ".join(toks)
        elif roll < 0.5:  # a count line
            counts = [i for i, ln in enumerate(lines) if ln.strip().isdigit()]
            if counts:
                i = rng.choice(counts)
                lines[i] = rng.choice(
                    [
                        "0",
                        "1",
                        str(int(lines[i]) + 1),
                        str(max(0, int(lines[i]) - 1)),
                        "9" * 400,
                        "100000",
                        "100001",
                        "1.0",
                        "-1",
                    ]
                )
        elif roll < 0.6:  # body lines reversed, or their indices dropped
            body = [i for i, ln in enumerate(lines) if len(ln.split()) == 4]
            if body:
                if rng.random() < 0.5:
                    values = [lines[i] for i in body][::-1]
                    for i, v in zip(body, values, strict=True):
                        lines[i] = v
                else:
                    for i in body:
                        lines[i] = " ".join(lines[i].split()[2:])
        elif roll < 0.7:
            lines[k] = rng.choice(
                [
                    "//body",
                    "//caudal",
                    "//Dorsal fin",
                    "//tail",
                    "//",
                    "//unknown",
                    "// body",
                    "//pectoralfin 2 0.1 0.2 0.3 0.4",
                    "//anal 1",
                    "//adipose",
                ]
            )
        elif roll < 0.78:
            del lines[k]
        elif roll < 0.86:
            lines.insert(k, lines[rng.randrange(len(lines))])
        elif roll < 0.92:  # OCR join: the header, count and first points on one line
            if k + 2 < len(lines):
                lines[k : k + 3] = [" ".join(lines[k : k + 3])]
        else:
            return mutate.mutate_text("\n".join(lines), rng)
    return "\n".join(lines)


# -- photos ----------------------------------------------------------------------------------------
MODES = ["RGBA", "RGBA", "RGB", "RGB", "L", "LA", "P", "1", "I;16", "I", "F", "CMYK", "PA"]


def photo_bytes(seed_png: bytes, rng: random.Random) -> bytes:
    """A photo for `fishgen texture`: the seed fish resized to odd sizes and aspect ratios, in other
    modes, blank/noise/flipped/rotated, saved as PNG (or another format under .png), or truncated."""
    from PIL import Image, ImageOps

    roll = rng.random()
    if roll < 0.05:
        return mutate.mutate_png(seed_png, rng)
    with Image.open(io.BytesIO(seed_png)) as src:
        im = src.convert("RGBA")
    if rng.random() < 0.15:  # below the 64-pixel minimum, or a sliver
        w, h = rng.choice([(64, 32), (1, 1), (2, 1), (1, 2), (3, 200), (400, 4), (63, 64), (17, 9), (160, 4)])
    else:
        w, h = rng.choice(
            [
                (160, 80),
                (160, 80),
                (160, 80),
                (64, 64),
                (65, 64),
                (128, 64),
                (97, 71),
                (64, 300),
                (300, 64),
                (2000, 64),
                (8000, 64),
                (64, 8000),
                (120, 119),
                (240, 60),
                (320, 160),
            ]
        )
    im = im.resize((w, h), rng.choice([Image.Resampling.NEAREST, Image.Resampling.BILINEAR]))
    edit = rng.random()
    if edit < 0.1:
        angle = rng.choice([3, 9, 11, 45, 90, 91, 180, -12])
        # a sliver turned 45 degrees grows to millions of pixels: the generator ran out of the
        # worker's memory (seed 13, photo 367); turn only the photo-sized ones
        im = im.rotate(angle, expand=w * h <= 200_000)
    elif edit < 0.17:
        im = ImageOps.mirror(im) if rng.random() < 0.5 else ImageOps.flip(im)
    elif edit < 0.22:
        im = Image.new("RGBA", (w, h), rng.choice([(0, 0, 0, 0), (255, 255, 255, 255), (0, 0, 0, 255)]))
    elif edit < 0.27:
        im = Image.frombytes("RGBA", (w, h), rng.randbytes(w * h * 4))
    elif edit < 0.32:  # the fish opaque on its own colour: no alpha, no contrast
        im.putalpha(255)
    elif edit < 0.36:  # fully transparent fish
        im.putalpha(0)
    mode = rng.choice(MODES)
    try:
        im = im.convert(mode)
    except ValueError:
        pass
    buf = io.BytesIO()
    fmt = rng.choices(["PNG", "JPEG", "GIF", "BMP", "TIFF"], weights=[80, 14, 2, 2, 2])[0]
    try:
        if fmt == "JPEG":
            im, options = _as_jpeg(im, rng)
            im.save(buf, fmt, **options)
        else:
            im.save(buf, fmt)
    except (OSError, ValueError, KeyError):
        buf = io.BytesIO()
        im.convert("RGB").save(buf, "PNG")
    data = buf.getvalue()
    if rng.random() < 0.12:  # truncated data
        data = data[: rng.randrange(len(data) + 1)]
    elif rng.random() < 0.05:
        data = mutate.mutate_bytes(data, rng)
    return data


def _as_jpeg(im, rng: random.Random) -> tuple[Any, dict]:
    """``im`` as a camera or an editor might save it as JPEG, and the save's options: in a mode JPEG
    holds (its alpha dropped), at any quality, its colour at full, half-width or half size (the
    reader draws a 4:2:0 photo's colour again: `chroma.redraw`), sometimes progressive or turned by
    an EXIF orientation."""
    from PIL import Image

    if im.mode not in ("RGB", "L", "CMYK"):
        im = im.convert(rng.choices(["RGB", "L", "CMYK"], weights=[8, 1, 1])[0])
    options: dict = {"quality": rng.choice([1, 5, 30, 75, 90, 95, 100]),
                     "subsampling": rng.choice([0, 1, 2, 2]), "progressive": rng.random() < 0.2}
    if rng.random() < 0.2:
        exif = Image.Exif()
        exif[0x0112] = rng.choice([0, 1, 2, 3, 5, 6, 8, 9, 255])
        options["exif"] = exif.tobytes()
    return im, options


# -- .awa texture clouds ---------------------------------------------------------------------------
AWA_TEXTURES = [
    "clouds/billow.png",
    "clouds/cumulus.png",
    "clouds/wisp.png",
    "billow.png",
    "../billow.png",
    "../../textures/clouds/billow.png",
    "/etc/passwd.png",
    "clouds/missing.png",
    "clouds/",
    "clouds",
    "clouds/billow.PNG",
    "clouds/billow.txt",
    "clouds//billow.png",
    "./clouds/billow.png",
    "clouds/../clouds/billow.png",
    "clouds\\billow.png",
    "",
    "x" * 300 + ".png",
    "c l o u d.png",
    "clouds/link.png",
    "clouds/dir.png",
    "nul.png",
    ".png",
    "clouds/billow.png\x00",
]


def awa_bytes(seeds: list[bytes], rng: random.Random) -> bytes:
    text = rng.choice(seeds).decode("utf-8")
    lines = text.split("\n")
    roll = rng.random()
    if roll < 0.3:  # texture names
        cubes = [i for i, ln in enumerate(lines) if ln.count(",") >= 8]
        for _ in range(rng.choice([1, 1, 2])):
            if cubes:
                i = rng.choice(cubes)
                cells = lines[i].split(",")
                cells[-1] = " " + rng.choice(AWA_TEXTURES)
                if rng.random() < 0.1:
                    cells = cells[:-1] if rng.random() < 0.5 else cells + [" clouds/wisp.png"]
                lines[i] = ",".join(cells)
        text = "\n".join(lines)
    else:
        text = mutate.mutate_text(text, rng, sep=",")
    data = text.encode("utf-8", "surrogatepass")
    if rng.random() < 0.04:
        data = mutate.mutate_bytes(data, rng)
    return data


# -- editor requests -------------------------------------------------------------------------------
#: Placeholders the runner fills in: the server's port and token, a folder outside the editor's.
PORT, TOKEN, OUTSIDE = "{PORT}", "{TOKEN}", "{OUTSIDE}"
SAVE_NAMES = [
    "new.awn",
    "new.awa",
    "table_4_4.awn",
    "sky.awa",
    "../escape.awn",
    "../../escape.awn",
    f"{OUTSIDE}/abs.awn",
    "/escape.awn",
    "sub/x.awn",
    "..",
    ".",
    "",
    ".awn",
    "x.AWN",
    "x.awn.txt",
    "x.txt",
    "con.awn",
    "a" * 300 + ".awn",
    "x\x00.awn",
    "x\n.awn",
    "..\\escape.awn",
    "~/x.awn",
    "link.awn",
    "x/../../escape.awn",
    "%2e%2e/escape.awn",
    1,
    None,
    [],
    {"name": "x"},
    True,
]
TEXTURE_NAMES = [
    "clouds/billow.png",
    "clouds/cumulus.png",
    "../sky.awa",
    "../../etc/passwd",
    "/etc/passwd",
    "clouds/missing.png",
    "",
    "clouds",
    "clouds/billow.png%00",
    "%2e%2e/%2e%2e/x.png",
    "x" * 2000,
]


def _json_mutant(value: Any, rng: random.Random) -> Any:
    value = copy.deepcopy(value)
    for _ in range(rng.choice([0, 1, 1, 2, 4])):
        places = _containers(value, [])
        if not places:
            break
        parent, key = rng.choice(places)
        roll = rng.random()
        if roll < 0.6:
            parent[key] = rng.choice(
                [
                    0,
                    -1,
                    1e308,
                    -1e308,
                    1e-320,
                    2**64,
                    10**400,
                    1.5,
                    "1",
                    "",
                    None,
                    True,
                    [],
                    {},
                    [1, 2],
                    [1, 2, 3, 4],
                    "clouds/billow.png",
                    "../x.png",
                    100_000,
                    10**7,
                    1e9,
                    2**53,
                    0.0,
                ]
            )
        elif roll < 0.8 and isinstance(parent, dict):
            del parent[key]
        elif isinstance(parent, list):
            if len(parent) < 5000:  # bounded: the generator's time counts against the case's
                parent.extend(parent[:1] * rng.choice([1, 10, 1000]))
    return value


def editor_requests(cubes_by_mode: dict[str, list[dict]], rng: random.Random) -> list[bytes]:
    """1-4 raw HTTP requests to the editor (each on its own connection)."""
    return [_request(cubes_by_mode, rng) for _ in range(rng.choice([1, 1, 2, 4]))]


def _request(cubes_by_mode: dict[str, list[dict]], rng: random.Random) -> bytes:
    route = rng.choices(
        ["/", "/api/document", "/api/open", "/api/save", "/api/fill", "/api/texture", "/api/lists", "other"],
        [1, 2, 3, 6, 4, 3, 2, 2],
    )[0]
    method = {"/api/open": "POST", "/api/save": "POST", "/api/fill": "POST"}.get(route, "GET")
    if rng.random() < 0.08:
        method = rng.choice(["GET", "POST", "HEAD", "PUT", "DELETE", "OPTIONS", "PATCH", "get", "BREW"])
    if route == "other":
        route = rng.choice(
            [
                "/api",
                "/api/",
                "/API/save",
                "/api/save/",
                "/../api/save",
                "/api/%2e%2e/save",
                "//api/save",
                "/api/save;x",
                "*",
                "http://127.0.0.1/api/save",
                "/" + "a" * 9000,
                "/api/save%00",
                "/favicon.ico",
            ]
        )
    body: bytes = b""
    mode = rng.choice(["particles", "texture"])
    payload: Any = None
    if route in ("/api/save", "/api/fill"):
        cubes = copy.deepcopy(cubes_by_mode[mode])
        if rng.random() < 0.1:
            cubes = copy.deepcopy(cubes_by_mode["texture" if mode == "particles" else "particles"])
        name = rng.choice(SAVE_NAMES)
        if isinstance(name, str) and rng.random() < 0.6 and route == "/api/save":
            name = (
                name if name.endswith((".awn", ".awa")) else name + (".awa" if mode == "texture" else ".awn")
            )
        payload = {"name": name, "mode": mode, "cubes": cubes}
        if route == "/api/fill":
            if rng.random() < 0.5:
                payload["seed"] = rng.choice([0, 7, -1, 2**63, 1.5, "1", None, True])
            if rng.random() < 0.5:
                payload["sun"] = rng.choice(
                    [
                        [1, 1, 0],
                        [0, 0, 0],
                        [1e308, 1e308, 1e308],
                        [1, 2],
                        ["a", 1, 1],
                        None,
                        [True, 0, 1],
                        [float("1e-320"), 0, 0],
                    ]
                )
        payload = _json_mutant(payload, rng) if rng.random() < 0.7 else payload
    elif route == "/api/open":
        payload = {"name": rng.choice(SAVE_NAMES + ["table_4_4.awn", "sky.awa", "bad.awn", "fifo.awn"])}
    if payload is not None or method in ("POST", "PUT"):
        text = json.dumps(payload, allow_nan=True) if payload is not None else ""
        roll = rng.random()
        if roll < 0.08:  # malformed JSON
            text = text[: rng.randrange(len(text) + 1)]
        elif roll < 0.12:
            text = rng.choice(
                [
                    "",
                    "{",
                    "null",
                    "[]",
                    "1e999",
                    "NaN",
                    '{"name": "\\ud800"}',
                    "\ufeff{}",
                    "[" * 100_000 + "]" * 100_000,
                    '{"name": ' * 5000,
                ]
            )
        body = text.encode("utf-8", "surrogatepass")
        if rng.random() < 0.03:  # a big body (the cap is 16 MiB)
            body = b'{"name": "' + b"a" * rng.choice([1 << 20, 4 << 20]) + b'"}'
        if rng.random() < 0.04:
            body = rng.choice([b"\xff\xfe{}", b"\x00" * 100, mutate.mutate_bytes(body, rng)])
    query = ""
    if route == "/api/texture" or rng.random() < 0.05:
        query = "&name=" + rng.choice(TEXTURE_NAMES)
    token = TOKEN
    roll = rng.random()
    if roll < 0.08:
        token = rng.choice(["", "x", TOKEN + "x", TOKEN[:-1], TOKEN.upper(), "%00", "é", "\udcff"])
    where = rng.choice(["header", "query", "query", "both"])
    target = route + (
        f"?token={token}{query}" if where in ("query", "both") else ("?" + query[1:] if query else "")
    )
    if rng.random() < 0.02:
        target += "&token=" + rng.choice(["x", TOKEN])
    host = f"127.0.0.1:{PORT}" if rng.random() < 0.5 else f"localhost:{PORT}"
    if rng.random() < 0.08:
        host = rng.choice(
            [
                "",
                "evil.com",
                f"127.0.0.1:{PORT}.evil.com",
                "127.0.0.1",
                f"LOCALHOST:{PORT}",
                f"127.0.0.1:{PORT} ",
                "[::1]:" + PORT,
                "x" * 5000,
                f"127.0.0.1:{PORT}\x00",
            ]
        )
    version = (
        "HTTP/1.1" if rng.random() < 0.97 else rng.choice(["HTTP/1.0", "HTTP/0.9", "HTTP/2.0", "HTTP/x", ""])
    )
    headers = [f"{method} {target} {version}".strip()]
    if rng.random() > 0.03:
        headers.append(f"Host: {host}")
    if rng.random() < 0.02:
        headers.append(f"Host: {rng.choice(['evil.com', host])}")
    if where in ("header", "both"):
        headers.append(f"X-Fishgen-Token: {token}")
    length = str(len(body))
    roll = rng.random()
    if roll < 0.06:
        length = rng.choice(
            [
                "-1",
                "x",
                "1e3",
                "99999999999999999999",
                str((16 << 20) + 1),
                "+5",
                " 5",
                "0x10",
                str(len(body) + 10),
                str(max(0, len(body) - 5)),
                "٣",
                "",
            ]
        )
    if body or method in ("POST", "PUT") or roll < 0.06:
        if rng.random() < 0.04:
            headers.append("Transfer-Encoding: chunked")
        else:
            headers.append(f"Content-Length: {length}")
    if rng.random() < 0.03:
        headers += [f"X-{k}: {'v' * 100}" for k in range(rng.choice([10, 200]))]
    head = ("\r\n".join(headers) + "\r\n\r\n").encode("utf-8", "surrogateescape")
    if rng.random() < 0.04:  # a slow/stopped client: part of the request, then nothing
        return b"SLOW" + (head + body)[: rng.randrange(len(head) + len(body) + 1)]
    return head + body
