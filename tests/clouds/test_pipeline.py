"""The one cube-file pipeline (fishgen.clouds.pipeline): every caller reads and fills through it, and
an empty cube stays empty however the file is scaled."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.clouds.lighting import Lighting
from fishgen.clouds.parser import load_cubes
from fishgen.clouds.pipeline import cube_clouds, read_cube_files, scaled
from fishgen.errors import UsageError

# 500 particles, the middle cube empty (as Table 4.3's line 16)
HOLLOW = "500\n3\n400, 4, 2, 2, 0, 0, 0, 0.8\n0, 1, 1, 1, 3, 0, 0, 0.5\n100, 2, 2, 2, 6, 0, 0, 0.6\n"
SCALED = [40, 0, 10]      # to 50 particles: every cube alike, the empty one still empty


def per_cube(cube_index: np.ndarray, cubes: int = 3) -> list[int]:
    return np.bincount(np.asarray(cube_index, np.int64), minlength=cubes).tolist()


def test_scaling_down_keeps_an_empty_cube_empty_and_a_small_one_alive(write_awn):
    model = load_cubes(write_awn(HOLLOW))
    assert [c.particles for c in scaled(model, 50).cubes] == SCALED
    assert [c.particles for c in scaled(model, 2).cubes] == [1, 0, 1]     # never a cube's last particle


def test_the_fill_is_seeded_per_input_offset_and_refused_over_the_limit(write_awn, tables):
    models = read_cube_files([tables["4.3"], write_awn(HOLLOW)])
    places = [(0, 0, 0), (30, 0, 0)]
    made = cube_clouds(models, seed=4, offsets=places, lighting=Lighting())
    apart = cube_clouds(models, seed=4, offsets=places, light=False)
    assert [len(c) for c in apart.clouds] == [554, 500] and apart.lit is None and made.clouds == ()
    assert np.array_equal(made.cloud.centers, np.concatenate([c.centers for c in apart.clouds]))
    assert made.cloud.light is not None and made.note is None
    alone = cube_clouds(models[1:], seed=5, light=False)      # input 1 is filled with seed 4 + 1
    assert np.allclose(alone.clouds[0].centers + [30, 0, 0], apart.clouds[1].centers, atol=1e-5)
    with pytest.raises(ValueError, match="unlit"):
        _ = alone.cloud
    with pytest.raises(UsageError, match="expected at most 1,000 particles in the scene .* in 2 files"):
        cube_clouds(models, max_particles=1000)
