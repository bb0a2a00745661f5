"""Levels of detail: each level built from the species file, one glb holding them all (MSFT_lod),
the coarser levels out of sight of clients that know nothing of levels, and each level measured."""
from __future__ import annotations

import numpy as np
import pygltflib
import pytest

from fishgen.assembly.fish import make_fish
from fishgen.assembly.levels import at_level
from fishgen.errors import FishgenError
from fishgen.exchange import export
from fishgen.species.parser import load_species
from tests.assembly.engine_clients import fin_gap, frame_of, iou, level_scene, silhouette
from tests.conftest import PARAMS, validate_gltf

LODS = ((32, 24), (16, 12), (8, 6))
CLIPS = ("swim", "idle", "sprint", "turn_left", "turn_right", "burst")


@pytest.fixture(scope="module")
def bony():
    return load_species(PARAMS / "bonybream.txt")


@pytest.fixture(scope="module", params=[False, True], ids=["parts", "merged"])
def levels(request, bony, tmp_path_factory):
    fish = make_fish(bony, lods=LODS, merge=request.param, clips=CLIPS)
    path = tmp_path_factory.mktemp("lods") / "fish.glb"
    export(fish.scene, path)
    return fish, path


def test_the_files_own_level_is_the_species_itself(bony):
    assert at_level(bony, 16, 12) is bony


def test_texture_points_are_resampled_where_the_grids_meet(bony):
    """At 31x24 every other ring and circle is one of the file's 16x12: those carry its points as they
    are; the fins' points keep their ends."""
    fine = at_level(bony, 31, 24)
    old = np.asarray(bony.texture_points.body).reshape(16, 12, 2)
    new = np.asarray(fine.texture_points.body).reshape(31, 24, 2)
    assert np.allclose(new[::2, ::2], old)
    assert np.allclose(new[1::2, ::2], (old[:-1] + old[1:]) / 2)
    for name in ("dorsal", "anal", "pelvic", "pectoral"):
        fin, points = getattr(fine, name), getattr(fine.texture_points, name)
        assert len(points) == fin.texture_point_count
        assert points[0] == getattr(bony.texture_points, name)[0]


def test_fins_move_to_the_nearest_section_of_each_level(bony):
    coarse = at_level(bony, 8, 6)
    assert (coarse.dorsal.start_section, coarse.dorsal.end_section) == (3, 5)    # 7..10 of 16
    assert coarse.pectoral.start_circle == 1 and coarse.pectoral.triangles == 2    # 60 degrees down 120
    assert coarse.texture_points is not None and len(coarse.texture_points.body) == 8 * 6


def test_a_fin_whose_ends_meet_on_one_ring_spans_the_section_its_middle_lies_in():
    """At 3x3 every random species' pelvic fin (whose ends both round to the middle ring) was
    stretched back to the tail ring, and its trailing edge hung past the tail by up to 17 % of the
    body. Now it spans the section its middle lies in, and no fin reaches behind the body."""
    from fishgen.assembly.fish import build_fish
    from fishgen.authoring.sampler import sample_species

    for seed in range(100, 116):
        species = sample_species(seed).species
        coarse = at_level(species, 3, 3)
        middle = (species.pelvic.start_section + species.pelvic.end_section) / 2
        at = middle * 2 / (species.body_sections - 1)
        assert coarse.pelvic.start_section <= at <= coarse.pelvic.end_section
        fish = build_fish(coarse)
        reach = {}
        for node in fish.nodes:
            if node.mesh is not None:
                mesh = fish.meshes[node.mesh]
                z = np.concatenate([p.attributes["POSITION"][:, 2] for p in mesh.primitives])
                reach[node.name] = float(z.min() + node.translation[2])
        tail = reach["body"]
        assert reach["pelvic_fin_left"] >= tail and reach["pelvic_fin_right"] >= tail, seed


def _fin_areas(species) -> dict[str, float]:
    from fishgen.assembly.fins import build_fins
    from fishgen.geometry.body import build_body
    from fishgen.geometry.shapes import profile_for

    body = build_body(profile_for(species.shape_class, species.shape_params), species.body_sections,
                      species.circle_sections, species.scale)
    out = {}
    for fin in build_fins(species, body.rings):
        tri = fin.mesh.positions[fin.mesh.faces]
        out[fin.name] = float(np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                             axis=1).sum() / 2)
    return out


@pytest.mark.parametrize("name,finer", [("bonybream", [(32, 24), (64, 48)]), ("centroberyx", [(64, 48)]),
                                        ("threadfingoldie", [(32, 24), (64, 48)])])
def test_a_finer_level_keeps_the_files_fin_sizes(name, finer):
    """Each top point of a fin lies `proportion` of the way up the triangle before it, so over twice
    the sections the edge fell twice as fast: BonyBream's pectoral fin at 32x24 had 68 % of its
    file's area, at 64x48 39 %. The proportion per step now keeps the fall over the fin's span."""
    species = load_species(PARAMS / f"{name}.txt")
    own = _fin_areas(species)
    for level in finer:
        got = _fin_areas(at_level(species, *level))
        for fin in ("dorsal_fin", "anal_fin", "pectoral_fin_left"):
            if fin in own:
                assert 0.85 <= got[fin] / own[fin] <= 1.15, f"{name} {level} {fin}: {got[fin] / own[fin]:.2f}"


def test_the_summary_says_which_fins_a_coarse_level_cannot_hold(bony):
    from fishgen.assembly.fish import fish_of
    from fishgen.assembly.fish_options import FishOptions

    fish = fish_of(bony, FishOptions(lods=((32, 24), (16, 12), (8, 6))))
    assert [lv.missing for lv in fish.facts.levels] == [(), (), ("adipose_fin", "anal_fin")]


def test_one_glb_holds_every_level_and_names_them_for_msft_lod_and_unity(levels):
    fish, path = levels
    doc = pygltflib.GLTF2().load(str(path))
    assert "MSFT_lod" in doc.extensionsUsed and "MSFT_lod" not in (doc.extensionsRequired or [])
    finest = [n for n in doc.nodes if "MSFT_lod" in (n.extensions or {})]
    assert [n.name for n in finest] == ["bonybream_LOD0"]
    ids = finest[0].extensions["MSFT_lod"]["ids"]
    assert [doc.nodes[i].name for i in ids] == ["bonybream_LOD1", "bonybream_LOD2"]
    coverage = finest[0].extras["MSFT_screencoverage"]
    assert len(coverage) == 3 and coverage == sorted(coverage, reverse=True)
    assert 0 < coverage[-1] < coverage[0] <= 1
    # the default scene reaches the finest level only; the coarser ones stand in the second scene
    reach, stack = set(), list(doc.scenes[doc.scene].nodes)
    while stack:
        i = stack.pop()
        reach.add(i)
        stack += doc.nodes[i].children or []
    assert not set(ids) & reach and set(ids) <= set(doc.scenes[1].nodes)
    triangles = [lv.triangles for lv in fish.facts.levels]
    assert triangles == sorted(triangles, reverse=True) and len(set(triangles)) == 3


def test_the_validator_accepts_msft_lod_with_no_warning(levels):
    _, path = levels
    (report,) = validate_gltf(path)
    assert report["numErrors"] == 0 and report["numWarnings"] == 0
    assert {m["code"] for m in report["messages"]} <= {"UNSUPPORTED_EXTENSION"}   # an info: MSFT_lod


def test_each_coarser_level_keeps_the_side_silhouette(levels):
    """Side-view silhouette IoU against the finest level: at least 0.9 for LOD1 (the issue's bar)."""
    fish, _ = levels
    box = frame_of(fish.scene)
    finest = silhouette(fish.scene, box=box)
    scores = [iou(finest, silhouette(level_scene(fish.scene, k), box=box)) for k in (1, 2)]
    print(f"side silhouette IoU vs LOD0: LOD1 {scores[0]:.3f}, LOD2 {scores[1]:.3f}")
    assert scores[0] >= 0.9 and scores[1] >= 0.75


def test_every_level_keeps_its_fins_on_over_every_clip(levels):
    fish, _ = levels
    if fish.facts.merged:          # the layouts pose alike (test_merge.py): measure one
        pytest.skip("measured on the parts layout")
    worst = {}
    for k in range(3):
        scene = level_scene(fish.scene, k)
        for clip in CLIPS:
            duration = scene.clip(clip).duration
            worst[(k, clip)] = fin_gap(scene, clip, np.linspace(0.0, duration, 9))
    print({key: f"{v:.2%}" for key, v in worst.items()})
    assert max(worst.values()) < 0.01


@pytest.mark.parametrize("lods", [[(8, 6), (16, 12)], [(16, 12), (16, 12)], [(2, 6)], [(16, 12)] * 9])
def test_levels_must_go_from_finest_to_coarsest(bony, lods):
    with pytest.raises(FishgenError, match="--lods"):
        make_fish(bony, lods=lods)


@pytest.mark.parametrize("circles", [5, 7, 9, 10])
def test_texture_at_other_circle_sections_puts_the_paired_fins_where_a_level_does(bony, circles):
    """`texture --circle-sections 5` moved BonyBream's pelvic fin from below the flank (330 degrees)
    to above it (+18): its own copy of the level mapping was not taught the odd ring's turn."""
    from fishgen.authoring.photo.sideview import with_counts

    texture, level = with_counts(bony, None, circles), at_level(bony, bony.body_sections, circles)
    assert texture.pelvic.start_circle == level.pelvic.start_circle
    assert texture.pectoral.start_circle == level.pectoral.start_circle
