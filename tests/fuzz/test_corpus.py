"""The committed seed corpus is what `python -m fishgen.fuzz.corpus` makes from params/."""
from pathlib import Path

from fishgen.fuzz.corpus import make_corpus
from fishgen.fuzz.inputs import DEFAULT_CORPUS


def names(folder: Path) -> set[str]:
    return {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}


def test_regenerating_the_corpus_makes_the_committed_files_and_keeps_the_thesis_sample(tmp_path):
    """A regeneration once deleted the Appendix B sample and left a mask texture out of the
    corpus: each file it makes is committed, and it makes every committed file (the bytes of
    built assets depend on the machine's zlib, so names are compared, and the hand-written texts)."""
    make_corpus(tmp_path)
    assert names(tmp_path) == names(DEFAULT_CORPUS)
    for text in ("fxl/appendix_b.fxl", "scene/full.toml", "ply/ascii_cloud/cloud.ply"):
        assert (tmp_path / text).read_bytes() == (DEFAULT_CORPUS / text).read_bytes(), text
