"""`fishgen school`: simulate a fish school and bake it into one animated asset, tracks and measures."""
from __future__ import annotations

import sys
from pathlib import Path

import click

from fishgen.assembly.fin_modes import FIN_MODES
from fishgen.assembly.swim_modes import SWIM_MODES
from fishgen.cli.params import FiniteRange

MODELS = ("boids", "pso")  # mirrors fishgen.school.model without importing numpy


@click.command("school", context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("inputs", nargs=-1, required=True, type=click.Path(path_type=Path),
                metavar="SPECIES|SCENE.toml...")
@click.option("-o", "--output", required=True, type=click.Path(path_type=Path),
              help="Animated asset to write (.glb or .gltf: the only formats that hold node animation).")
@click.option("--count", type=click.IntRange(1, 100_000), default=None,
              help="Fish per species  [default: the scene file's counts, else 50]")
@click.option("--frames", type=click.IntRange(2, 100_000), default=None,
              help="Frames to simulate and bake  [default: the scene file's, else 300]")
@click.option("--fps", type=FiniteRange(1, 1000), default=None,
              help="Frames per second  [default: the scene file's, else 30]")
@click.option("--seed", type=click.IntRange(0, 2**32 - 1), default=None,
              help="Random seed; the same seed gives byte-identical files  "
                   "[default: the scene file's, else 0]")
@click.option("--model", type=click.Choice(MODELS), default=None,
              help="boids: VRFish's brain (thesis 7.2); pso: the particle swarm following a target "
                   "(2017 report)  [default: the scene file's, else boids]")
@click.option("--tolerance", type=FiniteRange(0, 1), default=0.002, show_default=True, metavar="METRES",
              help="How far thinned keyframes may stray from the simulated path.")
@click.option("--tracks", type=click.Path(path_type=Path), default=None,
              help="Also write raw tracks: .csv or .npz (frame, time, fish, species, position, quaternion, "
                   "velocity).")
@click.option("--metrics", type=click.Path(path_type=Path), default=None,
              help="Also write the per-frame measures as JSON.")
@click.option("--plot", type=click.Path(path_type=Path), default=None,
              help="Also draw the measures over time beside a top view of the tracks (.png; needs "
                   "matplotlib, `pip install fishgen[plot]`).")
@click.option("--fins", type=click.Choice(FIN_MODES), default=None,
              help="Fin technique, as `fishgen build` has it  [default: from each species file]")
@click.option("--swim", type=click.Choice(SWIM_MODES), default="body", show_default=True,
              help="body: every fish's body waves, its tail beating faster the faster it swims; "
                   "fins: rigid bodies, only the fins move.")
@click.option("--textures", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Folder texture names resolve in  [default: as `fishgen build` resolves them]")
def school(inputs, output, count, frames, fps, seed, model, tolerance, tracks, metrics, plot, fins,
           swim, textures) -> None:
    """Simulate a school of SPECIES files (or a SCENE.toml) and bake it into an animated glb.

    Every fish of a species shares its meshes; each fish is a node with translation and
    rotation keys for the whole run, its body wave follows its own speed, and its fins beat
    phase-shifted in the same clip.
    A scene file holds species and counts, model parameters, bounds, the target path,
    a predator and the start layout; the options here override it.

    \b
    Examples:
      fishgen school params/bonybream.txt --count 200 -o out/school.glb
      fishgen school params/reef.toml -o out/reef.glb --metrics out/reef.json --tracks out/reef.npz
    """
    from fishgen.cli.params import check_inputs
    from fishgen.errors import FishgenError
    from fishgen.exchange import export
    from fishgen.exchange.registry import FORMATS, MESHES, NODE_ANIMATION, output_format
    from fishgen.school.scene_file import SceneFile, SpeciesEntry, check_size, load_scene_file, with_options

    output_format(output, [MESHES, NODE_ANIMATION])
    scene_files = [p for p in inputs if p.suffix.lower() == ".toml"]
    if scene_files and len(inputs) > 1:
        raise FishgenError(f"expected one scene file alone or species files, found {len(inputs)} inputs "
                           f"with {scene_files[0]}")
    if scene_files:
        scene = load_scene_file(scene_files[0])
    else:
        check_inputs(inputs, "school", [FORMATS["species"]], default=FORMATS["species"])
        scene = SceneFile(species=tuple(SpeciesEntry(p, 50) for p in inputs))
    scene = with_options(scene, count=count, frames=frames, fps=fps, seed=seed, model=model)
    check_size(scene)  # before anything is built
    for extra, suffixes in ((tracks, (".csv", ".npz")), (metrics, (".json",)), (plot, (".png",))):
        if extra is not None and extra.suffix.lower() not in suffixes:
            raise FishgenError(f"expected a file ending in {' or '.join(suffixes)}, found "
                               f"{extra.suffix or 'no extension'!r}", extra)

    from fishgen.school import run_school
    from fishgen.school.metrics import format_table, measures, summary, summary_table

    bar = None
    if sys.stderr.isatty():  # a person watching gets a bar; logs and CI get none
        bar = click.progressbar(length=scene.frames, label="simulating", file=sys.stderr)
        bar.__enter__()
    try:
        run = run_school(scene, fins=fins, swim=swim, tolerance=tolerance, textures_dir=textures,
                         progress=(lambda n: bar.update(n)) if bar is not None else None)
    finally:
        if bar is not None:
            bar.__exit__(None, None, None)
    written = export(run.scene, output, require=[MESHES, NODE_ANIMATION])
    per_frame = measures(run.tracks, run.group_lengths)
    warmup = min(scene.frames // 3, int(3 * scene.fps))
    numbers = summary(per_frame, warmup)
    if tracks is not None:
        from fishgen.school.tracks import write_tracks
        write_tracks(run.tracks, tracks, run.species_names)
    if metrics is not None:
        _write_metrics(metrics, run, per_frame, numbers, warmup)
    if plot is not None:
        from fishgen.school.plot import plot_school
        plot_school(plot, run, per_frame)
    size = sum(p.stat().st_size for p in written)
    kinds = ", ".join(f"{e.count} {Path(e.file).stem}" for e in scene.species)
    click.echo(f"{output}: {kinds}; {scene.frames} frames ({scene.frames / scene.fps:.1f} s), {scene.model}, "
               f"{size / 1e6:.2f} MB")
    rows = summary_table(per_frame, warmup, run.species_names)
    click.echo(format_table(rows, f"after {warmup / scene.fps:.1f} s warm-up"))


def _write_metrics(path: Path, run, per_frame: dict, numbers: dict, warmup: int) -> None:
    import json

    import numpy as np

    from fishgen.atomic import write_bytes

    def plain(value):
        if isinstance(value, dict):
            return {str(k): plain(v) for k, v in value.items()}
        if isinstance(value, np.ndarray):
            return np.round(value.astype(float), 6).tolist()
        if isinstance(value, (np.floating, np.integer)):
            return value.item()
        return value

    doc = {"species": run.species_names, "fps": run.config.fps, "frames": run.config.frames,
           "model": run.config.model, "warmup_frames": warmup, "summary": plain(numbers),
           "per_frame": plain(per_frame)}
    write_bytes(path, json.dumps(doc, indent=1, sort_keys=True).encode("utf-8"))

