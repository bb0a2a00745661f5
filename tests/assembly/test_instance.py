"""Many fish sharing one species' meshes, in either layout and with levels of detail: the fish side
of `fishgen school --merge/--lods/--compact`."""
from __future__ import annotations

import numpy as np
import pygltflib
import pytest

from fishgen.assembly.fish import make_fish
from fishgen.assembly.instance import add_fish, add_species, pad_weights
from fishgen.exchange import export
from fishgen.geometry.body_wave import wave_weights
from fishgen.scene.model import Channel, Clip, Sampler, Scene
from fishgen.scene.pose import deformed, pose
from fishgen.species.parser import load_species
from tests.conftest import PARAMS, assert_valid_gltf


@pytest.mark.parametrize("merge", [False, True], ids=["parts", "merged"])
def test_fish_share_meshes_move_whole_and_keep_their_levels(merge, tmp_path):
    fish = make_fish(load_species(PARAMS / "bonybream.txt"), merge=merge, lods=[(16, 12), (8, 6)],
                     clips=("swim", "turn_left"))
    school = Scene(name="school")
    species = add_species(school, fish.scene)
    times = np.array([0.0, 1.0], np.float32)
    channels = []
    for k in range(3):
        made = add_fish(school, species, f"bonybream_{k:05d}")
        go = Sampler(times, np.array([[k, 0, 0], [k, 0, 2.0]], np.float32))
        channels += [Channel(m, "translation", go) for m in made.movers]
        channels += [Channel(node, "rotation", c.sampler) for node, c in made.fins]
        weights = pad_weights(wave_weights(np.array([0.0, np.pi])), species.targets)
        channels += [Channel(node, "weights", Sampler(times, weights)) for node in made.waving]
    school.clips.append(Clip("school", channels))
    path = tmp_path / "school.glb"
    export(school, path)
    assert_valid_gltf(path)
    doc = pygltflib.GLTF2().load(str(path))
    assert len(doc.meshes) == len(fish.scene.meshes)                        # shared, not copied
    finest = [n for n in doc.nodes if "MSFT_lod" in (n.extensions or {})]
    assert [n.name for n in finest] == [f"bonybream_{k:05d}_LOD0" for k in range(3)]
    assert len({tuple(n.extensions["MSFT_lod"]["ids"]) for n in finest}) == 3     # each its own levels
    assert len(doc.skins) == (6 if merge else 0)                            # a skin per fish and level
    rest = pose(fish.scene)
    base = np.concatenate([deformed(fish.scene, n, p, rest)[0] for n, p in fish.scene.drawn()])
    at_one = pose(school, 1.0, "school")
    drawn = school.drawn()
    per_fish = len(fish.scene.drawn())
    for k in range(3):
        mine = drawn[k * per_fish:(k + 1) * per_fish]
        moved = np.concatenate([deformed(school, n, p, at_one)[0] for n, p in mine])
        shift = (moved - base).mean(axis=0)
        assert shift == pytest.approx([k, 0.0, 2.0], abs=0.02)   # where its root went (the wave: a little)
