"""Baking tracks: shared meshes, one node per fish, thinned keys within tolerance, phased fins."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.assembly.fish import build_fish
from fishgen.exchange.gltf import glb_bytes
from fishgen.exchange.gltf_reader import read_gltf
from fishgen.scene.pose import pose
from fishgen.school.bake import bake
from fishgen.school.model import Tracks
from fishgen.species.parser import load_species
from tests.conftest import PARAMS, assert_valid_gltf, validate_gltf


@pytest.fixture(scope="module")
def fish():
    return [build_fish(load_species(PARAMS / "bonybream.txt")),
            build_fish(load_species(PARAMS / "pineapplefish.txt"))]


def circling(count=12, frames=90, fps=30.0):
    t = np.arange(frames) / fps
    angle = np.linspace(0, 2 * np.pi, count, endpoint=False)[None] + 0.4 * t[:, None]
    radius = 2 + 0.1 * np.arange(count)[None]
    pos = np.stack([radius * np.cos(angle), 0.05 * np.sin(3 * t)[:, None] + 0 * angle,
                    radius * np.sin(angle)], -1)
    vel = np.gradient(pos, axis=0) * fps
    yaw = np.arctan2(vel[..., 0], vel[..., 2])
    q = np.zeros((frames, count, 4))
    q[..., 1], q[..., 3] = np.sin(yaw / 2), np.cos(yaw / 2)
    return Tracks(t, pos, vel, q, np.arange(count) % 2, np.linspace(0.9, 1.1, count))


def test_meshes_are_shared_and_every_fish_is_a_node(fish):
    tracks = circling()
    scene = bake(fish, tracks)
    assert len(scene.meshes) == sum(len(f.meshes) for f in fish)          # one mesh per species part
    fish_nodes = [scene.nodes[r] for r in scene.roots]
    assert len(fish_nodes) == 12 and all(len(n.children) == len(f.nodes) - 1
                                         for n, f in zip(fish_nodes, [fish[0], fish[1]] * 6, strict=True))
    assert fish_nodes[1].scale[0] == pytest.approx(tracks.scale[1])
    used = {scene.nodes[c].mesh for n in fish_nodes for c in n.children}
    assert used == set(range(len(scene.meshes)))


def test_the_baked_file_follows_the_tracks_within_tolerance(fish, tmp_path):
    tracks = circling()
    tolerance = 0.002
    path = tmp_path / "school.glb"
    path.write_bytes(glb_bytes(bake(fish, tracks, tolerance=tolerance)))
    assert_valid_gltf(path)
    scene = read_gltf(path)                 # the file's own keys, as an engine reads them
    roots = scene.roots
    for frame in (0, 17, 45, 89):
        posed = pose(scene, float(tracks.times[frame]), "school")
        where = np.array([posed.world[r][:3, 3] for r in roots])
        assert np.abs(where - tracks.positions[frame]).max() <= tolerance + 1e-5
        heads = np.array([posed.world[r][:3, 2] / np.linalg.norm(posed.world[r][:3, 2]) for r in roots])
        q = tracks.headings[frame]
        expected = np.stack([2 * q[:, 1] * q[:, 3], np.zeros(len(q)), 1 - 2 * q[:, 1] ** 2], 1)  # yaw's +Z
        assert np.all(np.einsum("ij,ij->i", heads, expected) > 0.9999)


def test_keys_are_thinned_and_fins_beat_out_of_step(fish):
    scene = bake(fish, circling(frames=300))
    clip = scene.clip("school")
    translations = [c for c in clip.channels if c.path == "translation"]
    assert max(len(c.sampler.times) for c in translations) <= 300 / 3   # smooth circles need few keys
    pectoral = [c.sampler for c in clip.channels
                if scene.nodes[c.node].name == "pectoral_fin_left" and c.path == "rotation"]
    assert len(pectoral) == 12 and pectoral[0].times[-1] == pytest.approx(299 / 30)
    assert len({s.values[0].tobytes() for s in pectoral}) > 1             # phases differ between fish


def test_same_seed_same_bytes(fish):
    one, two = (glb_bytes(bake(fish, circling(), seed=3)) for _ in range(2))
    assert one == two and glb_bytes(bake(fish, circling(), seed=4)) != one


def test_colour_variants_share_geometry_and_differ_only_in_material(fish, tmp_path):
    tracks = circling(count=24)
    plain, tinted = bake(fish, tracks, seed=3), bake(fish, tracks, seed=3, tints=4, tint=0.3)
    assert glb_bytes(bake(fish, tracks, seed=3, tints=1)) == glb_bytes(plain)       # off: the same file
    assert len(tinted.meshes) == 4 * len(plain.meshes) and len(tinted.materials) == 4 * len(plain.materials)
    base_meshes = len(plain.meshes)
    for mesh in tinted.meshes[base_meshes:]:           # each variant: a base mesh's very arrays
        (source,) = [m for m in tinted.meshes[:base_meshes]
                     if m.primitives[0].attributes["POSITION"] is mesh.primitives[0].attributes["POSITION"]]
        assert mesh.name.startswith(source.name + "_tint")
        for prim, original in zip(mesh.primitives, source.primitives, strict=True):
            assert all(prim.attributes[a] is original.attributes[a] for a in original.attributes)
            assert prim.indices is original.indices and prim.targets is original.targets
            material, first = tinted.materials[prim.material], tinted.materials[original.material]
            assert material.texture == first.texture and material.alpha_mode == first.alpha_mode
            factor = np.array(material.base_color[:3]) / np.array(first.base_color[:3])
            assert np.all((factor >= 0.7 - 1e-9) & (factor <= 1.0))
            assert material.base_color[3] == first.base_color[3]
    worn = {scene_mesh for r in tinted.roots for c in tinted.nodes[r].children
            if (scene_mesh := tinted.nodes[c].mesh) is not None}
    assert len(worn) > 2 * base_meshes                  # the 24 fish wear several variants
    path = tmp_path / "tinted.glb"
    path.write_bytes(glb_bytes(tinted))
    assert_valid_gltf(path)
    doc = read_gltf(path)
    # the file stores the geometry once: its accessors are those of the plain file plus none
    plain_path = tmp_path / "plain.glb"
    plain_path.write_bytes(glb_bytes(plain))
    import pygltflib
    counts = [len(pygltflib.GLTF2().load(str(p)).accessors) for p in (plain_path, path)]
    assert counts[0] == counts[1] and len(doc.meshes) == 4 * base_meshes
    # tinting draws from its own generator: every key of the plain file is in the tinted one
    assert [c.sampler.values.tobytes() for c in plain.clip("school").channels] == \
           [c.sampler.values.tobytes() for c in tinted.clip("school").channels]


def test_prototypes_are_each_species_phase_shifted_and_every_fish_wears_one(fish):
    """bake_prototypes: k prototypes a species, whose swim clips are the species' own started k
    equal shares of a loop apart and run the whole school; each fish is one of its own species',
    seeded; the copies follow the tracks exactly."""
    from fishgen.scene.pose import sample
    from fishgen.school.bake import bake_prototypes

    tracks = circling()
    scene = bake_prototypes(fish, tracks, prototypes=3, seed=5, fps=30.0)
    (crowd,) = scene.instancers
    assert not scene.roots and scene.fps == 30.0 and len(crowd.prototypes) == 6
    assert np.array_equal(crowd.proto_indices // 3, tracks.group)
    assert len(set(crowd.proto_indices.tolist())) > 3            # the phases are spread over the fish
    again = bake_prototypes(fish, tracks, prototypes=3, seed=5).instancers[0].proto_indices
    assert np.array_equal(again, crowd.proto_indices)
    assert np.array_equal(crowd.positions, tracks.positions.astype(np.float32))
    assert np.array_equal(crowd.orientations, tracks.headings.astype(np.float32))
    swim = fish[0].clip("swim")
    for k in range(3):
        clip = crowd.prototypes[k].clip("swim")
        assert clip.duration == pytest.approx(tracks.times[-1])
        for own, shifted in zip(swim.channels, clip.channels, strict=True):
            for t in (0.0, 0.7, 2.9):
                expected = sample(own, (t + swim.duration * k / 3) % swim.duration)
                assert np.abs(sample(shifted, t) - expected).max() < 1e-5
    # parts that shared one weights sampler still share one: one blend-shape channel set in USD
    weights = {id(c.sampler) for c in crowd.prototypes[1].clip("swim").channels if c.path == "weights"}
    assert len(weights) == 1


def test_a_file_holds_only_the_colour_variants_its_fish_wear(fish, tmp_path):
    """Four fish and sixteen tints: each fish's variant is there, tinted as with many fish, and no
    material or mesh nobody wears (the validator notes each as unused), not even the species' own
    colours when no fish wears them."""
    tracks = circling(count=4)
    few = bake(fish, tracks, seed=3, tints=16, tint=0.3)
    path = tmp_path / "few.glb"
    path.write_bytes(glb_bytes(few))
    report = validate_gltf(path)[0]
    assert report["numErrors"] == report["numWarnings"] == report["numInfos"] == 0, report["messages"][:3]
    worn = {few.nodes[c].mesh for r in few.roots for c in few.nodes[r].children} - {None}
    assert worn == set(range(len(few.meshes)))
    assert not any(m.name.startswith(("bony", "pine")) and "_tint" not in m.name for m in few.materials)
    # the same variants, tinted the same, as in a school where every variant is worn
    many = bake(fish, circling(count=400, frames=30), seed=3, tints=16, tint=0.3)
    colours = {m.name: m.base_color for m in many.materials}
    assert all(colours[m.name] == m.base_color for m in few.materials)


def test_prototypes_are_only_those_some_fish_is(fish):
    from fishgen.school.bake import bake_prototypes

    tracks = circling(count=3)
    crowd = bake_prototypes(fish, tracks, prototypes=4, seed=5, tints=8).instancers[0]
    assert sorted(set(crowd.proto_indices.tolist())) == list(range(len(crowd.prototypes)))
    assert len(crowd.prototypes) <= 3
    full = bake_prototypes(fish, circling(count=400), prototypes=4, seed=5, tints=8).instancers[0]
    assert len(full.prototypes) == 2 * 8 * 4
    names = {p.name for p in full.prototypes}
    assert {p.name for p in crowd.prototypes} <= names
