"""The default boids school holds together (issue 23): BonyBream as `fishgen school` sets it up
(its species file's brain, its length, the default region), measured after the warm-up."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.school.metrics import measures, summary
from fishgen.school.run import plan_school, warmup_frames
from fishgen.school.scene_file import SceneFile, SpeciesEntry
from fishgen.school.simulate import simulate
from tests.conftest import PARAMS


def after_warmup(*entries: tuple[str, int], seed: int = 0) -> dict:
    scene = SceneFile(species=tuple(SpeciesEntry(PARAMS / f"{name}.txt", count) for name, count in entries),
                      seed=seed)
    config, _, _ = plan_school(scene, swim="fins")
    tracks = simulate(config)
    warm = warmup_frames(config.frames, config.fps)
    return summary(measures(tracks, [g.body_length for g in config.groups], start=warm), warm)


@pytest.mark.parametrize("seed", [0, 1])
def test_a_thousand_bonybream_are_one_polarized_school(seed):
    s = after_warmup(("bonybream", 1000), seed=seed)
    assert s["groups_peak"] == [1.0]                   # one group in every frame
    assert s["polarization"][0] > 0.9 and s["polarization_least"][0] > 0.8
    assert s["overlaps_peak"] == 0.0


def test_two_species_of_a_hundred_are_one_polarized_school_each_apart():
    s = after_warmup(("bonybream", 100), ("threadfingoldie", 100))
    assert s["groups_peak"] == [1.0, 1.0]
    assert min(s["polarization_least"]) > 0.8
    assert s["overlaps_peak"] == 0.0 and s["mixed_groups_peak"] == 0.0
    assert np.isfinite(s["nearest_neighbour"]) and 0.5 < s["nearest_neighbour"] < 2.0
