"""Fixel's .FXL files: the thesis' sample reads, fishgen's own files round-trip, faults name a line."""
from __future__ import annotations

import pytest

from fishgen.authoring.photo.fxl import format_fxl, parse_fxl, read_fxl
from fishgen.errors import FishgenError
from fishgen.fuzz.corpus import APPENDIX_B_FXL as APPENDIX_B  # Appendix B.10 as printed
from fishgen.species.parser import load_species
from tests.conftest import PARAMS


def test_appendix_b_sample_reads():
    parts = parse_fxl(APPENDIX_B)
    assert sorted(parts) == ["anal", "dorsal"]
    assert len(parts["dorsal"]) == 14 and len(parts["anal"]) == 8
    assert parts["dorsal"][0] == (0.228515625, 0.00390625)
    assert parts["anal"][-1] == (0.41796875, 0.83203125)


def test_round_trip_of_bonybream_points():
    sp = load_species(PARAMS / "bonybream.txt")
    assert sp.texture_points is not None
    text = format_fxl(sp.texture_points, sp.circle_sections)
    assert text.splitlines()[:3] == ["//body", "192", "0 0 0.015625 0.3046875"]
    parts = parse_fxl(text)
    for name, pts in parts.items():
        assert tuple(pts) == getattr(sp.texture_points, name)


@pytest.mark.parametrize("text, line, words", [
    ("//dorsal\n2\n0.1 0.2\n", 3, "expected 2 points"),
    ("//dorsal\nmany\n", 2, "expected a point count"),
    ("//dorsal\n1\n0.1 1.5\n", 3, "from 0 to 1"),
    ("//dorsal\n1\n0.1 nan\n", 3, "from 0 to 1"),
    ("//dorsal\n1\n0.1 x\n", 3, "expected a number"),
    ("//dorsal\n1\n0.1 0.2\n//dorsal\n1\n0.1 0.2\n", 4, "each part once"),
    ("//fins\n1\n0.1 0.2\n", 2, "//part line first"),
    ("//body\n1\n0 0 0.1 0.2\n//fins\n", 4, "part name"),
    ("// just a comment\n", 1, "found none"),
])
def test_faults_name_their_line(text, line, words):
    with pytest.raises(FishgenError) as err:
        parse_fxl(text, "p.FXL")
    assert err.value.line == line and words in err.value.message


@pytest.mark.parametrize("text,line,message", [
    ("//body\n4\n1 1 0.1 0.1\n1 0 0.2 0.2\n0 1 0.3 0.3\n0 0 0.4 0.4\n", 3,
     "section and circle 0 0, found 1 1"),
    ("//body\n2\n0.1 0.1 0.2 0.2\n0.3 0.3 0.4 0.4\n", 3, "whole numbers first, found '0.1'"),
    ("//body\n4\n0 0 0.1 0.1\n0 1 0.2 0.2\n0 3 0.3 0.3\n1 0 0.4 0.4\n", 5, "found 0 3"),
    ("//body\n3\n0 0 0.1 0.1\n0 1 0.2 0.2\n1 0 0.3 0.3\n", 5, "expected 2 points on the last body section"),
    ("//dorsal\n" + "9" * 400 + "\n", 2, "expected a point count of at most 100,000"),
])
def test_body_lines_are_read_in_their_numbered_order_and_counts_are_bounded(text, line, message):
    """Issue 26, faults 14 and 7: the indices were ignored (a reversed file put the tail's point at
    the nose), and a count of 400 digits overflowed."""
    with pytest.raises(FishgenError) as caught:
        parse_fxl(text, "x.FXL")
    assert caught.value.line == line and message in caught.value.message


def test_a_fifo_given_as_fxl_in_is_refused_at_once(tmp_path):
    """Issue 26, fault 8: `--fxl-in` given a FIFO blocked forever."""
    import os

    fifo = tmp_path / "points.FXL"
    os.mkfifo(fifo)
    with pytest.raises(FishgenError, match="regular .FXL file"):
        read_fxl(fifo)
