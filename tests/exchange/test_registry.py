"""The format registry: one declaration per format drives writers, readers, CLI choices and errors."""
from __future__ import annotations

from pathlib import Path

import pytest

from fishgen.errors import FishgenError
from fishgen.exchange import export, registry
from fishgen.exchange.registry import (
    FORMATS,
    MESHES,
    NODE_ANIMATION,
    POINTS,
    Format,
    formats,
    lost,
    output_format,
    register_format,
)
from tests.conftest import PARAMS


def test_every_writer_and_reader_entry_point_resolves():
    for fmt in FORMATS.values():
        for target in (fmt.writer, fmt.reader):
            if target is not None:
                assert callable(registry._load(target)), target


def test_cli_choices_come_from_the_registry():
    from fishgen.commands.build import FISH_FORMATS
    from fishgen.exchange.clouds import FORMATS as CLOUD_FORMATS
    from fishgen.viewer.page import KINDS

    assert [f.name for f in FISH_FORMATS] == ["glb", "gltf", "obj", "ply", "usdc", "usda", "usdz"]
    assert CLOUD_FORMATS == (".glb", ".gltf", ".ply", ".csv", ".npy", ".nvdb", ".vdb")
    assert set(KINDS) == {".glb", ".gltf", ".obj", ".ply"}


def test_a_format_that_cannot_hold_what_is_asked_says_what_is_lost_and_what_to_use():
    with pytest.raises(FishgenError) as info:
        output_format("school.obj", [MESHES, NODE_ANIMATION])
    assert str(info.value) == ("school.obj: expected a format that holds node animation, found .obj "
                               "(Wavefront OBJ: a rest-pose mesh with .mtl and images), which would lose "
                               "them; use .glb or .gltf or .usdc or .usda or .usdz instead")
    with pytest.raises(FishgenError, match="an input of `fishgen clouds`"):
        output_format("sky.awn", [POINTS])
    # one need given as text is one need (it was six letters), and none that no format holds is
    # offered (it was "use  instead")
    with pytest.raises(FishgenError, match=r"holds node animation, found \.obj .*; use \.glb or"):
        output_format("school.obj", NODE_ANIMATION)
    with pytest.raises(FishgenError, match=r"holds nothing-at-all, found \.glb .*; no format holds them$"):
        output_format("x.glb", ["nothing-at-all"])


def test_summary_names_what_a_rest_pose_format_drops(tmp_path):
    from fishgen.assembly.fish import build_fish
    from fishgen.species.parser import load_species
    from tests.conftest import PARAMS

    fish = build_fish(load_species(PARAMS / "bonybream.txt"))
    assert lost(FORMATS["obj"], fish) == [NODE_ANIMATION, "morph targets", "alpha cutoff",
                                          "double-sided faces"]
    assert lost(FORMATS["glb"], fish) == []


def test_adding_a_format_is_one_module_and_one_entry(tmp_path, monkeypatch):
    """A toy XYZ point writer: declared once, it is reachable through export() by extension."""
    monkeypatch.setattr(registry, "FORMATS", dict(FORMATS))
    register_format(Format("xyz", (".xyz",), "plain x y z text", frozenset({POINTS}),
                           writer="tests.exchange.test_registry:write_xyz"))
    from fishgen.clouds import fill_cloud, load_cubes
    from fishgen.clouds.scene import cloud_scene
    from tests.conftest import PARAMS

    cloud = fill_cloud(load_cubes(PARAMS / "clouds" / "table_4_2.awn"), seed=1)
    (written,) = export(cloud_scene(cloud), tmp_path / "c.xyz")
    assert len(written.read_text().splitlines()) == len(cloud)
    assert "xyz" in [f.name for f in formats(writable=True, holding=[POINTS])]
    with pytest.raises(ValueError, match="already registered"):
        register_format(Format("xyz2", (".xyz",), "again"))


def write_xyz(scene, path: Path) -> list[Path]:
    (prim,) = scene.meshes[0].primitives
    path.write_text("".join(f"{x} {y} {z}\n" for x, y, z in prim.positions.tolist()))
    return [path]


def test_an_extension_two_formats_share_is_told_apart_by_content(tmp_path):
    """`.toml` is a school scene or a batch manifest (issue 19: a manifest given to `build`)."""
    from fishgen.exchange.registry import detect

    manifest, scene, broken = tmp_path / "m.toml", tmp_path / "s.toml", tmp_path / "b.toml"
    manifest.write_text('[[build]]\ninput = "a.txt"\noutput = "a.glb"\n')
    scene.write_text('[[species]]\nfile = "a.txt"\n')
    broken.write_text("[[species]\n")
    assert detect(manifest).name == "batch manifest" and detect(scene).name == "school scene"
    assert detect(broken) is None  # then the command's own reader says where the TOML breaks


def test_a_shared_extension_needs_a_sniff_on_every_format():
    with pytest.raises(ValueError, match="each need a sniff"):
        register_format(Format("toy scene", (".toml",), "a toy"))


def test_readers_take_exactly_the_options_their_format_declares(tmp_path):
    """No reader swallows unknown options: a mistyped one is a TypeError, not ignored."""
    from fishgen.exchange.registry import FORMATS

    with pytest.raises(TypeError, match="no reader takes sed"):
        FORMATS["cubes"].read(PARAMS / "clouds" / "table_4_3.awn", sed=3)
    scene = FORMATS["cubes"].read(PARAMS / "clouds" / "table_4_3.awn", seed=3, textures_dir=None)
    assert scene.counts()["particles"] == 554


def test_every_file_a_writer_writes_is_a_name_its_format_declares(tmp_path):
    """What a format writes beside a target (``sides``) is known before it writes: the commands
    check those names against their inputs and their other outputs up front."""
    from fishgen.assembly.fish import fish_of
    from fishgen.assembly.fish_options import FishOptions
    from fishgen.exchange.registry import written_names
    from fishgen.species.parser import load_species

    scene = fish_of(load_species(PARAMS / "bonybream.txt"), FishOptions(fins="mask")).scene
    for name in ("glb", "gltf", "obj", "ply"):
        target = tmp_path / name / f"fish.{name}"
        files = export(scene, target)
        declared = written_names(target)
        assert declared[0].matches(target.name) and len(files) > (name != "glb") * 2 - 1
        assert all(any(w.matches(f.name) for w in declared) for f in files), (name, files, declared)


@pytest.mark.parametrize("targets,shared", [
    (["o/a.gltf", "o/b.glb", "o/a.obj"], (0, 2, "a_*.png")),   # both write a_skin.png
    (["o/a.gltf", "o/a_skin.png"], (0, 1, "a_skin.png")),
    (["o/e.txt", "o/e.png"], (0, 1, "e.png")),                  # a species file's texture
    (["o/h.txt", "o/h_mask.png"], (0, 1, "h_mask.png")),
    (["o/a.glb", "o/./a.glb"], (0, 1, "a.glb")),
    (["o/a.gltf", "p/a.obj"], None),                            # other folders
    (["o/a.gltf", "o/a.glb", "o/b.obj"], None),
    ([f"o/f{k}.gltf" for k in range(200)], None),
])
def test_two_targets_share_a_file_when_their_names_or_side_files_meet(targets, shared):
    from fishgen.exchange.registry import first_shared

    found = first_shared(targets)
    assert (found if found is None else (found[0], found[1], str(found[2]))) == shared


def test_an_input_is_judged_by_its_content_a_name_alone_by_its_extension_and_said_so(tmp_path):
    """`fishgen edit out/x.txt` (no such file) said it found a VRFish species file, and a folder
    was 'no extension'."""
    cubes = [registry.FORMATS["cubes"], registry.FORMATS["texture cubes"]]
    with pytest.raises(FishgenError) as named:
        registry.input_format(tmp_path / "x.txt", kinds=cubes, command="edit")
    assert named.value.message == ("expected an input of `fishgen edit` (.awn, .awa), found '.txt', the "
                                   "extension of a VRFish species file; use `fishgen build` for it")
    with pytest.raises(FishgenError) as there:
        registry.input_format(PARAMS / "bonybream.txt", kinds=cubes, command="edit")
    assert ("found a .txt file (VRFish species file, by its extension); use `fishgen build`"
            in there.value.message)
    with pytest.raises(FishgenError, match="expected a file, found a directory"):
        registry.input_format(tmp_path, kinds=cubes, command="edit")


def test_an_input_judged_by_its_extension_alone_is_not_said_to_hold_that_content(tmp_path):
    """A species file named fish.glb read 'found binary glTF 2.0', though no byte was read; a
    school scene (.toml, which several formats share) is told by its content, and said so."""
    species = tmp_path / "fish.glb"
    species.write_text((PARAMS / "bonybream.txt").read_text())
    with pytest.raises(FishgenError) as named:
        registry.input_format(species, kinds=[registry.FORMATS["species"]], command="build")
    assert named.value.message.endswith("found a .glb file (binary glTF 2.0, by its extension)")
    with pytest.raises(FishgenError) as sniffed:
        registry.input_format(PARAMS / "reef.toml", kinds=[registry.FORMATS["species"]], command="build")
    assert sniffed.value.message.endswith("found a school scene file; use `fishgen school` for it")
    junk = tmp_path / "junk.toml"
    junk.write_bytes(bytes(range(256)))
    with pytest.raises(FishgenError) as neither:          # no sharing format knew it: none is claimed
        registry.input_format(junk, kinds=[registry.FORMATS["species"]], command="build")
    assert neither.value.message.endswith("found a .toml file that is neither a school scene file nor a "
                                          "batch manifest")
