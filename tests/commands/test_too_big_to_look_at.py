"""A glTF written past what fishgen's own viewers read gets one note saying so (engines load it)."""
from __future__ import annotations

from pathlib import Path

from fishgen.commands import Events, _too_big_to_look_at


def sparse(path: Path, size: int) -> Path:
    with path.open("wb") as handle:
        handle.truncate(size)       # the size by stat, nothing on disk
    return path


def notes_for(*paths: Path) -> list[str]:
    said: list[str] = []
    _too_big_to_look_at(paths, Events(note=said.append))
    return said


def test_past_what_preview_and_fly_read_is_said(tmp_path):
    """`sky --billboards --particles 1200000` wrote 528 MiB that `preview` and `fly` refused."""
    glb = sparse(tmp_path / "sky.glb", 528 << 20)
    assert notes_for(glb) == [f"{glb}: 528 MiB, more than `fishgen preview` and `fishgen fly` read (512 MiB) "
                              "or `fishgen view` embeds (256 MiB); engines load it"]


def test_past_what_view_embeds_is_said_and_a_gltf_buffer_counts(tmp_path):
    buffer = sparse(tmp_path / "sky.bin", 300 << 20)
    assert notes_for(tmp_path / "sky.gltf", buffer) == [
        f"{buffer}: 300 MiB, more than `fishgen view` embeds in a page (256 MiB); `fishgen preview`, "
        "`fishgen fly` and engines load it"]


def test_what_every_viewer_reads_and_other_formats_are_not_noted(tmp_path):
    assert notes_for(sparse(tmp_path / "a.glb", 256 << 20), sparse(tmp_path / "b.ply", 600 << 20),
                     tmp_path / "never_landed.glb") == []
