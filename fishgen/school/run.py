"""A school's whole run: build each species once, simulate, and bake into one scene."""
from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fishgen.scene.model import Scene
from fishgen.school.model import Brain, Group, SchoolConfig, Tracks
from fishgen.school.scene_file import SceneFile

DEFAULT_BOUNDS_BODY_LENGTHS = 4.0
"""Without bounds in the scene file, the region is this many body lengths per cube-root of the count."""


@dataclass
class SchoolRun:
    config: SchoolConfig
    tracks: Tracks
    scene: Scene
    body_lengths: np.ndarray       # (N,) metres, per fish (its species' length x its size jitter)
    species_names: list[str]
    read: tuple[Path, ...] = ()    # the species files and the textures they named

    @property
    def group_lengths(self) -> list[float]:
        """Body length in metres of each species at size 1 (what fishgen.school.metrics takes)."""
        return [g.body_length for g in self.config.groups]


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
               progress: Callable[[int], None] | None = None) -> SchoolRun:
    """Build each species once, simulate the school, and bake it into one scene."""
    from fishgen.assembly.fish import make_fish
    from fishgen.school.bake import bake
    from fishgen.school.simulate import simulate
    from fishgen.species.parser import load_species

    fishes, groups = [], []
    read: list[Path] = []
    for entry in scene_file.species:
        species = load_species(entry.file, textures_dir)
        read += [Path(entry.file), *species.side_files]
        fish = make_fish(species, fins=fins, fps=scene_file.fps, swim=swim, speed=entry.speed)
        units = species.world_scale * species.scale[0]
        fishes.append(fish.scene)
        groups.append(Group(Path(entry.file).stem, entry.count, fish.facts.body_length, entry.speed,
                            brain_of(species, units)))
    count = sum(g.count for g in groups)
    region = scene_file.bounds
    if region is None:
        half = DEFAULT_BOUNDS_BODY_LENGTHS * max(g.body_length for g in groups) * max(1.0, count ** (1 / 3))
        region = ((-half, -half / 3, -half), (half, half / 3, half))
    target = scene_file.target
    config = SchoolConfig(groups=tuple(groups), model=scene_file.model,  # type: ignore[arg-type]
                          frames=scene_file.frames, fps=scene_file.fps, seed=scene_file.seed, bounds=region,
                          layout=scene_file.layout, target=target,  # type: ignore[arg-type]
                          pso=scene_file.pso, predator=scene_file.predator)
    tracks = simulate(config, progress=progress)
    lengths = np.array([groups[g].body_length for g in tracks.group]) * tracks.scale
    scene = bake(fishes, tracks, tolerance=tolerance, seed=scene_file.seed, body_lengths=lengths)
    return SchoolRun(config, tracks, scene, lengths, [g.name for g in groups], tuple(dict.fromkeys(read)))
