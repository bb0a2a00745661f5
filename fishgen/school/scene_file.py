"""School scene files (TOML): species and counts, model parameters, bounds, target, predator, layout.

    model = "boids"            # or "pso"
    frames = 300
    fps = 30
    seed = 1
    bounds = [[-4, -1.5, -4], [4, 1.5, 4]]
    layout = "sphere"          # sphere | box | line | ring (default: ring for the couzin torus)

    [[species]]
    file = "bonybream.txt"     # relative to this file
    count = 60
    speed = 1.0                # cruising speed, body lengths per second

    [target]                   # the pso school's target
    path = "circle"            # circle | figure8 | spline | a CSV of t,x,y,z
    radius = 3.0
    period = 20.0

    [predator]                 # optional: fish flee it (flee_info of their species file)
    path = "figure8"

    [pso]                      # the particle swarm's weights (2017 report, Figure 2.2)
    inertia = 0.7

    [couzin]                   # Couzin et al. (2002): a preset, and any zone overriding it
    preset = "torus"           # swarm | torus | dynamic parallel | highly parallel
    orientation = 1.0          # body lengths; also repulsion, attraction, blind_angle, ...

    [variety]                  # VRSchool's per-fish variety
    size = 0.05                # s.d. of each fish's size factor
    tints = 3                  # colour variants per species (1: its own colours only)
    tint = 0.15

and, among the first keys (before any [table], where TOML would put them inside it):

    warmup = 3.0               # seconds the school takes to form (the summary skips them)
    preroll = 60.0             # seconds simulated before the first frame, not baked
    length = 0.3               # every species' nose-to-tail length, metres

Every mistake is one ``FILE:LINE: expected ..., found ...`` line; absurd sizes are refused
before anything is allocated. The keys that are also `fishgen school` options (frames, fps, seed,
model, layout, a species' count, ...) are declared once, here, and checked exactly as the options are.
Leaf module (no numpy): `fishgen school --help` and batch manifests read the declarations.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import click

from fishgen.errors import FishgenError, UsageError, describe
from fishgen.options import SEED, FiniteRange, Option, check_value
from fishgen.school.model import (
    COUZIN_PRESETS,
    COUZIN_RANGES,
    LAYOUTS,
    MODELS,
    PREROLL_PAPER_SECONDS,
    VARIETY_HELP,
    VARIETY_RANGES,
    WARMUP_SECONDS,
    CouzinParams,
    PsoParams,
    TargetPath,
    Variety,
    couzin_params,
)
from fishgen.tomlfile import Where as _Where
from fishgen.tomlfile import loads as _loads
from fishgen.tomlfile import text_of as _text_of

MAX_FISH = 100_000
MAX_FRAMES = 100_000
MAX_FISH_FRAMES = 2 * 10**8
"""Fish x frames: 10,000 fish x 1,000 frames is 10^7 (about 1 GB of tracks at 2 x 10^8)."""
MAX_SCENE_BYTES = 1 << 20
MAX_SPECIES = 64
"""[[species]] tables a scene may hold: each builds its own fish (meshes, texture, materials), so
1,000 one-fish tables of one file took 126 s and wrote 96 MB where one table of 1,000 took 2.5 s
and 2.5 MB, and the memory estimate, which counts fish and frames, did not see them."""
PATHS = ("circle", "figure8", "spline", "none")
DEFAULT_COUNT = 50
MAX_COORDINATE = 1e4
"""Metres from the origin a scene's bounds, centres and path points may lie (a school is far
smaller; a point at 1e308 overflowed the neighbour search)."""
MAX_PATH_SECONDS = 1e7
MAX_PATH_BYTES = 1 << 20
"""A path CSV's size: about 30,000 rows, read row by row in a fraction of a second (16 MiB took 5 s)."""

# Keys that are also options of `fishgen school` (and of its batch jobs): one declaration each.
COUNT = Option(click.IntRange(1, MAX_FISH), "Fish per species.", DEFAULT_COUNT)
FRAMES = Option(click.IntRange(2, MAX_FRAMES), "Frames to simulate and bake.", 300)
FPS = Option(FiniteRange(1, 1000), "Frames per second.", 30.0)
SEED_KEY = Option(SEED, "Random seed; the same seed gives byte-identical files.", 0)
MODEL = Option(click.Choice(MODELS), "boids: VRFish's brain (thesis 7.2), steering also by the school's "
               "heading; pso: the particle swarm following a target (2017 report); couzin: Couzin et al. "
               "(2002)'s zones of repulsion, orientation and attraction (see --preset).", "boids")
SPEED = Option(FiniteRange(0.05, 20), "Cruising speed, body lengths per second.", 1.0)


class Box(click.ParamType):
    """``X0,Y0,Z0,X1,Y1,Z1``: a box's min and max corners in metres, each side 0.1 m or more."""

    name = "X0,Y0,Z0,X1,Y1,Z1"
    toml_list = True  # a scene file's [[x0, y0, z0], [x1, y1, z1]]
    what = (f"X0,Y0,Z0,X1,Y1,Z1: six numbers within {MAX_COORDINATE:g} m, whose max corner exceeds the min "
            "by 0.1 m or more each way")

    def convert(self, value, param, ctx):
        if isinstance(value, (tuple, list)):  # a scene file's [[x0, y0, z0], [x1, y1, z1]]
            # or its own (lo, hi) from the command line, or a Python caller's
            items = [v for corner in value
                     for v in (corner if isinstance(corner, (list, tuple)) else [corner])]
        else:
            items = str(value).replace(" ", "").split(",")
        try:
            numbers = [float(v) for v in items if not isinstance(v, bool)]
        except (TypeError, ValueError, OverflowError):  # OverflowError: a TOML integer of 400 digits
            numbers = []
        if (len(numbers) != 6 or len(items) != 6 or not all(math.isfinite(v) and abs(v) <= MAX_COORDINATE
                                                            for v in numbers)
                or not all(numbers[k + 3] - numbers[k] >= 0.1 for k in range(3))):
            self.fail(f"expected {self.what}, found {value!r}", param, ctx)
        lo, hi = tuple(numbers[:3]), tuple(numbers[3:])
        return lo, hi


BOUNDS = Option(Box(), "The region the fish keep inside, metres (min and max corners).", None,
                shown_default="4 body lengths x the cube root of the count each way, a third as tall")
LENGTH = Option(FiniteRange(0.01, 100), "Every species' nose-to-tail length, metres.", None,
                shown_default="each species file's own", metavar="METRES")
WARMUP = Option(FiniteRange(0, 1e4), "Seconds the school takes to form from its start layout; the summary "
                "skips them, and `fishgen preview` of the file starts after them.", None,
                shown_default=f"0 after a pre-roll, else a third of the run, at most {WARMUP_SECONDS:g} s",
                metavar="SECONDS")
MAX_PREROLL = 600.0
PREROLL = Option(FiniteRange(0, MAX_PREROLL), "Seconds simulated before the first frame and not baked: the "
                 "school forms in them, so the animation starts with it formed.", None,
                 shown_default=f"couzin: {PREROLL_PAPER_SECONDS:g} s of the paper's clock at the slowest "
                               "species' speed (60 s at 1 body length/s, at most "
                               f"{MAX_PREROLL:g}); boids and pso: 0", metavar="SECONDS")
PRESET = Option(click.Choice(tuple(COUZIN_PRESETS)),
                "Couzin et al. (2002)'s collective state for the couzin model (sets --model couzin): "
                + ", ".join(f"{name} (orientation zone {p.orientation:g} body lengths)"
                            for name, p in COUZIN_PRESETS.items())
                + ". The torus starts as a ring already milling unless --layout says otherwise (from a "
                "random ball it rarely mills).", None,
                shown_default="the scene file's [couzin], else zones of 1, 1 and 15 body lengths (torus)")
LAYOUT = Option(click.Choice(LAYOUTS), "How the fish start: a random ball (sphere), scattered through the "
                "region (box), a line, or a horizontal ring heading round it (ring: a mill already).", None,
                shown_default="ring for the couzin model's torus (its preset, or its default zones), "
                              "else sphere")
SIZE_VARIETY = Option(FiniteRange(*VARIETY_RANGES["size"]), VARIETY_HELP["size"].capitalize() + ".",
                      Variety.size)
TINTS = Option(click.IntRange(int(VARIETY_RANGES["tints"][0]), int(VARIETY_RANGES["tints"][1])),
               VARIETY_HELP["tints"].capitalize() + ".",
               Variety.tints)
TINT = Option(FiniteRange(*VARIETY_RANGES["tint"]), VARIETY_HELP["tint"].capitalize() + ".", Variety.tint)


@dataclass(frozen=True)
class SpeciesEntry:
    file: Path
    count: int = DEFAULT_COUNT
    speed: float = 1.0
    line: int | None = field(default=None, compare=False)   # where a scene file names it, and as
    named: str | None = field(default=None, compare=False)  # it is written there


def check_species_files(scene: SceneFile, file: str | os.PathLike) -> None:
    """Refuse, at the scene file's line, a species file it names that is missing or not a file
    (else the species parser would name the resolved path alone)."""
    for entry in scene.species:
        if entry.line is None or entry.file.is_file():
            continue
        what = (", a folder" if entry.file.is_dir() else ", a device, pipe or other special file"
                if entry.file.exists() else " missing beside the scene file")
        named = describe(entry.named or str(entry.file))
        raise FishgenError(f"expected an existing species file, found {named}{what}", file, entry.line)


@dataclass(frozen=True)
class SceneFile:
    """What a scene file (or the command line alone) asks for; the CLI's flags override it."""

    species: tuple[SpeciesEntry, ...] = ()
    model: str = MODEL.default
    frames: int = FRAMES.default
    fps: float = FPS.default
    seed: int = SEED_KEY.default
    bounds: tuple[tuple[float, float, float], tuple[float, float, float]] | None = None
    layout: str | None = None            # None: start_layout's default
    target: TargetPath = TargetPath()
    predator: TargetPath | None = None
    pso: PsoParams = PsoParams()
    couzin: CouzinParams | None = None   # None: CouzinParams()
    preset: str | None = None            # the Couzin preset `couzin` was named by, if any
    variety: Variety | None = None       # None: Variety()
    warmup: float | None = None          # seconds; None: WARMUP_SHARE of the run, at most WARMUP_SECONDS
    preroll: float | None = None         # seconds; None: preroll_seconds' default
    length: float | None = None          # metres, every species; None: each species file's own
    read: tuple[Path, ...] = ()      # the files it named and were read: path CSVs
    table: tuple[str, int | None] | None = None   # the model's table the file gave ("pso" or "couzin"),
                                                  # and its header's line: the model must stay that


def with_options(scene: SceneFile, *, count: int | None = None, frames: int | None = None,
                 fps: float | None = None, seed: int | None = None, model: str | None = None,
                 speed: float | None = None, bounds: Any = None, length: float | None = None,
                 warmup: float | None = None, preset: str | None = None,
                 variety: dict[str, Any] | None = None, preroll: float | None = None,
                 layout: str | None = None) -> SceneFile:
    """``scene`` with the options given (not None) overriding it, as `fishgen school`'s flags do;
    ``count`` and ``speed`` set every species'; ``preset`` a Couzin preset (and the couzin model
    unless ``model`` says otherwise); ``variety`` the Variety fields given."""
    if count is not None:
        scene = replace(scene, species=tuple(replace(e, count=count) for e in scene.species))
    if speed is not None:
        scene = replace(scene, species=tuple(replace(e, speed=speed) for e in scene.species))
    if preset is not None:
        scene = replace(scene, couzin=COUZIN_PRESETS[preset], preset=preset, model=model or "couzin")
    if variety:
        scene = replace(scene, variety=replace(scene.variety or Variety(), **variety))
    given: dict[str, Any] = {name: value for name, value in
                             (("frames", frames), ("fps", fps), ("seed", seed), ("model", model),
                              ("bounds", bounds), ("length", length), ("warmup", warmup),
                              ("preroll", preroll), ("layout", layout))
                             if value is not None}
    return replace(scene, **given)


def start_layout(scene: SceneFile) -> str:
    """How the fish start: the scene's layout, else a ring for the couzin model's torus (its preset
    named, or its zones as they stand, which the model's defaults are: from a random ball in the
    default region it milled for 1 seed of 8, docs/decisions.md), else a sphere."""
    if scene.layout is not None:
        return scene.layout
    if scene.model != "couzin":
        return "sphere"
    torus = scene.preset == "torus" or (scene.preset is None
                                         and (scene.couzin or CouzinParams()) == COUZIN_PRESETS["torus"])
    return "ring" if torus else "sphere"


def preroll_seconds(scene: SceneFile) -> float:
    """Seconds simulated before the first frame: the scene's, else for the couzin model
    PREROLL_PAPER_SECONDS of the paper's clock, which runs at the paper's speed over the fish's
    (the slowest species' sets it), else none."""
    if scene.preroll is not None:
        return scene.preroll
    if scene.model != "couzin" or not scene.species:
        return 0.0
    paper = (scene.couzin or CouzinParams()).speed
    return min(MAX_PREROLL, PREROLL_PAPER_SECONDS * paper / min(e.speed for e in scene.species))


def preroll_steps(scene: SceneFile) -> int:
    """Steps simulated before the first frame (SchoolConfig.preroll_frames, known before planning)."""
    return int(round(preroll_seconds(scene) * scene.fps))


def check_size(scene: SceneFile, file: str | os.PathLike | None = None, line: int | None = None,
               tracks: bool = False) -> None:
    """Refuse absurd schools before anything is built: MAX_FISH fish, MAX_FISH_FRAMES fish x frames,
    and a run whose estimated peak memory (with ``tracks``, writing the raw tracks too) is more
    than this process may use."""
    from fishgen.school import memory

    # without a scene file, the fish and frames came from the command line (--count, --frames)
    refused = FishgenError if file is not None else UsageError
    total = sum(e.count for e in scene.species)
    pre = preroll_steps(scene)
    if total > MAX_FISH or total * (scene.frames + pre) > MAX_FISH_FRAMES:
        steps = f" and {pre:,} pre-roll steps" if pre else ""
        raise refused(f"expected at most {MAX_FISH:,} fish and {MAX_FISH_FRAMES:,} fish x frames, "
                      f"found {total:,} fish x {scene.frames:,} frames{steps}", file, line)
    need, limit = memory.estimate(total, scene.frames, tracks), memory.allowed()
    if limit is not None and need > limit[0]:
        raise refused(f"expected a school that fits in {memory.size_text(limit[0])} ({limit[1]}), found "
                      f"{total:,} fish x {scene.frames:,} frames, which needs about "
                      f"{memory.size_text(need)}{' with --tracks' if tracks else ''}: "
                      "use fewer fish or frames", file, line)


def _number(where: _Where, value: Any, key: str, low: float, high: float, table: str | None = None,
            nth: int = 0, whole: bool = False) -> Any:
    kind = "a whole number" if whole else "a number"
    ok = isinstance(value, int) if whole else isinstance(value, (int, float))
    # a TOML integer may have hundreds of digits: compare it as an integer, never as a float
    ok = ok and not isinstance(value, bool) and (isinstance(value, int) or math.isfinite(value))
    if not ok or not low <= value <= high:
        raise where.fail(f"{key} as {kind} from {low:g} to {high:g}", value, key, table, nth)
    return value


def _inside(where: _Where, scene: Path, name: str, key: str, table: str, nth: int = 0) -> Path:
    """A file a scene file names: in the scene file's folder (or below), never elsewhere (an absolute
    path, ``..``, a link out), as an asset's textures are: a scene file someone sent you reads only
    what came with it."""
    from fishgen.exchange.sidefiles import side_file

    try:
        return side_file(scene, name)
    except FishgenError as err:
        raise FishgenError(err.message.replace("the asset's folder", "the scene file's folder"), where.file,
                           where.line(key, table, nth)) from None


def _declared(where: _Where, spec: Option, value: Any, key: str, table: str | None = None,
              nth: int = 0) -> Any:
    """A key that is also an option, checked by the option's own declaration."""
    return check_value(spec, value, lambda what: where.fail(f"{key} as {what}", value, key, table, nth))


def _triple(where: _Where, value: Any, key: str, table: str | None = None) -> tuple[float, float, float]:
    if not (isinstance(value, list) and len(value) == 3):
        raise where.fail(f"{key} as [x, y, z]", value, key, table)
    return tuple(float(_number(where, v, key, -MAX_COORDINATE, MAX_COORDINATE, table))  # type: ignore[return-value]
                 for v in value)


def _path(where: _Where, data: Any, table: str, folder: Path) -> tuple[TargetPath, Path | None]:
    """The path of [target] or [predator], and the CSV file it was read from (if any)."""
    if not isinstance(data, dict):
        raise where.fail(f"a [{table}] table", data, table)
    kind = data.get("path", "circle")
    known = {"path", "centre", "radius", "period", "seed"}
    for key in data:
        if key not in known:
            raise where.fail(f"one of {', '.join(sorted(known))} in [{table}]", key, key, table)
    path = TargetPath()
    csv = None
    if not isinstance(kind, str):
        raise where.fail(f"path as one of {', '.join(PATHS)} or a CSV file", kind, "path", table)
    if kind not in PATHS:
        csv = _inside(where, folder / "scene", kind, "path", table)
        path = replace(path, kind="points", points=_csv_points(where, csv, table))
    else:
        path = replace(path, kind=kind)  # type: ignore[arg-type]
    if "centre" in data:
        path = replace(path, centre=_triple(where, data["centre"], "centre", table))
    if "radius" in data:
        path = replace(path, radius=float(_number(where, data["radius"], "radius", 0.01, 1e4, table)))
    if "period" in data:
        path = replace(path, period=float(_number(where, data["period"], "period", 0.1, 1e6, table)))
    if "seed" in data:
        path = replace(path, seed=_declared(where, SEED_KEY, data["seed"], "seed", table))
    return path, csv


def _csv_points(where: _Where, path: Path, table: str) -> tuple[tuple[float, float, float, float], ...]:
    """A path as CSV rows ``t,x,y,z`` (a header row is allowed), times increasing."""
    if not path.is_file():
        raise where.fail(f"path as one of {', '.join(PATHS)} or an existing CSV file", path.name, "path",
                         table)
    if path.stat().st_size > MAX_PATH_BYTES:
        raise FishgenError(f"expected a path CSV of at most {MAX_PATH_BYTES:,} bytes, "
                           "found a larger file", path)
    rows: list[tuple[float, ...]] = []
    for number, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
        cells = [c.strip() for c in line.split(",")]
        if not line.strip():
            continue
        try:
            values = tuple(float(c) for c in cells)
        except ValueError:
            if number == 1:
                continue  # a header row
            raise FishgenError(f"expected t,x,y,z numbers, found {describe(line)}", path, number) from None
        if len(values) != 4 or not all(math.isfinite(v) for v in values):
            raise FishgenError(f"expected 4 finite numbers t,x,y,z, found {describe(line)}", path, number)
        if not (abs(values[0]) <= MAX_PATH_SECONDS and all(abs(v) <= MAX_COORDINATE for v in values[1:])):
            raise FishgenError(f"expected t within {MAX_PATH_SECONDS:g} s and x,y,z within "
                               f"{MAX_COORDINATE:g} m, as a scene's bounds are, found {describe(line)}",
                               path, number)
        if rows and values[0] <= rows[-1][0]:
            raise FishgenError(f"expected increasing times, found {values[0]:g} after {rows[-1][0]:g}", path,
                               number)
        rows.append(values)
    if len(rows) < 2:
        raise FishgenError(f"expected at least 2 rows t,x,y,z, found {len(rows)}", path)
    return tuple((r[0], r[1], r[2], r[3]) for r in rows)


def _model_of_tables(where: _Where, data: dict, scene: SceneFile) -> SceneFile:
    """A [pso] or [couzin] table picks its model when the file names none (as ``--preset`` sets
    ``--model couzin``); under another model, or beside the other table, it would be read and then
    ignored, so it is refused at its header."""
    tables = [name for name in ("pso", "couzin") if name in data]
    if len(tables) > 1:
        raise where.fail("one model's table, [pso] or [couzin]", "a [pso] and a [couzin] table", "couzin",
                         "couzin")
    for name in tables:
        if "model" in data and scene.model != name:
            raise where.fail(f'model = "{name}" (or no model) with a [{name}] table', scene.model, name, name)
        return replace(scene, model=name, table=(name, where.line(name, name)))
    return scene


def check_table(scene: SceneFile, file: str | os.PathLike) -> None:
    """Refuse a scene whose model, after the command line's ``--model`` or ``--preset``, is not the
    one its [pso] or [couzin] table is for: the table would be ignored."""
    if scene.table is not None and scene.table[0] != scene.model:
        name, line = scene.table
        raise FishgenError(f"expected the {name} model with a [{name}] table, found the {scene.model} "
                           "model from the command line", file, line)


def _couzin(where: _Where, table: Any) -> tuple[CouzinParams, str | None]:
    """[couzin]: ``preset`` (one of COUZIN_PRESETS) and any CouzinParams field overriding it; and
    the preset's name."""
    if not isinstance(table, dict):
        raise where.fail("a [couzin] table", table, "couzin")
    keys = ("preset", *COUZIN_RANGES)
    values: dict[str, Any] = {}
    preset = None
    for key, value in table.items():
        if key not in keys:
            raise where.fail(f"one of {', '.join(keys)} in [couzin]", key, key, "couzin")
        if key == "preset":
            if not isinstance(value, str) or value not in COUZIN_PRESETS:
                raise where.fail(f"preset as one of {', '.join(COUZIN_PRESETS)}", value, key, "couzin")
            preset = value
        else:
            whole = key in ("neighbours", "sampled")
            number = _number(where, value, key, *COUZIN_RANGES[key], "couzin", whole=whole)
            values[key] = int(number) if whole else float(number)
    return couzin_params(preset, **values), preset


def _variety(where: _Where, table: Any) -> Variety:
    """[variety]: size, tints and tint, each checked as its option is."""
    if not isinstance(table, dict):
        raise where.fail("a [variety] table", table, "variety")
    specs = {"size": SIZE_VARIETY, "tints": TINTS, "tint": TINT}
    values = {}
    for key, value in table.items():
        if key not in specs:
            raise where.fail(f"one of {', '.join(specs)} in [variety]", key, key, "variety")
        values[key] = _declared(where, specs[key], value, key, "variety")
    return replace(Variety(), **values)


def load_scene_file(path: str | os.PathLike) -> SceneFile:
    """Read and check a school scene file."""
    path = Path(path)
    file = os.fspath(path)
    if path.is_dir():
        raise FishgenError("expected a scene file, found a directory", path)
    if not path.is_file():
        raise FishgenError("expected an existing scene file, found none", path)
    if path.stat().st_size > MAX_SCENE_BYTES:
        raise FishgenError(f"expected a scene file of at most {MAX_SCENE_BYTES:,} bytes, found a larger file",
                           path)
    text = _text_of(path.read_bytes(), file)
    data = _loads(text, file)
    where = _Where(text, file)
    known = {"model", "frames", "fps", "seed", "bounds", "layout", "species", "target", "predator", "pso",
             "couzin", "variety", "warmup", "preroll", "length"}
    for key in data:
        if key not in known:
            raise where.fail(f"one of {', '.join(sorted(known))}", key, key)
    scene = SceneFile()
    for key, spec in (("model", MODEL), ("frames", FRAMES), ("fps", FPS), ("seed", SEED_KEY),
                      ("warmup", WARMUP), ("preroll", PREROLL), ("length", LENGTH), ("bounds", BOUNDS),
                      ("layout", LAYOUT)):
        if key in data:
            scene = replace(scene, **{key: _declared(where, spec, data[key], key)})
    entries = data.get("species", [])
    if not isinstance(entries, list) or not entries or not all(isinstance(e, dict) for e in entries):
        raise where.fail("one or more [[species]] tables", "none" if not entries else entries, "species")
    if len(entries) > MAX_SPECIES:
        raise FishgenError(f"expected at most {MAX_SPECIES} [[species]] tables (each builds its own fish; "
                           f"one table's count gives a species many fish), found {len(entries):,}",
                           where.file, where.line("file", "species", MAX_SPECIES))
    species = []
    for k, entry in enumerate(entries):
        for key in entry:
            if key not in ("file", "count", "speed"):
                raise where.fail("file, count or speed in [[species]]", key, key, "species", k)
        name = entry.get("file")
        if not isinstance(name, str):
            raise where.fail("file as a species file name", "no file" if name is None else name, "file",
                             "species", k)
        count = _declared(where, COUNT, entry.get("count", COUNT.default), "count", "species", k)
        speed = _declared(where, SPEED, entry.get("speed", SPEED.default), "speed", "species", k)
        species.append(SpeciesEntry(_inside(where, path, name, "file", "species", k), count, speed,
                                    where.line("file", "species", k), name))
    scene = replace(scene, species=tuple(species))
    if "target" in data:
        target, csv = _path(where, data["target"], "target", path.parent)
        scene = replace(scene, target=target, read=scene.read + ((csv,) if csv else ()))
    if "predator" in data:
        predator, csv = _path(where, data["predator"], "predator", path.parent)
        scene = replace(scene, predator=predator, read=scene.read + ((csv,) if csv else ()))
    if "pso" in data:
        pso = data["pso"]
        if not isinstance(pso, dict):
            raise where.fail("a [pso] table", pso, "pso")
        names = {f.name for f in fields(PsoParams)}
        values = {}
        for key, value in pso.items():
            if key not in names:
                raise where.fail(f"one of {', '.join(sorted(names))} in [pso]", key, key, "pso")
            values[key] = float(_number(where, value, key, 0, 1e3, "pso"))
        scene = replace(scene, pso=replace(PsoParams(), **values))
    if "couzin" in data:
        couzin, preset = _couzin(where, data["couzin"])
        scene = replace(scene, couzin=couzin, preset=preset)
    scene = _model_of_tables(where, data, scene)
    if "variety" in data:
        scene = replace(scene, variety=_variety(where, data["variety"]))
    total = sum(e.count for e in scene.species)
    if total > MAX_FISH or total * scene.frames > MAX_FISH_FRAMES:
        raise where.fail(f"at most {MAX_FISH:,} fish and {MAX_FISH_FRAMES:,} fish x frames",
                         f"{total:,} fish x {scene.frames:,} frames", "count", "species")
    return scene
