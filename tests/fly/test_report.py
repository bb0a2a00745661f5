"""The fly-through's report: what the page posts is checked; JSON whole, CSV one row per second."""
from __future__ import annotations

import csv
import json
import math

import pytest

from fishgen import __version__
from fishgen.errors import FishgenError
from fishgen.fly.report import CSV_COLUMNS, check_report, full_report, summary, write_report
from tests.fly.conftest import page_report


def test_a_good_report_is_kept_with_every_field_the_issue_asks_for():
    r = full_report(check_report(page_report()), {"inputs": ["a.awn"], "headless": True})
    assert r["fishgen"] == __version__ and r["window"] == {"width": 800, "height": 600}
    assert r["seconds"] == 2.0 and r["frames"] == 40
    assert set(r["fps"]) == {"median", "p5", "min", "max"}
    assert r["scene"]["particles"] == 615 and r["drawn"]["particles"] == 615.0
    assert r["renderer"].startswith("ANGLE") and len(r["per_second"]) == 2


@pytest.mark.parametrize("change", [
    {"frames": -1}, {"seconds": math.nan}, {"fps": {"median": 1}}, {"renderer": "x" * 400},
    {"per_second": "many"}, {"window": {"width": 0, "height": 600}},
    {"drawn": {"particles": True, "billboards": 0, "clouds": 1}},
])
def test_a_malformed_report_is_refused_in_one_line(change):
    with pytest.raises(FishgenError, match="^expected "):
        check_report(page_report(**change))


def test_a_report_without_a_member_is_refused():
    bad = page_report()
    del bad["fps"]
    with pytest.raises(FishgenError, match="fps"):
        check_report(bad)


def test_json_and_csv_reports(tmp_path):
    r = full_report(check_report(page_report()), {"headless": True})
    write_report(r, tmp_path / "r.json")
    assert json.loads((tmp_path / "r.json").read_text()) == r
    write_report(r, tmp_path / "r.csv")
    rows = list(csv.DictReader((tmp_path / "r.csv").open()))
    assert tuple(rows[0]) == CSV_COLUMNS and len(rows) == 2           # one row per second
    assert rows[1]["second"] == "1" and rows[1]["frames"] == "19" and rows[0]["particles_in_scene"] == "615"
    assert rows[0]["fishgen"] == __version__ and rows[0]["renderer"].startswith("ANGLE")


def test_the_summary_says_size_frames_fps_particles_and_renderer():
    text = "\n".join(summary(full_report(check_report(page_report()), {})))
    for words in ("800x600", "40 frames", "20.0 FPS median", "615 particles", "SwiftShader"):
        assert words in text


@pytest.mark.parametrize("instancing, said", [(True, "schools instanced"),
                                              (False, "schools drawn fish by fish (--no-instancing)")])
def test_a_school_flown_alone_is_summed_up_as_meshes_and_how_they_were_drawn(instancing, said):
    """Flying a school printed only "0 particles in 0 clouds", and a --no-instancing report looked
    like an instanced one."""
    scene = {"particles": 0, "billboards": 0, "distant_particles": 0, "distant_billboards": 0,
             "clouds": 0, "meshes": 1000}
    report = full_report(check_report(page_report(scene=scene)), {"instancing": instancing})
    lines = summary(report)
    assert report["instancing"] is instancing
    assert not any(line.startswith("0 particles") for line in lines)
    assert not any(line.startswith("impostors:") for line in lines), "no clouds, no impostor line"
    assert f"1,000 meshes (fish and other solids), {said}" in lines
