"""What the editor may touch: cube files of its folder by bare name, textures in the texture folders."""
from __future__ import annotations

import os

import pytest

from fishgen.editor.workspace import Workspace
from fishgen.errors import FishgenError
from tests.editor.test_document import _png


@pytest.fixture
def folder(tmp_path):
    """skies/ (the edited folder) with a cube file, textures/ beside it, and things outside."""
    skies = tmp_path / "skies"
    skies.mkdir()
    (skies / "a.awn").write_text("1\n1\n1, 1, 1, 1, 0, 0, 0, 1\n")
    (skies / "b.awa").write_text("1\n1\n1, 1, 1, 1, 0, 0, 0, 1, clouds/puff.png\n")
    (skies / "notes.txt").write_text("not a cube file")
    (tmp_path / "textures" / "clouds").mkdir(parents=True)
    (tmp_path / "textures" / "clouds" / "puff.png").write_bytes(_png())
    (tmp_path / "textures" / "clouds" / "two words.png").write_bytes(_png())
    (skies / "own.png").write_bytes(_png())
    (tmp_path / "secret.awn").write_text("1\n1\n1, 1, 1, 1, 0, 0, 0, 1\n")
    (tmp_path / "secret.png").write_bytes(_png())
    return skies


@pytest.mark.parametrize("name", ["../secret.awn", "/etc/passwd.awn", "/tmp/x.awn", "..", "sub/a.awn",
                                  "..\\secret.awn", "a.awn\x00", ".hidden.awn", "", "a.txt", "a", 5, None])
def test_only_bare_cube_file_names_of_the_folder_are_accepted(folder, name):
    with pytest.raises(FishgenError, match="^expected a"):
        Workspace(folder / "a.awn").cube_file(name, must_exist=False)


def test_a_link_out_of_the_folder_is_refused_and_one_inside_is_followed(folder):
    os.symlink(folder.parent / "secret.awn", folder / "out.awn")
    os.symlink(folder / "a.awn", folder / "in.awn")
    ws = Workspace(folder / "a.awn")
    with pytest.raises(FishgenError, match="a link leading out of it"):
        ws.cube_file("out.awn", must_exist=True)
    with pytest.raises(FishgenError, match="a link leading out of it"):
        ws.cube_file("out.awn", must_exist=False)  # nor written through
    assert ws.cube_file("in.awn", must_exist=True) == (folder / "a.awn").resolve()
    assert "out.awn" not in ws.cube_files() and "in.awn" in ws.cube_files()


def test_the_file_it_was_given_is_always_its_own(folder):
    os.symlink(folder.parent / "secret.awn", folder / "given.awn")
    ws = Workspace(folder / "given.awn")
    assert ws.cube_file("given.awn", must_exist=True) == folder.parent / "secret.awn"


def test_a_new_name_in_the_folder_may_be_written_but_not_read(folder):
    ws = Workspace(folder / "a.awn")
    assert ws.cube_file("new.awa", must_exist=False) == folder.resolve() / "new.awa"
    with pytest.raises(FishgenError, match="^expected an existing file in .*, found no 'new.awa'$"):
        ws.cube_file("new.awa", must_exist=True)


def test_the_folder_lists_its_cube_files(folder):
    assert Workspace(folder / "new.awn").cube_files() == ["a.awn", "b.awa"]


def test_textures_are_listed_as_a_awa_file_names_them(folder):
    names = Workspace(folder / "b.awa").texture_names()
    assert names == ["clouds/puff.png", "own.png"]  # "two words.png" cannot sit in a cube line


def test_a_texture_is_served_from_the_texture_folders_only(folder):
    ws = Workspace(folder / "b.awa")
    assert ws.texture("clouds/puff.png") == _png() and ws.texture("own.png") == _png()
    for name in ("../secret.png", "../../secret.png", str(folder.parent / "secret.png"), "notes.txt",
                 "clouds/missing.png", "a b.png", 7):
        with pytest.raises(FishgenError, match="^expected a"):
            ws.texture(name)


def test_a_texture_link_out_of_the_folders_is_neither_listed_nor_served(folder):
    os.symlink(folder.parent / "secret.png", folder / "leak.png")
    ws = Workspace(folder / "b.awa")
    assert "leak.png" not in ws.texture_names()
    with pytest.raises(FishgenError, match="may not leave the texture folder"):
        ws.texture("leak.png")


def test_textures_dir_replaces_the_folders(folder, tmp_path):
    other = tmp_path / "other"
    other.mkdir()
    (other / "x.png").write_bytes(_png())
    ws = Workspace(folder / "b.awa", textures_dir=other)
    assert ws.texture_names() == ["x.png"]
    with pytest.raises(FishgenError):
        ws.texture("own.png")
