"""`fishgen sky`: a validator-clean glTF of separately culled, lit clouds, the same bytes for a seed."""
from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import pytest

from fishgen.commands.sky import SkyOptions, sky
from fishgen.sky.modes import LOD_LEVELS, MODES
from fishgen.sky.scene import LEVELS_IN_A_SCENE
from tests.conftest import PARAMS, assert_valid_gltf, run_cli, validate_gltf


def glb_json(path: Path) -> dict:
    data = path.read_bytes()
    length, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON"
    return json.loads(data[20:20 + length])


def clouds_of(doc: dict) -> list[dict]:
    scene = doc["scenes"][doc["scene"]]
    return [doc["nodes"][k] for k in scene["nodes"]]


def particles_of(doc: dict, node: dict) -> int:
    mesh = doc["meshes"][doc["nodes"][node["children"][0]]["mesh"]]
    return sum(doc["accessors"][p["attributes"]["POSITION"]]["count"] for p in mesh["primitives"])


@pytest.fixture(scope="module")
def skies(tmp_path_factory):
    """Every mode at its own size (thick: 10^6 particles), and a small thick one twice."""
    out = tmp_path_factory.mktemp("skies")
    made = {}
    for mode in MODES:
        made[mode] = sky((), out / f"{mode}.glb", SkyOptions(mode=mode, seed=5))
    return out, made


@pytest.mark.parametrize("mode", list(MODES))
def test_each_mode_is_validator_clean_with_one_node_per_cloud(skies, mode):
    out, made = skies
    path = out / f"{mode}.glb"
    assert_valid_gltf(path)
    (report,) = validate_gltf(path)
    # infos only: MSFT_lod, and the lower levels when they stand in no scene
    assert {m["code"] for m in report["messages"]} == {"UNSUPPORTED_EXTENSION",
                                                       *(() if LEVELS_IN_A_SCENE else ("UNUSED_OBJECT",))}
    doc = glb_json(path)
    roots = clouds_of(doc)
    assert len(roots) == MODES[mode].clouds == made[mode].facts.clouds
    assert sum(particles_of(doc, n) for n in roots) == MODES[mode].particles == made[mode].facts.particles
    assert "MSFT_lod" in doc["extensionsUsed"] and "MSFT_lod" not in doc.get("extensionsRequired", [])
    assert f"{path.stat().st_size / 1e6:.1f} MB" in made[mode].lines[0]


def test_thick_has_more_clouds_and_particles_than_medium_and_medium_than_thin(skies):
    out, made = skies
    facts = [made[m].facts for m in ("thin", "medium", "thick")]
    assert facts[0].clouds < facts[1].clouds < facts[2].clouds
    assert facts[0].particles < facts[1].particles < facts[2].particles
    assert facts[2].particles == 1_000_000


def test_each_cloud_node_carries_its_place_turn_and_bounds_and_its_levels(skies):
    out, _ = skies
    doc = glb_json(out / "medium.glb")
    reachable = set()
    stack = list(doc["scenes"][0]["nodes"])
    while stack:
        k = stack.pop()
        reachable.add(k)
        stack += doc["nodes"][k].get("children", [])
    hidden = {i for scene in doc["scenes"][1:] for i in scene["nodes"]}
    assert len(doc["scenes"]) == (2 if LEVELS_IN_A_SCENE else 1) and not hidden & reachable
    for root in clouds_of(doc):
        assert root["name"].startswith("cloud_") and "translation" in root and "rotation" in root
        bounds = root["extras"]["fishgen_cloud"]["bounds"]
        (child,) = root["children"]
        lod0 = doc["nodes"][child]
        assert lod0["name"] == root["name"] + "_LOD0"
        position = doc["accessors"][doc["meshes"][lod0["mesh"]]["primitives"][0]["attributes"]["POSITION"]]
        # the box holds every particle (radii included) in the cloud's own frame
        assert np.all(np.array(bounds["min"]) <= np.array(position["min"]) + 1e-4)
        assert np.all(np.array(bounds["max"]) >= np.array(position["max"]) - 1e-4)
        ids = lod0["extensions"]["MSFT_lod"]["ids"]
        coverage = lod0["extras"]["MSFT_screencoverage"]
        assert len(coverage) == len(ids) + 1 and coverage == sorted(coverage, reverse=True)
        assert coverage[-1] == 0
        assert coverage[:-1] == [c for _, c in LOD_LEVELS[:len(ids)]]
        counts = [root["extras"]["fishgen_cloud"]["particles"]]
        for k, node in enumerate(ids, 1):
            assert doc["nodes"][node]["name"] == f"{root['name']}_LOD{k}"
            assert node not in reachable          # drawn only by clients that know MSFT_lod
            assert (node in hidden) == LEVELS_IN_A_SCENE      # the second scene, as a fish's levels
            counts.append(sum(doc["accessors"][p["attributes"]["POSITION"]]["count"]
                              for p in doc["meshes"][doc["nodes"][node]["mesh"]]["primitives"]))
        assert counts == sorted(counts, reverse=True) and len(set(counts)) == len(counts)
    sky_extras = doc["scenes"][0]["extras"]
    assert sky_extras["fishgen_sky"]["mode"] == "medium" and sky_extras["fishgen_light"]["sun"]


def test_the_same_seed_gives_the_same_bytes_another_seed_others(tmp_path, cli):
    args = ["sky", "--mode", "thick", "--particles", "30000"]
    for name, seed in (("a", 3), ("b", 3), ("c", 4)):
        run = cli(*args, "--seed", str(seed), "-o", tmp_path / f"{name}.glb")
        assert run.returncode == 0, run.stderr
    assert (tmp_path / "a.glb").read_bytes() == (tmp_path / "b.glb").read_bytes()
    assert (tmp_path / "a.glb").read_bytes() != (tmp_path / "c.glb").read_bytes()


def test_user_cube_files_make_the_clouds_texture_clouds_as_billboards(tmp_path):
    out = tmp_path / "mixed.gltf"
    made = sky((), out, SkyOptions(mode="thin", clouds=(PARAMS / "clouds" / "table_4_3.awn",
                                                        PARAMS / "clouds" / "sky.awa"), particles=6_000))
    assert_valid_gltf(out)
    doc = json.loads(out.read_text())
    sources = {n["extras"]["fishgen_cloud"]["source"] for n in clouds_of(doc)}
    assert sources == {"table_4_3.awn", "sky.awa"}
    assert any(m["name"].startswith("cloud texture ") for m in doc["materials"])
    assert len({i["name"] for i in doc["images"]}) == len(doc["images"])      # each texture stored once
    assert {p.name for p in made.read} >= {"table_4_3.awn", "sky.awa", "billow.png"}


def test_in_a_scene_the_lower_levels_are_no_orphans(tmp_path, monkeypatch):
    """The layout a sky takes once fishgen fly's page reads it (LEVELS_IN_A_SCENE): the fish's."""
    monkeypatch.setattr("fishgen.sky.scene.LEVELS_IN_A_SCENE", True)
    path = tmp_path / "thin.glb"
    sky((), path, SkyOptions(mode="thin", particles=6_000))
    (report,) = validate_gltf(path)
    assert report["numErrors"] == report["numWarnings"] == 0
    assert {m["code"] for m in report["messages"]} == {"UNSUPPORTED_EXTENSION"}     # no UNUSED_OBJECT
    doc = glb_json(path)
    named = [i for n in doc["nodes"] for i in n.get("extensions", {}).get("MSFT_lod", {}).get("ids", [])]
    assert named and doc["scenes"][1] == {"name": "levels of detail", "nodes": named}


def test_no_lod_writes_no_levels(tmp_path):
    sky((), tmp_path / "flat.glb", SkyOptions(mode="thin", lod=False))
    doc = glb_json(tmp_path / "flat.glb")
    assert "MSFT_lod" not in doc.get("extensionsUsed", [])
    assert len(doc["nodes"]) == 2 * MODES["thin"].clouds and len(doc["scenes"]) == 1


@pytest.mark.parametrize("args, words", [
    (["--area", "0,10"], "--area"), (["--altitude", "90,40"], "--altitude"), (["--noise", "2"], "--noise"),
    (["--mode", "stormy"], "--mode"), (["-o", "sky.ply"], ".glb or .gltf"),
])
def test_bad_options_are_one_line_and_write_nothing(tmp_path, cli, args, words):
    run = cli("sky", *(args if "-o" in args else [*args, "-o", tmp_path / "s.glb"]), cwd=tmp_path)
    assert run.returncode == 2 and words in run.stderr and "Traceback" not in run.stderr
    assert not list(tmp_path.iterdir())


def test_a_bad_cube_file_is_its_own_line(tmp_path, cli):
    bad = tmp_path / "bad.awn"
    bad.write_text("5\n1\n5, 1, 1, x, 0, 0, 0, 1\n")
    run = cli("sky", "--clouds", bad, "-o", tmp_path / "s.glb")
    assert run.returncode == 2 and run.stderr.startswith(f"{bad}:3: expected")
    assert not (tmp_path / "s.glb").exists()


@pytest.mark.parametrize("args, message", [
    (["--particles", "1"], "fishgen sky: expected --particles of at least 368 for a thin sky"),
    (["--max-particles", "19999"], "fishgen sky: expected at most 19,999 particles (raise --max-particles), "
                                   "found 20,000 for a thin sky"),
])
def test_a_sky_of_the_wrong_size_is_a_usage_error(tmp_path, cli, args, message):
    run = cli("sky", "--mode", "thin", *args, "-o", tmp_path / "s.glb")
    assert run.returncode == 2 and run.stderr.startswith(message) and run.stderr.count("\n") == 1, run.stderr
    assert not list(tmp_path.iterdir())


def test_max_particles_bounds_the_sky_not_the_model_files_it_re_fills(tmp_path, cli):
    """--max-particles 600 refused a 500-particle sky, naming a shipped model's own count (615) in a
    file inside the package; a model declaring 10^9 particles is re-filled to its share too."""
    huge = tmp_path / "huge.awn"
    huge.write_text("1000000000\n1\n1000000000, 10, 10, 10, 0, 0, 0, 1\n")
    for extra in ([], ["--clouds", huge]):
        run = cli("sky", "--mode", "thin", "--particles", "500", "--max-particles", "600", *extra,
                  "-o", tmp_path / "s.glb")
        assert run.returncode == 0, run.stderr
        assert "500 particles" in run.stdout


def test_a_small_skys_summary_says_its_size_in_kilobytes(tmp_path):
    """400 particles said "0.0 MB"."""
    path = tmp_path / "s.glb"
    made = run_cli("sky", "--mode", "thin", "--particles", "400", "-o", path)
    assert made.returncode == 0, made.stderr
    assert f", {path.stat().st_size / 1e3:.0f} KB (seed 0" in made.stdout


def test_help_gives_each_modes_least_particles_as_the_shipped_files_make_it():
    """--help gave --particles' range as 1 to 50,000,000, where a thin sky needs 368 (QA pass 13)."""
    from fishgen.sky.build import load_models
    from fishgen.sky.modes import SHIPPED_CUBES

    cubes, _ = load_models()
    assert SHIPPED_CUBES == max(sum(1 for c in f.cubes if c.particles) for f in cubes)
    run = run_cli("sky", "--help")
    text = " ".join(run.stdout.split())
    assert "(with the shipped files, thin 368, medium 1,104, thick 2,760)" in text, text


@pytest.mark.parametrize("shadow_map", ["cloud", "sky"])
def test_a_sky_counts_each_cloud_filled_lit_and_levelled_on_one_bar(tmp_path, shadow_map):
    """A thick sky took 3.5 s, 7 s with 4 million particles, with nothing on the terminal
    (QA pass 21)."""
    from fishgen.commands import Events
    from tests.progress_bars import recorded_bars

    bars, progress = recorded_bars()
    sky([], tmp_path / "s.glb", SkyOptions(mode="thin", shadow_map=shadow_map), Events(progress=progress))
    clouds = MODES["thin"].clouds
    assert [(label, total) for label, total, _ in bars] == [("building the sky", 3 * clouds)]
    assert sum(bars[0][2]) == 3 * clouds
