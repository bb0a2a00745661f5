"""A glTF written past what a client reads or plays gets one note saying so (it is written: an
engine loads it); nothing is said of files every client takes."""
from __future__ import annotations

from pathlib import Path

import pytest

from fishgen.exchange.client_limits import GODOT3_TRACKS, notes
from tests.conftest import PARAMS, run_cli


def sparse(path: Path, size: int) -> Path:
    with path.open("wb") as handle:
        handle.truncate(size)       # the size by stat, nothing on disk
    return path


def test_past_what_preview_and_fly_read_is_said(tmp_path):
    """`sky --billboards --particles 1200000` wrote 528 MiB that `preview` and `fly` refused."""
    glb = sparse(tmp_path / "sky.glb", 528 << 20)
    assert notes((glb,)) == [f"{glb}: 528 MiB, more than `fishgen preview` and `fishgen fly` read (512 MiB) "
                             "or `fishgen view` embeds (256 MiB); engines load it"]


def test_past_what_view_embeds_is_said_and_a_gltf_buffer_counts(tmp_path):
    buffer = sparse(tmp_path / "sky.bin", 300 << 20)
    assert notes((tmp_path / "sky.gltf", buffer)) == [
        f"{buffer}: 300 MiB, more than `fishgen view` embeds in a page (256 MiB); `fishgen preview`, "
        "`fishgen fly` and engines load it"]


def test_what_every_viewer_reads_and_other_formats_are_not_noted(tmp_path):
    assert notes((sparse(tmp_path / "a.glb", 256 << 20), sparse(tmp_path / "b.ply", 600 << 20),
                  tmp_path / "never_landed.glb")) == []


@pytest.mark.parametrize("count,noted", [(28, False), (29, True)])
def test_a_school_past_what_godot_3_animates_is_said(tmp_path, count, noted):
    """Godot 3 plays at most 1,024 animated blend-shape weights: fins and body waves of 36 weights a
    fish froze past the 28th fish (QA pass 14: 29 of 200 still, 203,808 error lines, no word)."""
    out = tmp_path / "s.glb"
    run = run_cli("school", PARAMS / "bonybream.txt", "--count", str(count), "--frames", "4", "-o", out)
    assert run.returncode == 0, run.stderr
    said = [line for line in run.stderr.splitlines() if "Godot 3" in line]
    assert said == ([f"{out}: animates {count * 36:,} blend-shape weights; Godot 3 plays at most "
                     f"{GODOT3_TRACKS:,} of each and leaves the rest still (schools in Godot 3: "
                     "docs/clients.md)"] if noted else [])


@pytest.mark.parametrize("count,noted", [(170, False), (171, True)])
def test_a_rigid_school_past_godot_3s_nodes_is_said(tmp_path, count, noted):
    """With --swim fins a fish animates 6 nodes and no weights: 29 of 200 stood still (QA pass 14)."""
    out = tmp_path / "s.glb"
    run = run_cli("school", PARAMS / "bonybream.txt", "--count", str(count), "--frames", "4",
                  "--swim", "fins", "-o", out)
    assert run.returncode == 0, run.stderr
    assert ("animates 1,026 nodes; Godot 3 plays at most 1,024" in run.stderr) == noted, run.stderr
