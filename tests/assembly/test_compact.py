"""Smaller animation, the core glTF way: normalized 16-bit rotation keys and morph weights."""
from __future__ import annotations

import numpy as np
import pygltflib
import pytest

from fishgen.assembly.compact import (
    compact_clips,
    quantize_rotations,
    quantize_weights,
    rotation_error_degrees,
)
from fishgen.assembly.fish import make_fish
from fishgen.exchange import export
from fishgen.exchange.gltf_reader import read_gltf
from fishgen.scene.pose import deformed, pose
from fishgen.species.parser import load_species
from tests.conftest import PARAMS, assert_valid_gltf

CLIPS = ("swim", "idle", "sprint", "turn_left", "turn_right", "burst")
FLOAT, SHORT, UNSIGNED_SHORT = 5126, 5122, 5123


def test_a_unit_quaternion_loses_at_most_a_few_thousandths_of_a_degree():
    q = np.random.default_rng(3).normal(size=(20000, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    stored = quantize_rotations(q)
    assert stored.dtype == np.int16
    assert rotation_error_degrees(q, stored) < 0.01


def test_weights_outside_zero_to_one_are_refused():
    assert quantize_weights(np.array([0.0, 0.5, 1.0])).tolist() == [0, 32768, 65535]
    with pytest.raises(ValueError):
        quantize_weights(np.array([-0.5]))


@pytest.mark.parametrize("merge", [False, True], ids=["parts", "merged"])
def test_compact_files_store_normalized_shorts_and_pose_as_before(merge, tmp_path):
    species = load_species(PARAMS / "bonybream.txt")
    plain = make_fish(species, clips=CLIPS, merge=merge).scene
    small = make_fish(species, clips=CLIPS, merge=merge, compact=True).scene
    export(plain, tmp_path / "plain.glb")
    export(small, tmp_path / "small.glb")
    assert_valid_gltf(tmp_path / "small.glb")
    assert (tmp_path / "small.glb").stat().st_size < (tmp_path / "plain.glb").stat().st_size
    doc = pygltflib.GLTF2().load(str(tmp_path / "small.glb"))
    kinds = set()
    for anim in doc.animations:
        for channel in anim.channels:
            out = doc.accessors[anim.samplers[channel.sampler].output]
            kinds.add((channel.target.path, out.componentType, bool(out.normalized)))
    assert kinds == {("rotation", SHORT, True), ("weights", UNSIGNED_SHORT, True)}
    back = read_gltf(tmp_path / "small.glb")   # fishgen's own reader plays it as a client would
    for clip in CLIPS:
        for t in np.linspace(0.0, plain.clip(clip).duration, 5):
            a, b = pose(plain, float(t), clip), pose(back, float(t), clip)
            for (na, pa), (nb, pb) in zip(plain.drawn(), back.drawn(), strict=True):
                assert np.abs(deformed(plain, na, pa, a)[0] - deformed(back, nb, pb, b)[0]).max() < 2e-5


def test_each_shared_sampler_is_quantized_once():
    scene = make_fish(load_species(PARAMS / "bonybream.txt"), clips=("swim",)).scene
    assert compact_clips(scene) < 0.01
    weights = {id(c.sampler) for c in scene.clips[0].channels if c.path == "weights"}
    assert len(weights) == 1 and scene.clips[0].channels[-1].sampler.values.dtype == np.uint16
