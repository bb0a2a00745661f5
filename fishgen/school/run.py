"""A school's whole run: build each species once, simulate, and bake into one scene; then measure."""
from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from fishgen.scene.model import Scene
from fishgen.school.model import (
    WARMUP_SECONDS,
    WARMUP_SHARE,
    Brain,
    CouzinParams,
    Group,
    SchoolConfig,
    Tracks,
    Variety,
)
from fishgen.school.scene_file import SceneFile

DEFAULT_BOUNDS_BODY_LENGTHS = 4.0
"""Without bounds in the scene file, the region is this many body lengths per cube-root of the count."""
EXTRAS_KEY = "fishgen_school"
"""The member of a school file's glTF scene extras that records the run: {"warmup": seconds,
"model": name, "fps": frames per second, "frames": count, "preroll": seconds simulated before the
first frame}."""


def warmup_frames(frames: int, fps: float, seconds: float | None = None) -> int:
    """Frames the school takes to form from its start layout: `seconds` when given, else the first
    third of the run, at most WARMUP_SECONDS; never the whole run."""
    if seconds is None:
        return min(int(frames * WARMUP_SHARE), int(WARMUP_SECONDS * fps))
    return max(0, min(int(round(seconds * fps)), frames - 1))


@dataclass
class SchoolRun:
    config: SchoolConfig
    tracks: Tracks
    scene: Scene
    body_lengths: np.ndarray       # (N,) metres, per fish (its species' length x its size jitter)
    species_names: list[str]
    read: tuple[Path, ...] = ()    # the species files and the textures they named
    warmup_frames: int = 0         # frames before the school has formed (the summary skips them)

    @property
    def group_lengths(self) -> list[float]:
        """Body length in metres of each species at size 1 (what fishgen.school.metrics takes)."""
        return [g.body_length for g in self.config.groups]

    def measures(self, every_frame: bool = False) -> dict[str, np.ndarray]:
        """Per-frame measures (fishgen.school.metrics): by default only what the summary table
        prints, from the warm-up on (the frames before are NaN); `every_frame` measures all of
        them in every frame (for --metrics and --plot)."""
        from fishgen.school.metrics import PRINTED, measures

        if every_frame:
            return measures(self.tracks, self.group_lengths)
        return measures(self.tracks, self.group_lengths, start=self.warmup_frames, only=PRINTED)

    def summary(self, per_frame: dict[str, np.ndarray] | None = None) -> str:
        """The one-screen table of the measures after the warm-up, mean and worst."""
        from fishgen.school.metrics import format_table, summary_table

        per_frame = self.measures() if per_frame is None else per_frame
        rows = summary_table(per_frame, self.warmup_frames, self.species_names)
        steps = self.config.preroll_frames
        settled = [f"{steps / self.config.fps:.3g} s pre-roll"] if steps else []
        if self.warmup_frames or not settled:
            settled.append(f"{self.warmup_frames / self.config.fps:.1f} s warm-up")
        return format_table(rows, "after " + " and ".join(settled))


def brain_of(species, body_length_units: float) -> Brain:
    """A species file's urge weightings as a Brain; distances from VRFish world units to body lengths.

    The file's repel distance is a fraction of a body length, which is why VRFish's fish swam
    through each other (thesis 7.3): keep-away is at least one body length here.
    """
    b = species.behaviour
    if b is None:
        return Brain()
    return Brain(random=b.random, center=b.center, keepaway=b.keepaway,
                 repel_distance=max(1.0, b.repel_distance / body_length_units), speed=b.speed,
                 change_rate=max(1.0, b.change_rate), direction=b.direction,
                 flee=(b.flee[0], max(1.0, b.flee[1] / body_length_units)))


def run_school(scene_file: SceneFile, *, fins: str | None = None, swim: str = "body",
               tolerance: float = 0.002,
               textures_dir: str | os.PathLike | None = None,
               progress: Callable[[int], None] | None = None,
               couzin: CouzinParams | None = None, variety: Variety | None = None,
               warmup: float | None = None, length: float | None = None,
               lods: tuple[tuple[int, int], ...] | None = None, merge: bool = False,
               prototypes: int | None = None) -> SchoolRun:
    """Build each species once, simulate the school, and bake it into one scene.

    `couzin`, `variety` and `warmup` (seconds) default to the scene file's (its `couzin`,
    `variety` and `warmup` members when it has them), else CouzinParams(), Variety() and the
    default warm-up. `length`: every species' nose-to-tail length in metres (default: each
    species file's own). `lods`, `merge`: each species built as `fishgen build --lods/--merge`
    builds it, every fish a copy of its node tree over shared meshes (no colour variants then).
    `prototypes`: the school as an instancer of that many phase-shifted prototypes per species
    (:func:`fishgen.school.bake.bake_prototypes`, what USD writes) instead of a node per fish."""
    from fishgen.school.bake import bake, bake_instanced, bake_prototypes
    from fishgen.school.simulate import simulate

    variety = _given(variety, scene_file, "variety", Variety())
    warmup = _given(warmup, scene_file, "warmup", None)
    length = _given(length, scene_file, "length", None)
    config, fishes, read = plan_school(scene_file, fins=fins, swim=swim, textures_dir=textures_dir,
                                       couzin=couzin, variety=variety, length=length, lods=lods,
                                       merge=merge)
    tracks = simulate(config, progress=progress)
    groups = config.groups
    lengths = np.array([groups[g].body_length for g in tracks.group]) * tracks.scale
    if prototypes is not None:
        scene = bake_prototypes(fishes, tracks, prototypes=prototypes, seed=scene_file.seed, fps=config.fps,
                                tints=variety.tints, tint=variety.tint)
    elif lods or merge:
        scene = bake_instanced(fishes, tracks, tolerance=tolerance, seed=scene_file.seed,
                               body_lengths=lengths)
    else:
        scene = bake(fishes, tracks, tolerance=tolerance, seed=scene_file.seed, body_lengths=lengths,
                     tints=variety.tints, tint=variety.tint)
    # a pre-rolled school is formed at frame 0: no warm-up unless one is asked for
    pre = config.preroll_frames
    settle = warmup_frames(config.frames, config.fps, 0.0 if warmup is None and pre else warmup)
    scene.extras[EXTRAS_KEY] = {"warmup": round(settle / config.fps, 6), "model": config.model,
                                "fps": config.fps, "frames": config.frames,
                                "preroll": round(pre / config.fps, 6)}   # as simulated: whole steps
    return SchoolRun(config, tracks, scene, lengths, [g.name for g in groups], read, warmup_frames=settle)


def plan_school(scene_file: SceneFile, *, fins: str | None = None, swim: str = "body",
                textures_dir: str | os.PathLike | None = None, couzin: CouzinParams | None = None,
                variety: Variety | None = None,
                length: float | None = None, lods: tuple[tuple[int, int], ...] | None = None,
                merge: bool = False) -> tuple[SchoolConfig, list[Scene], tuple[Path, ...]]:
    """What run_school simulates, each species built once (as `fishgen build` builds it), and
    the files that took (species files and the textures they name)."""
    from fishgen.assembly.fish import make_fish
    from fishgen.school.scene_file import preroll_seconds, start_layout
    from fishgen.species.parser import load_species

    couzin = _given(couzin, scene_file, "couzin", CouzinParams())
    variety = _given(variety, scene_file, "variety", Variety())
    length = _given(length, scene_file, "length", None)
    fishes: list[Scene] = []
    groups: list[Group] = []
    read: list[Path] = []
    for entry in scene_file.species:
        species = load_species(entry.file, textures_dir)
        read += [Path(entry.file), *species.side_files]
        fish = make_fish(species, fins=fins, fps=scene_file.fps, swim=swim, speed=entry.speed, length=length,
                         lods=lods, merge=merge)
        units = species.world_scale * species.scale[0]
        fishes.append(fish.scene)
        # a species listed twice is two schools: told apart by number in the summary and the tracks
        name = Path(entry.file).stem
        before = [Path(e.file).stem for e in scene_file.species[:len(groups)]].count(name)
        groups.append(Group(f"{name} ({before + 1})" if before else name, entry.count, fish.facts.body_length,
                            entry.speed, brain_of(species, units)))
    count = sum(g.count for g in groups)
    region = scene_file.bounds
    if region is None:
        half = DEFAULT_BOUNDS_BODY_LENGTHS * max(g.body_length for g in groups) * max(1.0, count ** (1 / 3))
        region = ((-half, -half / 3, -half), (half, half / 3, half))
    config = SchoolConfig(groups=tuple(groups), model=scene_file.model,  # type: ignore[arg-type]
                          frames=scene_file.frames, fps=scene_file.fps, seed=scene_file.seed, bounds=region,
                          layout=start_layout(scene_file),  # type: ignore[arg-type]
                          target=scene_file.target,
                          pso=scene_file.pso, predator=scene_file.predator, couzin=couzin,
                          size_jitter=variety.size,
                          preroll=preroll_seconds(replace(scene_file, couzin=couzin)))
    return config, fishes, tuple(dict.fromkeys(read))


def school_extras(scene: Scene) -> dict[str, Any] | None:
    """What a school file records of its run (EXTRAS_KEY), or None when it holds none that is valid:
    for `fishgen preview`, to start after the warm-up."""
    record = scene.extras.get(EXTRAS_KEY) if isinstance(scene.extras, dict) else None
    if not isinstance(record, dict):
        return None
    warm = record.get("warmup")
    if isinstance(warm, bool) or not isinstance(warm, (int, float)) or not np.isfinite(warm) or warm < 0:
        return None
    return record


def _given(value, scene_file: SceneFile, name: str, default):
    if value is not None:
        return value
    member = getattr(scene_file, name, None)
    return default if member is None else member
