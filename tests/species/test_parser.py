"""The species file (thesis Appendix A): what parses, and one test per fault class."""
from __future__ import annotations

from pathlib import Path

import pytest

from fishgen.errors import FishgenError
from fishgen.species.parser import load_species, parse_species
from fishgen.species.writer import format_species
from tests.conftest import PARAMS, ROOT

BONY = (PARAMS / "bonybream.txt").read_text()
SHIPPED = sorted(PARAMS.glob("*.txt"))


def lines_of(text: str) -> list[str]:
    return text.splitlines()


def write(tmp_path: Path, text: str, name: str = "fish.txt") -> Path:
    path = tmp_path / name
    path.write_text(text)
    for tex in ("bonybream.png", "bonybream_mask.png"):
        (tmp_path / tex).write_bytes((ROOT / "textures" / tex).read_bytes())
    return path


def error_of(tmp_path: Path, text: str) -> FishgenError:
    with pytest.raises(FishgenError) as info:
        load_species(write(tmp_path, text))
    return info.value


def replace_record(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def line_number(text: str, needle: str) -> int:
    return next(i for i, line in enumerate(lines_of(text), 1) if line.startswith(needle))


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_every_shipped_species_parses_with_its_textures(path):
    sp = load_species(path)
    assert sp.colour_texture.is_file() and sp.mask_texture.is_file()
    assert len(sp.texture_points.body) == sp.body_sections * sp.circle_sections


def test_bonybream_values_match_appendix_a():
    sp = parse_species(BONY, "bonybream.txt")
    assert (sp.name, sp.world_scale, sp.body_sections, sp.circle_sections) == ("bonybream", 25.5, 16, 12)
    assert sp.scale == (0.26, 0.1, 0.04) and sp.textured and sp.masked
    assert sp.caudal.connection == (0.95, 0.0, 0.0) and sp.caudal.movement_angle == 10.0
    assert (sp.dorsal.start_section, sp.dorsal.end_section, sp.dorsal.start_angle) == (7, 10, 70.0)
    assert sp.anal.start_angle == -55.0 and sp.pelvic.start_circle == 11
    # the pectoral record holds 9 values although its printed header names 7
    assert (sp.pectoral.movement_angle, sp.pectoral.step_size) == (4.0, 1.0)
    assert [len(getattr(sp.texture_points, f)) for f in ("caudal", "dorsal", "adipose", "anal", "pectoral",
                                                         "pelvic")] == [9, 8, 6, 8, 7, 8]
    assert sp.behaviour.change_rate == 50.0 and sp.behaviour.flee == (0.04, 10.0)


def test_writer_round_trips_every_shipped_species():
    for path in SHIPPED:
        sp = parse_species(path.read_text(), str(path))
        again = parse_species(format_species(sp), "again.txt")
        assert again == sp


def test_untextured_species_may_omit_the_texture_block():
    text = lines_of(BONY)
    start = line_number(BONY, "bonybream.png")
    end = line_number(BONY, "//movement of fish")
    body = "\n".join(text[: start - 2] + text[end - 1:]).replace("16 12 true true", "16 12 false false")
    sp = parse_species(body, "plain.txt")
    assert not sp.textured and sp.texture_points is None


# --------------------------------------------------------------------- the faults
def test_appendix_a_as_printed_stops_at_the_wrapped_comment(tmp_path):
    printed = (ROOT / "tests" / "fixtures" / "appendix_a_as_printed.txt").read_text()
    err = error_of(tmp_path, printed)
    assert err.line == 2
    assert "wrapped comment" in str(err) and "//" in str(err)
    assert str(err).startswith(f"{tmp_path / 'fish.txt'}:2: expected the header record")


def test_cyrillic_letter_for_a_count_names_the_character(tmp_path):
    text = BONY.replace("//no_of_adipose_texture_points\n6\n", "//no_of_adipose_texture_points\nб\n")
    err = error_of(tmp_path, text)
    assert err.line == line_number(text, "б")
    assert "U+0431 CYRILLIC SMALL LETTER BE" in str(err) and "misprinted digit" in str(err)


def test_wrong_value_count(tmp_path):
    text = replace_record(BONY, "0.26 0.1 0.04", "0.26 0.1")
    err = error_of(tmp_path, text)
    assert err.line == line_number(text, "0.26 0.1") and "(3 values), found 2 values" in str(err)


def test_non_number(tmp_path):
    text = replace_record(BONY, "7.0 10.0 0.6 0.05 70.0 0.98", "7.0 10.0 0.6 0.05 seventy 0.98")
    err = error_of(tmp_path, text)
    assert "dorsal fin startangle_in_degrees as a number, found 'seventy'" in str(err)


@pytest.mark.parametrize("bad", ["nan", "inf"])
def test_nan_and_infinity_are_not_numbers(tmp_path, bad):
    err = error_of(tmp_path, replace_record(BONY, "0.26 0.1 0.04", f"0.26 {bad} 0.04"))
    assert "scaleY" in str(err)


def test_body_point_count_must_match_level_of_detail(tmp_path):
    text = replace_record(BONY, "\n192\n", "\n191\n")
    err = error_of(tmp_path, text)
    assert "expected 192 body texture points (BodySections 16 x CircleSections 12), found 191" in str(err)


def test_fin_point_count_must_follow_fin_structure(tmp_path):
    text = replace_record(BONY, "//no_of_dorsal_texture_points\n8", "//no_of_dorsal_texture_points\n9")
    err = error_of(tmp_path, text)
    assert ("expected 8 dorsal fin texture points (2 x (endBodySection 10 - startBodySection 7 + 1))"
            in str(err))


def test_fin_section_outside_the_body(tmp_path):
    err = error_of(tmp_path, replace_record(BONY, "7.0 10.0 0.6 0.05 70.0 0.98",
                                            "7.0 16.0 0.6 0.05 70.0 0.98"))
    assert ("dorsal fin endBodySection as a BodySection number after startBodySection 7, from 8 to 15, "
            "found '16.0'" in str(err))


@pytest.mark.parametrize("fin,record,one_section", [
    ("dorsal fin", "7.0 10.0 0.6 0.05 70.0 0.98", "7.0 7.0 0.6 0.05 70.0 0.98"),
    ("dorsal fin", "7.0 10.0 0.6 0.05 70.0 0.98", "15.0 15.0 0.6 0.05 70.0 0.98"),
    ("pelvic", "11.0 4.0 7.0 0.1 0.6 90.0 6.0 1.0", "11.0 4.0 4.0 0.1 0.6 90.0 6.0 1.0"),
])
def test_a_fin_on_one_body_section_is_refused_at_its_line(tmp_path, fin, record, one_section):
    """A fin needs two base points along the body: start = end was a shape-mismatch traceback."""
    err = error_of(tmp_path, replace_record(BONY, record, one_section))
    assert f"expected {fin} " in str(err) and err.line is not None and "Traceback" not in str(err)


def test_pectoral_triangles_may_not_wrap_the_body(tmp_path):
    err = error_of(tmp_path, replace_record(BONY, "6.0 2.0 3.0 0.95", "6.0 2.0 12.0 0.95"))
    assert "pectoral no_of_triangles" in str(err) and "from 1 to 11" in str(err)


def test_unknown_shape_class(tmp_path):
    err = error_of(tmp_path, replace_record(BONY, "FishShapeSin 16", "FishShapeCos 16"))
    assert "a shape class (one of FishShapeAngel, FishShapeHawk, FishShapeSin, FishShapeSpline)" in str(err)
    assert "'FishShapeCos'" in str(err)


def test_spline_shape_needs_control_points(tmp_path):
    err = error_of(tmp_path, replace_record(BONY, "FishShapeSin 16 12 true true false false",
                                            "FishShapeSpline 16 12 true true false false 0.5"))
    assert "FishShapeSpline control points" in str(err)


def test_missing_texture_file(tmp_path):
    err = error_of(tmp_path, replace_record(BONY, "bonybream.png bonybream_mask.png",
                                            "bonybream.png nothere.png"))
    assert "expected an existing texture file, found 'nothere.png' missing" in str(err)


@pytest.mark.parametrize("name", ["../../etc/passwd", "/etc/passwd", "../fish.png"])
def test_texture_paths_may_not_leave_the_texture_folder(tmp_path, name):
    (tmp_path / "fish.png").write_bytes(b"x")
    inner = tmp_path / "species"
    inner.mkdir()
    text = replace_record(BONY, "bonybream.png bonybream_mask.png", f"{name} bonybream_mask.png")
    path = write(inner, text)
    with pytest.raises(FishgenError) as info:
        load_species(path)
    assert "expected a texture path inside" in str(info.value) and repr(name) in str(info.value)


def test_textures_option_is_the_only_root_when_given(tmp_path):
    path = write(tmp_path, BONY)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    with pytest.raises(FishgenError, match="missing from"):
        load_species(path, textures_dir=elsewhere)
    assert load_species(path, textures_dir=ROOT / "textures").colour_texture.parent == ROOT / "textures"


def test_truncated_file(tmp_path):
    text = "\n".join(lines_of(BONY)[:40]) + "\n"
    err = error_of(tmp_path, text)
    assert "found end of file (the file is truncated)" in str(err) and err.line == 41


def test_trailing_garbage(tmp_path):
    err = error_of(tmp_path, BONY + "1 2 3\n")
    assert "expected end of file after the flee record" in str(err)


def test_empty_file(tmp_path):
    err = error_of(tmp_path, "")
    assert str(err).endswith(":1: expected a VRFish species file, found an empty file")


def test_binary_file(tmp_path):
    path = tmp_path / "fish.txt"
    path.write_bytes(b"bonybream 25.5\n\x89PNG\x00\x01")
    with pytest.raises(FishgenError, match=r":2: expected a text species file, found binary data"):
        load_species(path)


def test_absurd_level_of_detail_is_refused_before_allocating(tmp_path):
    err = error_of(tmp_path, replace_record(BONY, "FishShapeSin 16 12", "FishShapeSin 100000000 12"))
    assert "BodySections as a whole number from 3 to 1024, found '100000000'" in str(err)


@pytest.mark.parametrize("old, new, message", [
    # said "BodySections as BodySections": the expectation named the field again
    ("FishShapeSin 16 12", "FishShapeSin 16.5 12",
     "BodySections as a whole number from 3 to 1024, found '16.5'"),
    # said "a whole number in >= 0"
    ("//number_of_ points_body_points\n192", "//number_of_ points_body_points\n-5",
     "number_of_points_body_points as a whole number of 0 or more, found '-5'"),
])
def test_a_whole_number_says_its_range_in_words(tmp_path, old, new, message):
    assert message in str(error_of(tmp_path, replace_record(BONY, old, new)))


def test_step_size_required_for_a_moving_fin(tmp_path):
    err = error_of(tmp_path, replace_record(BONY, "3.0 10.0 1.0\n", "3.0 10.0 0.0\n"))
    assert "caudal step_size as a step size > 0" in str(err)


def test_texture_that_is_not_an_image(tmp_path):
    path = write(tmp_path, BONY)
    (tmp_path / "bonybream_mask.png").write_text("not a picture")
    with pytest.raises(FishgenError,
                       match="expected a texture image .* found 'bonybream_mask.png' unreadable"):
        load_species(path)


def test_absurd_texture_size_is_refused_from_its_header(tmp_path):
    from PIL import Image
    path = write(tmp_path, BONY)
    Image.new("1", (9000, 8)).save(tmp_path / "bonybream_mask.png")
    with pytest.raises(FishgenError, match="at most 8192 pixels a side, found 'bonybream_mask.png' 9000x8"):
        load_species(path)


def test_a_texture_name_that_is_a_folder_is_called_a_folder_not_missing(tmp_path):
    path = write(tmp_path, BONY)
    (tmp_path / "bonybream.png").unlink()
    (tmp_path / "bonybream.png").mkdir()
    with pytest.raises(FishgenError) as err:
        load_species(path)
    assert str(err.value) == (f"{path}:{line_number(BONY, 'bonybream.png bonybream_mask.png')}: expected a "
                              "texture file, found 'bonybream.png', a folder")


def test_a_texture_name_that_is_a_pipe_is_called_so_not_missing(tmp_path):
    """QA pass 15: a FIFO named as a texture was said to be missing; it is there, not a file."""
    import os

    path = write(tmp_path, BONY)
    (tmp_path / "bonybream.png").unlink()
    os.mkfifo(tmp_path / "bonybream.png")
    with pytest.raises(FishgenError) as err:
        load_species(path)
    assert str(err.value).endswith("expected a texture file, found 'bonybream.png', not a regular file (a "
                                   "pipe, a socket or a device)")


def png_header(width: int, height: int) -> bytes:
    """A PNG that is only its header: what Pillow reads before it decides whether to decode."""
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IEND", b""))


@pytest.mark.parametrize("side,found", [(100_000, "of 10,000,000,000 pixels"), (10_000, "10000x10000")])
def test_a_header_past_pillows_own_limit_is_the_same_one_line(tmp_path, recwarn, side, found):
    path = write(tmp_path, BONY)
    (tmp_path / "bonybream.png").write_bytes(png_header(side, side))
    with pytest.raises(FishgenError) as err:
        load_species(path)
    assert str(err.value) == (f"{path}:{line_number(BONY, 'bonybream.png bonybream_mask.png')}: expected a "
                              f"texture of at most 8192 pixels a side, found 'bonybream.png' {found}")
    assert not [w for w in recwarn if "DecompressionBomb" in type(w.message).__name__]


@pytest.mark.parametrize("old,new,needle", [
    ("0.26 0.1 0.04", "1e300 0.1 0.04", "scaleX as a number > 0 and <= 100"),
    ("bonybream 25.5", "bonybream 1e308", "world_scale as a number > 0 and <= 10000"),
    ("0 0 0.015625 0.3046875", "0 0 1e300 -1e300", "u as a number >= 0 and <= 1"),
    ("7.0 10.0 0.6 0.05 70.0 0.98", "7.0 10.0 6e6 0.05 70.0 0.98", "startLength as a number >= 0 and <= 100"),
])
def test_values_beyond_any_sensible_size_are_refused(tmp_path, old, new, needle):
    err = error_of(tmp_path, replace_record(BONY, old, new))
    assert needle in str(err) and err.line == line_number(replace_record(BONY, old, new), new)


@pytest.mark.parametrize("old,new,message", [
    ("bonybream 25.5", "bonybream 1e-300", "expected a body at least 0.001 m long (world_scale x 0.05 m x "
                                           "scaleX), found 1e-300 x 0.05 m x 0.26 = 1.3e-302 m"),
    ("0.26 0.1 0.04", "1e-300 1e-300 1e-300", "expected a body at least 0.001 m long (world_scale x 0.05 m x "
                                              "scaleX), found 25.5 x 0.05 m x 1e-300 = 1.28e-300 m"),
    ("0.26 0.1 0.04", "0.26 0.1 1e-300", "expected scaleZ as a number at least 0.001 x scaleX (0.00026), "
                                         "found '1e-300'"),
])
def test_a_body_too_small_to_draw_is_refused_at_its_scale_record(tmp_path, old, new, message):
    """QA pass 12: a world_scale of 1e-300 built a fish of float32 zeros, '0.000 m long', and exited
    0; --length refuses under 1 mm, and so does the file now, on the body scale record."""
    text = replace_record(BONY, old, new)
    err = error_of(tmp_path, text)
    assert err.message == message and err.line == line_number(text, "0.26 0.1 0.04" if old != "0.26 0.1 0.04"
                                                              else new)


def test_a_long_value_is_shortened_in_the_error(tmp_path):
    """QA pass 12: a 5,000-digit BodySections was echoed whole on the one error line."""
    err = error_of(tmp_path, replace_record(BONY, "FishShapeSin 16 12", "FishShapeSin " + "9" * 5000 + " 12"))
    assert "BodySections" in err.message and len(str(err)) < 300 and "9" * 39 + "…" in err.message


@pytest.mark.parametrize("points,found", [
    ("0.2 0.5 0.1 0.4", "control point 2 of 2 at x 0.1, r 0.4 (after x 0.2)"),
    ("0.2 0.5 0.6 0", "control point 2 of 2 at x 0.6, r 0"),
    ("1.5 0.5", "control point 1 of 1 at x 1.5, r 0.5"),
    ("0.2 0.5 0.6", "3 extra values"),
])
def test_a_spline_point_out_of_order_or_range_is_named(tmp_path, points, found):
    """QA pass 12: every bad FishShapeSpline said `found 10 extra values`, naming no point."""
    err = error_of(tmp_path, replace_record(BONY, "FishShapeSin 16 12 true true false false",
                                            f"FishShapeSpline 16 12 true true false false {points}"))
    assert err.message.endswith(f", found {found}")


def test_form_feed_in_a_comment_does_not_split_the_line():
    text = BONY.replace("//fish_colours_RGB", "//fish_colours\x0cRGB \u2028 (yellow)")
    assert parse_species(text, "ff.txt").colour == (1.0, 1.0, 0.0)


def test_nan_gets_no_wrapped_comment_hint(tmp_path):
    err = error_of(tmp_path, replace_record(BONY, "0.26 0.1 0.04", "0.26 nan 0.04"))
    assert "wrapped comment" not in str(err) and "scaleY as a finite number" in str(err)


def test_body_point_split_across_lines_is_still_a_value_count_error(tmp_path):
    text = replace_record(BONY, "1 0 0.064453125 0.32421875\n1 1 0.064453125 0.296875\n",
                          "1 0 0.064453125\n0.32421875 1 1 0.064453125 0.296875\n")
    err = error_of(tmp_path, text)
    assert err.line == line_number(text, "1 0 0.064453125") and "(4 values), found 3 values" in str(err)


@pytest.mark.parametrize("token", ["1_0.0", "１０", "nan", "0x10", "1e5e5"])
def test_only_the_number_forms_the_thesis_files_use_are_numbers(tmp_path, token):
    """Issue 26, fault 13: Python's float() reads "1_0.0" and full-width digits; the format has
    neither. In a record and in the block of body texture points (the fast path) alike."""
    from fishgen.species.parser import load_species

    text = (PARAMS / "bonybream.txt").read_text()
    lines = text.splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("bonybream "))
    record = lines.copy()
    record[header] = " ".join(lines[header].split()[:-1] + [token])
    points = lines.copy()
    first_point = next(i for i, line in enumerate(lines)
                       if line.split()[:2] == ["0", "0"] and len(line.split()) == 4)
    parts = lines[first_point].split()
    points[first_point] = " ".join(parts[:2] + [token, parts[3]])
    for name, changed, line in (("record.txt", record, header + 1), ("points.txt", points, first_point + 1)):
        path = tmp_path / name
        path.write_text("\n".join(changed) + "\n")
        with pytest.raises(FishgenError) as caught:
            load_species(path, textures_dir=ROOT / "textures")
        assert caught.value.line == line and repr(token) in str(caught.value), str(caught.value)
