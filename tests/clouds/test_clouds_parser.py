"""The .awn parser: the report's own files, and one test per fault class."""
from __future__ import annotations

import warnings

import pytest
from cloud_tables import TABLES, TOTALS

from fishgen.clouds import CubeFileWarning, load_cubes
from fishgen.errors import FishgenError


@pytest.mark.parametrize("table", sorted(TABLES))
def test_report_tables_parse_with_their_totals(table):
    with warnings.catch_warnings():
        warnings.simplefilter("error", CubeFileWarning)  # their totals add up: no warning
        cubes = load_cubes(TABLES[table])
    assert cubes.total == cubes.declared_total == TOTALS[table]
    assert len(cubes.cubes) == {"4.2": 3, "4.3": 17, "4.4": 23}[table]


def test_table_4_3_line_with_missing_comma_parses():
    cubes = load_cubes(TABLES["4.3"])
    line14 = next(c for c in cubes.cubes if c.line == 14)
    assert line14.particles == 50
    assert line14.size == (2.36429, 1.50285, 2.29693)
    assert line14.centre == (4.6, -3.0, 0.0)
    assert line14.max_radius == 2.2345
    assert next(c for c in cubes.cubes if c.line == 16).particles == 0
    assert next(c for c in cubes.cubes if c.line == 13).centre[0] == pytest.approx(6.12438e-7)


def test_axis_order_makes_the_first_cube_a_flat_wide_base():
    # The decision: sizes are x, y, z extents with y up (docs/decisions.md).
    for table in ("4.3", "4.4"):
        cubes = load_cubes(TABLES[table]).cubes
        base = cubes[0]
        assert base.centre[1] == min(c.centre[1] for c in cubes)   # lowest
        assert base.size[1] == min(base.size)                         # flat in y
        assert base.size[0] == max(c.size[0] for c in cubes)         # widest in x
        assert all(c.centre[2] == pytest.approx(0, abs=1) for c in cubes)


def test_separators_crlf_bom_tabs_and_blank_lines(write_awn):
    path = write_awn(b"\xef\xbb\xbf 7\r\n\r\n2\r\n3\t1 1 1\t0 0 0 1\r\n4 ,2, 2 ,2,1,1,1 , 0.5\r\n\n")
    cubes = load_cubes(path)
    assert [c.particles for c in cubes.cubes] == [3, 4]
    assert [c.line for c in cubes.cubes] == [4, 5]
    assert cubes.cubes[1].size == (2.0, 2.0, 2.0)


@pytest.mark.parametrize("ending", ["\n", "\r\n", "\r"], ids=["LF", "CRLF", "CR (old Mac)"])
def test_every_line_ending_parses_with_the_same_line_numbers(write_awn, ending):
    text = ending.join(["3", "", "2", "1 1 1 1 0 0 0 1", "2, 2, 2, 2, 1, 1, 1, 0.5", ""])
    cubes = load_cubes(write_awn(text))
    assert [c.particles for c in cubes.cubes] == [1, 2]
    assert [c.line for c in cubes.cubes] == [4, 5]
    bad = write_awn(ending.join(["3", "2", GOOD, "1, 1, x, 1, 0, 0, 0, 1"]), "bad.awn")
    with pytest.raises(FishgenError, match=r"bad.awn:4: expected a number for the y size"):
        load_cubes(bad)


def test_declared_total_mismatch_warns_and_cube_counts_win(write_awn):
    path = write_awn("10\n1\n5, 1, 1, 1, 0, 0, 0, 1\n")
    with pytest.warns(CubeFileWarning, match=rf"{path}:1: warning: declared total 10.*hold 5"):
        cubes = load_cubes(path)
    assert cubes.total == 5 and cubes.declared_total == 10


GOOD = "1, 1, 1, 1, 0, 0, 0, 1"

# (name, file text, line of the error, what the message must say)
FAULTS = [
    ("empty file", "", 1, "found an empty file"),
    ("blank file", "\n  \n\t\n", 1, "found an empty file"),
    ("binary NUL", b"1\n1\n\x00\x01\x02garbage", 3, "expected a text cube file, found binary data"),
    ("binary NUL, CR lines", b"1\r1\r\x00garbage", 3, "found binary data"),
    ("binary PNG", b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", 1, "found binary data"),
    ("invalid UTF-8", b"1\n1\n1, 1, 1, 1, 0, 0, 0, \xff\n", 3, "found binary data"),
    ("missing cube count", "1\n", 2, "expected the number of cubes"),
    ("zero cubes", "0\n0\n", 2, "expected at least 1 cube, found 0"),
    ("fewer cube lines", f"2\n2\n{GOOD}\n", 4, "expected 2 cube lines (declared on line 2), found 1"),
    ("more cube lines", f"2\n1\n{GOOD}\n{GOOD}\n", 4, "found another cube line"),
    ("too few fields", "1\n1\n1, 1, 1, 1, 0, 0, 1\n", 3, "expected 8 fields"),
    ("too many fields", "1\n1\n1, 1, 1, 1, 0, 0, 0, 1, 9\n", 3, "maximum radius), found 9 fields"),
    ("two fields on line 1", "1 2\n1\n" + GOOD, 1, "expected 1 field (the total particle count)"),
    ("empty field", "1\n1\n1, 1,, 1, 0, 0, 0, 1\n", 3, "found an empty field"),
    ("negative count", "1\n1\n-1, 1, 1, 1, 0, 0, 0, 1\n", 3,
     "a whole number of 0 or more for the particle count, found '-1'"),
    ("negative total", "-5\n1\n" + GOOD, 1, "found '-5'"),
    ("fractional count", "1\n1\n2.5, 1, 1, 1, 0, 0, 0, 1\n", 3, "whole number for the particle count"),
    ("non-number", "1\n1\n1, 1, wide, 1, 0, 0, 0, 1\n", 3, "a number for the y size, found 'wide'"),
    ("non-number total", "lots\n1\n" + GOOD, 1, "found 'lots'"),
    ("NaN", "1\n1\n1, 1, 1, 1, nan, 0, 0, 1\n", 3, "finite number for the centre x, found 'nan'"),
    ("infinity", "1\n1\n1, inf, 1, 1, 0, 0, 0, 1\n", 3, "finite number for the x size, found 'inf'"),
    ("overflow", "1\n1\n1, 1, 1, 1, 0, 1e999, 0, 1\n", 3, "finite number for the centre y"),
    ("NaN count", "1\n1\nNaN, 1, 1, 1, 0, 0, 0, 1\n", 3,
     "a whole number for the particle count, found 'NaN'"),
    ("inf total", "inf\n1\n" + GOOD, 1, "expected a whole number for the total particle count, found 'inf'"),
    ("yes total", "yes\n1\n" + GOOD, 1, "expected a whole number for the total particle count, found 'yes'"),
    ("negative cube count", "1\n-2\n" + GOOD, 2,
     "expected a whole number of 0 or more for the number of cubes, found '-2'"),
    ("4300+ digit total", "9" * 5000 + "\n1\n" + GOOD, 1,
     "expected a whole number of at most 18 digits for the total particle count, "
     "found a number with 5,000 digits"),
    ("4300+ digit cube count", "1\n" + "1" * 4301 + "\n" + GOOD, 2,
     "at most 18 digits for the number of cubes"),
    ("4300+ digit particles", "1\n1\n" + "7" * 4400 + ", 1, 1, 1, 0, 0, 0, 1\n", 3,
     "at most 18 digits for the particle count, found a number with 4,400 digits"),
    ("4300+ digit negative", "1\n1\n-" + "7" * 4400 + ", 1, 1, 1, 0, 0, 0, 1\n", 3,
     "of 0 or more for the particle count"),
    ("centre out of float32", "1\n1\n1, 1, 1, 1, 0, -1e39, 0, 1\n", 3,
     "centre y within float32 range (-3.4e+38 to 3.4e+38), found '-1e39'"),
    ("zero size", "1\n1\n1, 1, 1, 0, 0, 0, 0, 1\n", 3, "z size greater than 0, found '0'"),
    ("negative size", "1\n1\n1, -2, 1, 1, 0, 0, 0, 1\n", 3, "x size greater than 0, found '-2'"),
    ("zero radius", "1\n1\n1, 1, 1, 1, 0, 0, 0, 0.0\n", 3, "maximum radius greater than 0"),
    ("negative radius", "1\n1\n1, 1, 1, 1, 0, 0, 0, -1\n", 3, "maximum radius greater than 0"),
    ("float32 underflow", "1\n1\n1, 1, 1, 1, 0, 0, 0, 1e-50\n", 3, "within float32 range"),
    ("no particles at all", "0\n1\n0, 1, 1, 1, 0, 0, 0, 1\n", 1, "at least 1 particle"),
    ("cubes of none under a total", "5\n1\n0, 1, 1, 1, 0, 0, 0, 1\n", 3, "at least 1 particle"),
    ("one cube line missing", "1\n1\n", 3, "expected 1 cube line (declared on line 2), found 0"),
    ("one cube too many", f"1\n1\n{GOOD}\n{GOOD}\n", 4, "after the 1 cube declared on line 2"),
]


def test_messages_read_well(write_awn):
    # No doubled articles ("a the ...", "the the ...") in any fault message.
    for _, text, _, _ in FAULTS:
        try:
            load_cubes(write_awn(text))
        except FishgenError as err:
            assert " a the " not in str(err) and " the the " not in str(err), str(err)


@pytest.mark.parametrize("name,text,line,message", FAULTS, ids=[f[0] for f in FAULTS])
def test_each_fault_is_reported_at_its_line(write_awn, name, text, line, message):
    path = write_awn(text)
    with pytest.raises(FishgenError) as caught:
        load_cubes(path)
    rendered = str(caught.value)
    assert rendered.startswith(f"{path}:{line}: expected "), rendered
    assert ", found " in rendered and message in rendered, rendered
    assert "\n" not in rendered


def test_declared_total_over_the_limit_is_refused_on_line_1(write_awn):
    path = write_awn(f"{10**15}\n1\n{GOOD}\n")
    with pytest.raises(FishgenError, match=r":1: expected at most 50,000,000 particles "
                                           r"\(raise the limit with --max-particles\)"):
        load_cubes(path, raise_with="--max-particles")


def test_the_limit_names_an_option_only_where_the_caller_has_one(write_awn):
    """`fishgen preview` and `fishgen edit` have no --max-particles: the message said to use it."""
    path = write_awn(f"{10**15}\n1\n{GOOD}\n")
    with pytest.raises(FishgenError) as caught:
        load_cubes(path)
    assert str(caught.value) == f"{path}:1: expected at most 50,000,000 particles, found {10**15:,}"


def test_cube_counts_over_the_limit_are_refused_at_the_line_that_crosses_it(write_awn):
    path = write_awn("15\n3\n" + "\n".join(["10, 1, 1, 1, 0, 0, 0, 1"] * 3) + "\n")
    with pytest.raises(FishgenError, match=r":4: expected at most 15 particles.*found 20"):
        load_cubes(path, max_particles=15)
    with pytest.warns(CubeFileWarning):  # declared 15, cubes hold 30
        assert load_cubes(path, max_particles=30).total == 30


def test_missing_file_and_directory(tmp_path):
    with pytest.raises(FishgenError, match="no such file"):
        load_cubes(tmp_path / "nope.awn")
    with pytest.raises(FishgenError, match="found a directory"):
        load_cubes(tmp_path)


def test_devices_and_fifos_are_refused_without_reading(tmp_path):
    import os
    with pytest.raises(FishgenError, match=r"^/dev/zero: expected a cube file, found a device$"):
        load_cubes("/dev/zero")  # used to read forever, then MemoryError
    fifo = tmp_path / "pipe.awn"
    os.mkfifo(fifo)  # no writer: opening must not block
    with pytest.raises(FishgenError, match=r"pipe.awn: expected a cube file, found a pipe \(FIFO\)$"):
        load_cubes(fifo)


def test_files_over_the_size_cap_are_refused_reading_at_most_cap_plus_one(tmp_path, monkeypatch):
    from fishgen.clouds import parser
    monkeypatch.setattr(parser, "MAX_FILE_BYTES", 100)
    path = tmp_path / "big.awn"
    path.write_bytes(b"1\n1\n" + b" " * 200 + GOOD.encode())
    with pytest.raises(FishgenError, match=r"big.awn: expected a cube file of at most 0 MiB"):
        load_cubes(path)
    path.write_bytes(b"1\n1\n" + GOOD.encode() + b" " * (100 - 4 - len(GOOD)))  # exactly the cap
    assert len(path.read_bytes()) == 100 and load_cubes(path).total == 1


def test_default_caps_refuse_absurd_files_before_parsing_cubes(write_awn):
    from fishgen.clouds import parser
    assert parser.MAX_FILE_BYTES == 16 << 20
    with pytest.raises(FishgenError, match=r":2: expected at most 100,000 cubes, found 100,001$"):
        load_cubes(write_awn(f"1\n100001\n{GOOD}\n"))
