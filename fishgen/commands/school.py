"""`fishgen school`: simulate a fish school and bake it into one animated asset, tracks and measures."""
from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fishgen.commands import QUIET, Command, Events, Inputs, Made, Output, stage
from fishgen.exchange.registry import MESHES, NODE_ANIMATION
from fishgen.options import (
    FILE,
    PROTOTYPES,
    FiniteRange,
    compact_option,
    declare,
    fins_option,
    lods_option,
    merge_option,
    option,
    prototypes_option,
    swim_option,
    textures_option,
)
from fishgen.school.scene_file import (
    BOUNDS,
    COUNT,
    FPS,
    FRAMES,
    LAYOUT,
    LENGTH,
    MODEL,
    PREROLL,
    PRESET,
    SEED_KEY,
    SIZE_VARIETY,
    SPEED,
    TINT,
    TINTS,
    WARMUP,
)

SIDE_OUTPUTS = {"tracks": (".csv", ".npz"), "metrics": (".json",), "plot": (".png",)}


@dataclass(frozen=True)
class SchoolOptions:
    count: int | None = declare(COUNT, default=None, shown_default=f"the scene file's counts, else "
                                                                   f"{COUNT.default}")
    frames: int | None = declare(FRAMES, default=None, shown_default=f"the scene file's, else "
                                                                     f"{FRAMES.default}")
    fps: float | None = declare(FPS, default=None, shown_default=f"the scene file's, else {FPS.default:g}")
    seed: int | None = declare(SEED_KEY, default=None,
                               shown_default="the scene file's, else 0; in a batch, derived from the "
                                             "output's name")
    model: str | None = declare(MODEL, default=None, shown_default=f"the scene file's, else {MODEL.default}")
    preset: str | None = declare(PRESET)
    speed: float | None = declare(SPEED, default=None,
                                  shown_default=f"the scene file's, else {SPEED.default:g}")
    length: float | None = declare(LENGTH)
    bounds: Any = declare(BOUNDS, shown_default=f"the scene file's, else {BOUNDS.shown_default}")
    layout: str | None = declare(LAYOUT, shown_default=f"the scene file's, else {LAYOUT.shown_default}")
    warmup: float | None = declare(WARMUP, shown_default=f"the scene file's, else {WARMUP.shown_default}")
    preroll: float | None = declare(PREROLL, shown_default=f"the scene file's, else {PREROLL.shown_default}")
    size_variety: float | None = declare(SIZE_VARIETY, default=None,
                                         shown_default=f"the scene file's, else {SIZE_VARIETY.default:g}")
    tints: int | None = declare(TINTS, default=None, shown_default=f"the scene file's, else {TINTS.default}",
                                help=TINTS.help + " Only 1 with --lods or --merge.")
    tint: float | None = declare(TINT, default=None, shown_default=f"the scene file's, else {TINT.default:g}")
    tolerance: float = option(FiniteRange(0, 1),
                              "How far thinned keyframes may stray from the simulated path.",
                              0.002, metavar="METRES")
    tracks: Path | None = option(FILE, "Also write raw tracks: .csv or .npz (frame, time, fish, species, "
                                 "position, quaternion, velocity).", shown_default="none", manifest=False)
    metrics: Path | None = option(FILE, "Also write the per-frame measures as JSON.", shown_default="none",
                                  manifest=False)
    plot: Path | None = option(FILE,
                               "Also draw the measures over time beside a top view of the tracks (.png; "
                               "needs matplotlib, `pip install 'fishgen[plot]'`).", shown_default="none",
                               manifest=False)
    fins: str | None = fins_option("from each species file")
    swim: str = swim_option("body: every fish's body waves, its tail beating faster the faster it swims; "
                            "fins: rigid bodies, only the fins move.")
    textures: Path | None = textures_option("as `fishgen build` resolves them")
    compact: bool = compact_option()
    lods: tuple[tuple[int, int], ...] | None = lods_option()
    merge: bool = merge_option()
    prototypes: int | None = prototypes_option()


def check_options(options: SchoolOptions, output: str | os.PathLike | None = None) -> None:
    """Options that cannot go together, refused before any work (and at a manifest job's line)."""
    from fishgen.errors import UsageError

    if (options.lods or options.merge) and (options.tints or 1) > 1:
        raise UsageError("expected --tints 1 with --lods or --merge (colour variants copy the part meshes), "
                         f"found --tints {options.tints}")
    if options.preset is not None and options.model not in (None, "couzin"):
        raise UsageError(f"expected --preset with the couzin model, found --model {options.model}")
    if options.prototypes is not None and output is not None:
        from fishgen.exchange.registry import INSTANCES, by_extension

        fmt = by_extension(output)
        if fmt is not None and INSTANCES not in fmt.holds:   # a glb's fish share meshes, not prototypes
            raise UsageError(f"expected --prototypes with a USD output (.usdc, .usda, .usdz), found -o "
                             f"{os.fspath(output)!r}")


COMMAND = Command(
    name="school",
    summary="Simulate a fish school and bake it into an animated glTF or USD, tracks and measures.",
    help="""Simulate a school of SPECIES files (or a SCENE.toml) and bake it into an animated glTF or USD.

    Every fish of a species shares its meshes; each fish is a node with translation and
    rotation keys for the whole run, its body wave follows its own speed, and its fins beat
    phase-shifted in the same clip.
    A scene file holds species and counts, model parameters, bounds, the target path,
    a predator and the start layout; the options here override it.

    \b
    Examples:
      fishgen school params/bonybream.txt --count 200 -o out/school.glb
      fishgen school params/reef.toml -o out/reef.glb --metrics out/reef.json --tracks out/reef.npz
    """,
    options=SchoolOptions,
    run="fishgen.commands.school:school",
    inputs=Inputs("SPECIES|SCENE.toml..."),
    output=Output("Animated asset to write: .glb or .gltf (a node per fish), or .usdc, .usda or .usdz (a "
                  "PointInstancer of skinned fish; needs usd-core).",
                  holds=(MESHES, NODE_ANIMATION)),
    batch=True,
    together=True,
    check=check_options,
)


@dataclass(frozen=True)
class SchoolFacts:
    species: tuple[tuple[str, int], ...]   # (name, count)
    frames: int
    fps: float
    model: str
    bytes: int
    warmup_frames: int
    table: str                             # the summary of the measures after the warm-up


def school(inputs: Sequence[Path], output: str | os.PathLike,
           options: SchoolOptions = SchoolOptions(),
           events: Events = QUIET) -> Made:
    """Simulate, bake and write the school; the side outputs (tracks, metrics, plot) are written
    only when the glb was, and every target is checked before the simulation starts."""
    inputs = COMMAND.given(inputs, options)
    output = Path(output)
    from fishgen.commands.paths import (
        check_inputs,
        check_targets,
        needs,
        output_at_fault,
        read_beside,
        suffix_of,
    )
    from fishgen.errors import UsageError, either, plural
    from fishgen.exchange.registry import FORMATS, INSTANCES, MESHES, NODE_ANIMATION, output_format
    from fishgen.school.scene_file import (
        SceneFile,
        SpeciesEntry,
        check_size,
        check_species_files,
        check_table,
        load_scene_file,
        preroll_steps,
        with_options,
    )

    with output_at_fault():
        instanced = INSTANCES in output_format(output, [MESHES, NODE_ANIMATION]).holds
    kinds = check_inputs(inputs, "school", [FORMATS["school scene"], FORMATS["species"]],
                         default=FORMATS["species"])
    scene_files = [p for p, kind in zip(inputs, kinds, strict=True) if kind is FORMATS["school scene"]]
    if scene_files and len(inputs) > 1:
        raise UsageError(f"expected one scene file alone or species files, found {len(inputs)} inputs "
                         f"with {scene_files[0]}")
    sides = {name: getattr(options, name) for name in SIDE_OUTPUTS if getattr(options, name) is not None}
    for name, path in sides.items():
        suffix_of(path, SIDE_OUTPUTS[name], f"--{name}")
    if "plot" in sides:
        needs("matplotlib", "plot", "--plot")
    if scene_files:
        scene = load_scene_file(scene_files[0])
        check_species_files(scene, scene_files[0])
    else:
        scene = SceneFile(species=tuple(SpeciesEntry(p) for p in inputs))
    check_options(options, output)
    variety = {key: value for key, value in (("size", options.size_variety), ("tints", options.tints),
                                             ("tint", options.tint)) if value is not None}
    scene = with_options(scene, count=options.count, frames=options.frames, fps=options.fps,
                         seed=options.seed, model=options.model, speed=options.speed, bounds=options.bounds,
                         length=options.length, warmup=options.warmup, preset=options.preset,
                         variety=variety, preroll=options.preroll, layout=options.layout)
    # before anything is built
    if scene_files:
        check_table(scene, scene_files[0])
    check_size(scene, scene_files[0] if scene_files else None, tracks="tracks" in sides)
    species_files = [e.file for e in scene.species]
    textures = read_beside(species_files, [FORMATS["species"]] * len(species_files), options.textures)
    check_targets([output, *sides.values()], [*inputs, *species_files, *scene.read, *textures])

    from fishgen.school import run_school

    steps = scene.frames + preroll_steps(scene)
    # baking and writing weigh about a frame simulated each, a frame (2,000 fish: 0.5 s
    # simulated, then 0.9 s baked and written that the bar, at 100 %, did not count)
    with events.progress("simulating", steps + 2 * scene.frames) as bar:
        simulated = 0

        def step(n: int) -> None:
            nonlocal simulated
            bar.update(n)
            simulated += n
            if simulated == steps:
                stage(bar, "baking")

        run = run_school(scene, fins=options.fins, swim=options.swim, tolerance=options.tolerance,
                         textures_dir=options.textures, progress=step, lods=options.lods,
                         merge=options.merge,
                         prototypes=(options.prototypes or PROTOTYPES) if instanced else None)
        if options.compact:
            from fishgen.assembly.compact import compact_clips

            compact_clips(run.scene)
        bar.update(scene.frames)
        stage(bar, "writing")
        warmup = run.warmup_frames
        per_frame: dict = {}
        numbers: dict = {}
        table = ""
        if "metrics" in sides or "plot" in sides:
            import numpy as np

            from fishgen.school.metrics import summary

            # to the digits the file keeps, before the means: the measures' sums go through BLAS,
            # whose kernels (one per CPU family) differ in the last bits, and the summary's full
            # floats showed it (OPENBLAS_CORETYPE=Zen changed metrics.json; QA pass 17)
            per_frame = {k: np.round(v, METRIC_DIGITS) for k, v in run.measures(every_frame=True).items()}
            numbers = summary(per_frame, warmup)
        if events.summary:  # else nobody reads the table: only what it prints is measured
            table = run.summary(per_frame or None)
        files, sizes = _write_all(output, run, sides, per_frame, numbers, warmup)
        bar.update(scene.frames)
    # said once written: a run that fails keeps its one line
    if scene.warmup is not None and round(scene.warmup * scene.fps) > warmup:
        events.note(f"{output}: a warm-up of {scene.warmup:g} s is as long as the run or longer "
                    f"({scene.frames / scene.fps:.1f} s): the summary measures its last frame only")
    crowded = _crowded(run.config)
    if crowded:
        events.note(f"{output}: {crowded}")
    size = sum(n for p, n in sizes.items() if p not in sides.values())
    counted = tuple(zip(run.species_names, (e.count for e in scene.species), strict=True))
    kinds_line = ", ".join(f"{count} {name}" for name, count in counted)
    # an instancer's prototypes keep the finest level and their own keys: said, as `build` says it
    dropped = [what for what, given in (("levels of detail", options.lods), ("compact keys", options.compact))
               if instanced and given]
    note = f" ({output.suffix[1:].upper()} holds no {either(dropped)})" if dropped else ""
    # a .gltf's buffer and images, a USD's textures: counted in the size, and said, as `build` says them
    beside = [p for p in sizes if Path(p) != Path(output) and p not in sides.values()]
    line = (f"{output}: {kinds_line}; {scene.frames} frames ({scene.frames / scene.fps:.1f} s), "
            f"{scene.model}, {size / 1e6:.2f} MB{note}"
            + (f" (+{plural(len(beside), 'file')})" if beside else ""))
    facts = SchoolFacts(counted, scene.frames, scene.fps,
                        scene.model, size, warmup, table)
    read = tuple(dict.fromkeys([*inputs, *scene.read, *run.read]))
    return Made(tuple(files), read, (line, table) if table else (line,), facts)


def _crowded(config) -> str | None:
    """What to say of bounds smaller than a body length cubed for each fish (the school then crowds
    and its fish overlap whatever the model does), or None."""
    import math

    lo, hi = config.bounds
    volume = math.prod(float(b) - float(a) for a, b in zip(lo, hi, strict=True))
    need = sum(g.count * g.body_length ** 3 for g in config.groups)
    if volume >= need:
        return None
    count = sum(g.count for g in config.groups)
    return (f"the bounds hold {volume:.3g} m³, less than a body length cubed for each fish ({need:.3g} m³ "
            f"for {count:,}): they crowd and overlap; give wider --bounds")


def _write_all(output: Path, run, sides: dict[str, Path], per_frame: dict, numbers: dict,
               warmup: int) -> tuple[list[Path], dict[Path, int]]:
    """The glb and every side output, all or none, and each one's size (read while staged: under
    the CLI they land only once the summary is printed)."""
    from fishgen.atomic import together, write_bytes
    from fishgen.exchange import export
    from fishgen.exchange.registry import MESHES, NODE_ANIMATION

    with together() as staged:
        files = export(run.scene, output, require=[MESHES, NODE_ANIMATION])
        if "tracks" in sides:
            from fishgen.school.tracks import write_tracks
            files.append(write_tracks(run.tracks, sides["tracks"], run.species_names))
        if "metrics" in sides:
            write_bytes(sides["metrics"], _metrics_json(run, per_frame, numbers, warmup))
            files.append(sides["metrics"])
        if "plot" in sides:
            from fishgen.school.plot import plot_school
            files.append(plot_school(sides["plot"], run, per_frame))
        sizes = {target: os.path.getsize(tmp) for tmp, target in staged}
    return files, sizes


METRIC_DIGITS = 6
"""Decimals a measure keeps in metrics.json, per frame and in the summary."""


def _metrics_json(run, per_frame: dict, numbers: dict, warmup: int) -> bytes:
    import json
    import math

    import numpy as np

    def plain(value: Any) -> Any:
        """JSON values; a measure that has no value (NaN: a one-fish species' neighbour distance) or
        none finite is null, since strict JSON parsers refuse NaN and Infinity."""
        if isinstance(value, dict):
            return {str(k): plain(v) for k, v in value.items()}
        if isinstance(value, list):
            return [plain(v) for v in value]
        if isinstance(value, np.ndarray):
            rounded = np.round(value.astype(float), METRIC_DIGITS).astype(object)
            rounded[~np.isfinite(value.astype(float))] = None
            return rounded.tolist()
        if isinstance(value, (np.floating, np.integer, float)):
            number = round(float(value), METRIC_DIGITS)
            return number if math.isfinite(number) else None
        return value

    doc = {"species": run.species_names, "fps": run.config.fps, "frames": run.config.frames,
           "model": run.config.model, "warmup_frames": warmup, "preroll_frames": run.config.preroll_frames,
           "summary": plain(numbers),
           "per_frame": plain(per_frame)}
    return json.dumps(doc, indent=1, sort_keys=True, allow_nan=False).encode("utf-8")
