"""Two draw calls a fish: one skinned mesh of at most two primitives, posed exactly as the node per
part layout is."""
from __future__ import annotations

import numpy as np
import pygltflib
import pytest

from fishgen.assembly.fish import make_fish
from fishgen.exchange import export
from fishgen.scene.pose import deformed, pose
from fishgen.species.parser import load_species
from tests.conftest import PARAMS, assert_valid_gltf

CLIPS = ("swim", "idle", "sprint", "turn_left", "turn_right", "burst")
MOVING = {"pectoral_fin_left", "pectoral_fin_right", "pelvic_fin_left", "pelvic_fin_right"}


@pytest.fixture(scope="module")
def bony():
    return load_species(PARAMS / "bonybream.txt")


def _posed(scene, clip, t):
    """Every drawn vertex, posed, in drawing order (body first, then each fin in the species' order)."""
    posed = pose(scene, t, clip)
    return np.concatenate([deformed(scene, n, p, posed)[0] for n, p in scene.drawn()])


@pytest.mark.parametrize("swim", ["body", "fins"])
def test_one_mesh_two_primitives_a_joint_per_moving_fin(bony, swim, tmp_path):
    clips = CLIPS if swim == "body" else ("swim", "idle", "sprint")
    fish = make_fish(bony, merge=True, swim=swim, clips=clips)
    scene = fish.scene
    path = tmp_path / "fish.glb"
    export(scene, path)
    assert_valid_gltf(path)
    doc = pygltflib.GLTF2().load(str(path))
    (mesh,) = doc.meshes
    assert [doc.materials[p.material].alphaMode for p in mesh.primitives] == ["OPAQUE", "MASK"]
    assert fish.facts.draw_calls == 2 and len(scene.drawn()) == 2
    (skin,) = doc.skins
    joints = [doc.nodes[j].name for j in skin.joints]
    moving = MOVING | ({"caudal_fin"} if swim == "fins" else set())
    assert joints[0] == "bonybream" and set(joints[1:]) == moving
    mesh_node = next(n for n in doc.nodes if n.mesh is not None)
    assert doc.nodes.index(mesh_node) in doc.scenes[0].nodes      # a root, as glTF asks of skinned meshes
    assert not mesh_node.translation
    prims = scene.meshes[0].primitives
    body_joints = prims[0].attributes["JOINTS_0"]
    assert not body_joints.any() and (prims[0].attributes["WEIGHTS_0"][:, 0] == 255).all()  # body on the root
    assert set(np.unique(prims[1].attributes["JOINTS_0"][:, 0])) == set(range(len(joints)))
    targets = len(fish.facts.targets)
    assert targets == (7 if swim == "body" else 0) and all(len(p.targets) == targets for p in prims)
    channels = {a.name: {(doc.nodes[c.target.node].name, c.target.path) for c in a.channels}
                for a in doc.animations}
    assert len({frozenset(v) for v in channels.values()}) == 1      # every clip drives the same things


@pytest.mark.parametrize("clip", CLIPS)
def test_the_merged_fish_poses_exactly_as_the_parts_do(bony, clip):
    parts = make_fish(bony, clips=CLIPS).scene
    merged = make_fish(bony, clips=CLIPS, merge=True).scene
    for t in np.linspace(0.0, parts.clip(clip).duration, 7):
        a, b = _posed(parts, clip, float(t)), _posed(merged, clip, float(t))
        assert a.shape == b.shape and np.abs(a - b).max() < 1e-6    # metres: float32 rounding only


def test_levels_of_a_merged_fish_share_the_root_joint(bony):
    scene = make_fish(bony, merge=True, lods=[(24, 16), (12, 8)]).scene
    roots = {scene.skins[n.skin].joints[0] for n in scene.nodes if n.skin is not None}
    assert len(scene.skins) == 2 and len(roots) == 1            # moving one node moves every level
    assert set(scene.hidden_roots) >= roots                     # the second scene holds the joints it uses
