"""What the batch command reads before its jobs run, to guard the files they read."""
from __future__ import annotations

import shutil

from fishgen.commands.batch import _job_reads, _manifest
from tests.conftest import ROOT


def test_each_input_is_read_once_however_many_jobs_build_it(tmp_path, monkeypatch):
    """A manifest of 100 builds of four species parsed each file 100 times in the batch's own
    process, before any job started (0.15 s of a 2 s `-j 2` run). A job with its own --textures
    reads its own textures."""
    import fishgen.species.parser as parser

    (tmp_path / "params").mkdir()
    shutil.copy(ROOT / "params" / "bonybream.txt", tmp_path / "params")
    for folder in ("textures", "other"):
        (tmp_path / folder).mkdir()
        for name in ("bonybream.png", "bonybream_mask.png"):
            shutil.copy(ROOT / "textures" / name, tmp_path / folder / name)
    manifest = tmp_path / "params" / "m.toml"
    manifest.write_text('out = "out"\n' + "".join(
        f'[[build]]\ninput = "bonybream.txt"\noutput = "{i}.glb"\n' for i in range(5))
        + '[[build]]\ninput = "bonybream.txt"\noutput = "5.glb"\ntextures = "../other"\n')
    loads = []
    real = parser.load_species
    monkeypatch.setattr(parser, "load_species", lambda *a, **k: loads.append(a) or real(*a, **k))
    reads = _job_reads(_manifest(manifest, None))
    assert len(loads) == 2
    species = tmp_path / "params" / "bonybream.txt"
    assert [read for _, read in reads] == 5 * [[species, tmp_path / "textures" / "bonybream.png",
                                              tmp_path / "textures" / "bonybream_mask.png"]] + [
        [species, tmp_path / "other" / "bonybream.png", tmp_path / "other" / "bonybream_mask.png"]]
