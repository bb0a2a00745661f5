"""What a fly-through shows: a sky of a mode, cube files as clouds, or glTF assets as they are."""
from __future__ import annotations

import pytest

from fishgen.errors import FishgenError, UsageError
from fishgen.exchange.gltf_reader import read_gltf
from fishgen.fly.assets import prepare_assets
from tests.conftest import PARAMS, ROOT


def glb_scene(data: bytes, tmp_path):
    path = tmp_path / "x.glb"
    path.write_bytes(data)
    return read_gltf(path)


def test_cube_files_become_one_scene_of_clouds_side_by_side(tmp_path):
    cubes = [PARAMS / "clouds" / "table_4_3.awn", PARAMS / "clouds" / "table_4_4.awn"]
    assets, read = prepare_assets(cubes, seed=2)
    assert len(assets) == 1 and assets[0].source == "cubes" and read == cubes
    scene = glb_scene(assets[0].data, tmp_path)
    roots = [scene.nodes[k] for k in scene.roots]
    assert [n.name for n in roots] == ["table_4_3", "table_4_4"]
    assert roots[1].translation[0] > roots[0].translation[0]
    assert scene.counts()["particles"] == 554 + 615


def test_a_mode_makes_a_sky_and_glb_files_go_as_they_are(tmp_path):
    assets, read = prepare_assets([], mode="thin", seed=1)
    assert assets[0].source == "sky" and assets[0].name == "thin sky"
    assert glb_scene(assets[0].data, tmp_path).counts()["particles"] == 20_000
    fish = ROOT / "tests" / "fixtures" / "tiny.glb"
    assets, read = prepare_assets([fish])
    assert assets[0].data == fish.read_bytes() and read == [fish]


@pytest.mark.parametrize("inputs, mode, error", [
    ([], None, UsageError), ([ROOT / "tests" / "fixtures" / "tiny.glb"], "thin", UsageError),
    ([PARAMS / "bonybream.txt"], None, FishgenError),
])
def test_what_cannot_be_flown_is_refused_in_one_line(inputs, mode, error):
    with pytest.raises(error, match="expected"):
        prepare_assets(inputs, mode=mode)


def test_a_damaged_glb_is_refused_before_the_page_sees_it(tmp_path):
    bad = tmp_path / "bad.glb"
    bad.write_bytes(b"glTF" + bytes(20))
    with pytest.raises(FishgenError):
        prepare_assets([bad])


def _glb(path, doc: dict):
    """A glb of this JSON alone (no binary chunk), padded as the format asks."""
    import json
    import struct

    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    header = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text))
    path.write_bytes(header + struct.pack("<I4s", len(text), b"JSON") + text)
    return path


@pytest.mark.parametrize("doc, found", [
    ({"asset": {"version": "2.0"}, "nodes": [{}]}, "found no scenes"),
    ({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{}]}, "draws something, found none"),
    ({"asset": {"version": "2.0"}, "scenes": [{}]}, "draws something, found none"),
])
def test_a_glb_the_page_would_show_nothing_of_is_refused(tmp_path, doc, found):
    """Valid glTF, but nothing to show: fly's page failed with a script's stack trace (no scene for
    three.js, or no point for the camera to aim at); now one line naming the file. (`view` writes
    its page, which says it could not show the asset.)"""
    path = _glb(tmp_path / "empty.glb", doc)
    read_gltf(path)                                  # fishgen's reader takes it: it is valid glTF
    with pytest.raises(FishgenError, match=found) as caught:
        prepare_assets([path])
    assert caught.value.file == str(path)


def test_cube_files_too_big_to_fly_are_refused_before_any_is_filled(tmp_path, monkeypatch):
    """40 million particles took 5 GB before the system refused an array; with a limit known up front
    fly refuses them in one line, as `clouds` and `sky` do."""
    import fishgen.clouds.memory as memory
    from fishgen.clouds import fill

    monkeypatch.setattr(memory, "allowed", lambda: (600 * 2**20, "this process's address-space limit"))
    monkeypatch.setattr(fill, "fill_cloud", lambda *a, **k: pytest.fail("filled before it was refused"))
    big = tmp_path / "big.awn"
    big.write_text("2000000\n1\n2000000, 10, 10, 10, 0, 0, 0, 1\n")
    with pytest.raises(UsageError, match=r"fits in 600 MiB .* found 2,000,000 particles for \.glb"):
        prepare_assets([big])
