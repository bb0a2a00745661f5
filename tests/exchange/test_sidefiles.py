"""fishgen.exchange.sidefiles: a file an asset names is an input of the command that reads it."""
from __future__ import annotations

import json

import pytest

from tests.conftest import PARAMS, run_cli


@pytest.mark.parametrize("asset, target", [("bb.gltf", "bb_skin.png"), ("bb.obj", "bb_skin.png"),
                                           ("bb.obj", "bb_skin_mask.png")])
def test_a_preview_never_replaces_a_file_its_asset_names(tmp_path, asset, target):
    """`fishgen preview bb.gltf -o bb_skin.png` wrote the render over the fish's own texture, exit 0:
    the files a glTF or OBJ names were not inputs, as a species file's textures were."""
    built = run_cli("build", PARAMS / "bonybream.txt", "-o", tmp_path / asset)
    assert built.returncode == 0, built.stderr
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    result = run_cli("preview", tmp_path / asset, "-o", tmp_path / target, "--size", "64x48")
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert "expected an output that is not one of the command's inputs" in result.stderr
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_a_page_never_replaces_a_file_its_asset_names(tmp_path):
    """A glTF whose image is named page.html: `fishgen view --no-serve -o page.html` wrote over it."""
    built = run_cli("build", PARAMS / "bonybream.txt", "-o", tmp_path / "bb.gltf")
    assert built.returncode == 0, built.stderr
    gltf = json.loads((tmp_path / "bb.gltf").read_text())
    (tmp_path / "bb_skin.png").rename(tmp_path / "page.html")
    gltf["images"][0]["uri"] = "page.html"
    (tmp_path / "bb.gltf").write_text(json.dumps(gltf))
    image = (tmp_path / "page.html").read_bytes()
    result = run_cli("view", "--no-serve", tmp_path / "bb.gltf", "-o", tmp_path / "page.html")
    assert result.returncode == 2 and "not one of the command's inputs" in result.stderr, result.stderr
    assert (tmp_path / "page.html").read_bytes() == image


@pytest.mark.parametrize("first, second", [("foo.gltf", "foo.obj"), ("foo.obj", "foo.usda"),
                                           ("foo.usda", "foo.ply"), ("foo.ply", "foo.gltf")])
def test_a_build_never_changes_a_texture_another_asset_beside_it_names(tmp_path, first, second):
    """foo.gltf and foo.obj both name foo_skin.png: `-o foo.obj --fins opaque` after `-o foo.gltf
    --fins mask` wrote the skin without its mask, and the glTF's fins lost their cut-out, exit 0."""
    from fishgen.commands import run
    from fishgen.commands.build import COMMAND
    from fishgen.errors import UsageError

    bream = PARAMS / "bonybream.txt"
    fins = {"mask": COMMAND.options(fins="mask"), "opaque": COMMAND.options(fins="opaque")}
    run(COMMAND, (bream,), tmp_path / first, fins["mask"])
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    with pytest.raises(UsageError, match=f"found 'foo_skin.png', named by '{first}' beside it"):
        run(COMMAND, (bream,), tmp_path / second, fins["opaque"])
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    run(COMMAND, (bream,), tmp_path / second, fins["mask"])           # the same texture: no change
    assert (tmp_path / "foo_skin.png").read_bytes() == before["foo_skin.png"]


def test_an_asset_may_replace_its_own_texture(tmp_path):
    from fishgen.commands import run
    from fishgen.commands.build import COMMAND

    bream = PARAMS / "bonybream.txt"
    run(COMMAND, (bream,), tmp_path / "foo.gltf", COMMAND.options(fins="mask"))
    run(COMMAND, (bream,), tmp_path / "foo.gltf", COMMAND.options(fins="opaque"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["foo.bin", "foo.gltf", "foo_skin.png"]


def test_a_usdc_beside_it_blocks_only_the_side_files_it_names(tmp_path):
    """A .usdc was taken to name every file of its stem: rebuilding foo.gltf with another --length
    was refused for foo.bin, which no USD names."""
    from fishgen.commands import run
    from fishgen.commands.build import COMMAND
    from fishgen.errors import UsageError

    bream = PARAMS / "bonybream.txt"
    run(COMMAND, (bream,), tmp_path / "foo.usdc", COMMAND.options(fins="mask"))
    run(COMMAND, (bream,), tmp_path / "foo.gltf", COMMAND.options(fins="mask"))
    run(COMMAND, (bream,), tmp_path / "foo.gltf", COMMAND.options(fins="mask", length=0.5))  # a new foo.bin
    with pytest.raises(UsageError, match="named by 'foo.usdc'"):
        run(COMMAND, (bream,), tmp_path / "foo.gltf", COMMAND.options(fins="opaque"))


def test_an_asset_of_another_case_names_its_side_files_too(tmp_path):
    from fishgen.commands import run
    from fishgen.commands.build import COMMAND
    from fishgen.errors import UsageError

    bream = PARAMS / "bonybream.txt"
    run(COMMAND, (bream,), tmp_path / "foo.GLTF", COMMAND.options(fins="mask"))
    with pytest.raises(UsageError, match="named by 'foo.GLTF'"):
        run(COMMAND, (bream,), tmp_path / "foo.obj", COMMAND.options(fins="opaque"))
    run(COMMAND, (bream,), tmp_path / "foo.GLTF", COMMAND.options(fins="opaque"))              # its own
