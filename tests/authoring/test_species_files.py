"""Sampled species as files: written exactly where -o says, their textures named NEW.png and
NEW_mask.png whenever a species file can name them, and every file of a set landing together."""
from __future__ import annotations

import pytest

from fishgen.authoring.species_files import check_texture_names, texture_names, write_samples
from fishgen.errors import UsageError
from fishgen.species.parser import load_species


@pytest.mark.parametrize("name", ["Ab-c.d.txt", "ünï🐟.txt", "bream-fit.txt", "a,b.txt"])
def test_a_name_a_species_file_can_hold_is_kept(tmp_path, name):
    names = texture_names(tmp_path / name)
    stem = name[:-4]
    assert (names.colour, names.mask) == (f"{stem}.png", f"{stem}_mask.png")
    assert names.why is None and names.note is None


@pytest.mark.parametrize("name,stem", [("my fish.txt", "my_fish"), ("a \t b.txt", "a_b"),
                                       ("back\\slash.txt", "back_slash"), ("bad\udcff.txt", "bad_")])
def test_a_name_a_species_file_cannot_hold_is_derived_and_said(tmp_path, name, stem):
    names = texture_names(tmp_path / name)
    assert (names.colour, names.mask) == (f"{stem}.png", f"{stem}_mask.png")
    assert names.note is not None and "\n" not in names.note and stem in names.note


def test_a_name_too_long_for_the_mask_is_cut_to_fit(tmp_path):
    names = texture_names(tmp_path / ("é" * 124 + ".txt"))   # 248 bytes: the .txt fits, _mask.png not
    assert names.why is not None and len(names.mask.encode()) <= 255 and names.mask.endswith("_mask.png")


@pytest.mark.parametrize("name", ["my fish.txt", "ünï🐟.txt", "Ab-c.d.txt"])
def test_the_species_file_is_written_exactly_where_o_says_and_reads_back(tmp_path, name):
    notes: list[str] = []
    written = write_samples(7, 1, tmp_path / name, note=notes.append)
    assert written == [tmp_path / name]
    species = load_species(tmp_path / name)   # its texture record names files that are there
    assert species.colour_texture is not None and species.colour_texture.parent == tmp_path
    assert len(list(tmp_path.iterdir())) == 3
    assert len(notes) == (1 if " " in name else 0)


def test_a_rerun_gives_the_same_bytes_and_replaces_its_own_derived_textures(tmp_path):
    write_samples(3, 1, tmp_path / "my fish.txt")
    first = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    write_samples(3, 1, tmp_path / "my fish.txt")
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == first


def test_derived_names_never_take_another_file(tmp_path):
    write_samples(3, 1, tmp_path / "my_fish.txt")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    with pytest.raises(UsageError, match="named by 'my_fish.txt' beside it"):
        write_samples(4, 1, tmp_path / "my fish.txt")
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    (tmp_path / "my_fish.txt").unlink()             # a picture no species file names: still not ours
    with pytest.raises(UsageError, match="no file already there"):
        write_samples(4, 1, tmp_path / "my fish.txt")


@pytest.mark.parametrize("folder", [False, True])
def test_the_documented_pair_never_takes_a_file_its_species_file_does_not_name(tmp_path, folder):
    """QA pass 12: `species -o fish.txt` replaced an unrelated fish.png and fish_mask.png, exit 0
    (derived names were refused in that case, the documented pair was not)."""
    out = tmp_path / "reef" if folder else tmp_path / "fish.txt"
    picture = tmp_path / "reef" / "species_4.png" if folder else tmp_path / "fish.png"
    picture.parent.mkdir(exist_ok=True)
    picture.write_bytes(b"precious")
    with pytest.raises(UsageError, match="no file already there, found .*not there yet"):
        write_samples(3, 2, out, folder=True) if folder else write_samples(3, 1, out)
    assert picture.read_bytes() == b"precious" and len(list(picture.parent.iterdir())) == 1
    picture.unlink()
    write_samples(3, 2, out, folder=True) if folder else write_samples(3, 1, out)
    write_samples(3, 2, out, folder=True) if folder else write_samples(3, 1, out)  # a rerun replaces its own


@pytest.mark.parametrize("first,second", [("fish7.txt", "fish7_mask.txt"), ("fish7_mask.txt", "fish7.txt")])
def test_a_texture_another_species_file_names_is_never_replaced(tmp_path, first, second):
    """fish7_mask.txt's colour texture is fish7_mask.png, fish7.txt's fin mask: it was replaced by a
    colour picture, and fish7 built with it as its mask, exit 0."""
    write_samples(7, 1, tmp_path / first)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    with pytest.raises(UsageError, match=f"'fish7_mask.png', named by '{first}' beside it"):
        write_samples(7, 1, tmp_path / second)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    write_samples(7, 1, tmp_path / first)           # a rerun still replaces its own textures
    (tmp_path / "fish7_mask.png").unlink()          # missing, it would be written as the wrong picture
    with pytest.raises(UsageError, match=f"'fish7_mask.png', named by '{first}' beside it"):
        write_samples(7, 1, tmp_path / second)


def test_derived_names_never_take_another_output(tmp_path):
    names = texture_names(tmp_path / "a b.txt")
    with pytest.raises(UsageError, match="no other output"):
        check_texture_names(names, [tmp_path / "a_b_mask.png"])
    check_texture_names(texture_names(tmp_path / "ab.txt"), [tmp_path / "ab.png"])  # kept: not ours to judge


def test_a_set_of_species_lands_whole_or_not_at_all(tmp_path, monkeypatch):
    import fishgen.authoring.species_files as species_files

    real = species_files.sample_files
    calls = []

    def failing(seed, stem, names=None):
        calls.append(seed)
        if len(calls) == 3:
            raise OSError("disk full")
        return real(seed, stem, names)

    monkeypatch.setattr(species_files, "sample_files", failing)
    with pytest.raises(OSError):
        write_samples(10, 5, tmp_path / "reef", folder=True)
    assert not (tmp_path / "reef").exists() and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name,inside", [("ünï🐟.txt", "uni"), ("Crème brûlée.txt", "Creme_brulee"),
                                         ("🐟.txt", "species"), ("bream-fit.txt", "bream_fit")])
def test_the_name_inside_a_species_file_keeps_the_letters_of_its_file_name(tmp_path, name, inside):
    """The name a species file holds is ASCII: accents are dropped, not the letters under them
    (`ünï🐟.txt` held `n`)."""
    from fishgen.authoring.species_files import species_name

    assert species_name(tmp_path / name) == inside
    write_samples(7, 1, tmp_path / name)
    assert load_species(tmp_path / name).name == inside
