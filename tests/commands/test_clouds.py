"""fishgen.commands.clouds: what the use case tells a terminal while it works."""
from __future__ import annotations

import pytest

from fishgen.commands import Events
from fishgen.commands.clouds import CloudsOptions, clouds
from tests.conftest import PARAMS
from tests.progress_bars import recorded_bars


def _cube_file(path, particles: int):
    path.write_text(f"{particles}\n2\n{particles // 2}, 6, 3, 4, 0, 0, 0, 1.5\n"
                    f"{particles - particles // 2}, 5, 4, 4, 4, 1, 0, 1.2\n")
    return path


@pytest.mark.parametrize("particles", [615, 150_000])
def test_a_cloud_is_filled_and_lit_on_one_bar_that_ends_full(tmp_path, particles):
    """`fishgen clouds` drew no bar: 10^7 particles were 1.3 s of a silent terminal (QA pass 21).
    A step a particle filled and two a particle lit (the light weighs about twice the fill); a
    big cloud's light advances slab group by group and chunk by chunk, not at its end alone."""
    source = PARAMS / "clouds" / "table_4_4.awn" if particles == 615 else _cube_file(tmp_path / "c.awn",
                                                                                     particles)
    bars, progress = recorded_bars()
    clouds([source], tmp_path / "c.ply", CloudsOptions(), Events(progress=progress))
    assert [(label, total) for label, total, _ in bars] == [("filling and lighting", 3 * particles)]
    updates = bars[0][2]
    assert sum(updates) == 3 * particles and min(updates) > 0
    if particles > 2048:       # lit through slabs: the projection, the splats, each chunk read
        assert len(updates) - (-(-particles // (1 << 16))) >= 4, updates


def test_an_unlit_cloud_counts_its_fill_alone(tmp_path):
    bars, progress = recorded_bars()
    clouds([_cube_file(tmp_path / "c.awn", 70_000)], tmp_path / "c.ply", CloudsOptions(light=False),
           Events(progress=progress))
    assert bars == [("filling", 70_000, [65_536, 70_000 - 65_536])]


def test_a_volume_counts_its_particles_splatted_on_a_bar_of_its_own(tmp_path):
    """10^6 particles took 20 s to voxelize after the fill's bar was full (a review)."""
    bars, progress = recorded_bars()
    table = PARAMS / "clouds" / "table_4_4.awn"
    clouds([table], tmp_path / "c.nvdb", CloudsOptions(), Events(progress=progress))
    assert [(label, total) for label, total, _ in bars] == [("filling and lighting", 3 * 615),
                                                            ("voxelizing", 615)]
    assert sum(bars[1][2]) == 615 and len(bars[1][2]) >= 1


def test_a_scene_past_the_limit_is_refused_before_any_bar(tmp_path):
    """Two files each under --max-particles, over it together: the refusal came with the bar drawn."""
    from fishgen.errors import UsageError

    bars, progress = recorded_bars()
    table = PARAMS / "clouds" / "table_4_4.awn"
    with pytest.raises(UsageError, match="expected at most 1,000 particles in the scene"):
        clouds([table, table], tmp_path / "c.ply", CloudsOptions(max_particles=1000),
               Events(progress=progress))
    assert bars == []
