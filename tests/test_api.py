"""The library API the README documents: every name resolves, and it works end to end."""
from __future__ import annotations

import fishgen
from tests.conftest import PARAMS, assert_valid_gltf


def test_every_public_name_resolves():
    for name in fishgen.__all__:
        assert getattr(fishgen, name) is not None


def test_readme_example(tmp_path):
    species = fishgen.load_species(PARAMS / "bonybream.txt")
    asset = fishgen.build_fish(species, fins="mask", length=0.4, fps=30)
    fishgen.export(asset, tmp_path / "bonybream.glb")
    cloud = fishgen.fill_cloud(fishgen.load_cubes(PARAMS / "clouds" / "table_4_4.awn"), seed=0)
    fishgen.export_cloud(cloud, tmp_path / "cloud.glb")
    assert len(cloud.centers) == 615
    assert_valid_gltf(tmp_path / "bonybream.glb", tmp_path / "cloud.glb")


def test_clips_and_levels_may_be_given_as_the_command_line_gives_them():
    """`build_fish(species, clips="swim")` split the name into its letters ('s,w,i,m')."""
    from fishgen.assembly.fish import make_fish
    from fishgen.species.parser import load_species

    fish = make_fish(load_species(PARAMS / "bonybream.txt"), clips="swim,idle", lods="32x24,16x12")
    assert [c.name for c in fish.facts.clips] == ["swim", "idle"]
    assert [(lv.bodies, lv.circles) for lv in fish.facts.levels] == [(32, 24), (16, 12)]
