"""File names as the file system spells them and as the files that name them write them."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from fishgen.file_names import name_text, text_name

ROOT = Path(__file__).resolve().parents[1]

ASCII_LOCALE = {"LC_ALL": "C", "LANG": "C", "PYTHONCOERCECLOCALE": "0", "PYTHONUTF8": "0"}
"""A locale whose file names are ASCII: Python keeps a name's other bytes as surrogates."""


@pytest.mark.skipif(sys.getfilesystemencoding() != "utf-8", reason="names spelled as a UTF-8 locale does")
def test_a_name_is_written_by_its_bytes_and_read_back_as_the_same_file():
    # b"f\xc3\xafsh.png" as an ASCII locale spells it: the bytes past ASCII kept as surrogates
    assert name_text("f\udcc3\udcafsh.png") == "fïsh.png"
    assert name_text("fïsh.png") == "fïsh.png" and text_name("fïsh.png") == "fïsh.png"
    assert text_name(name_text("caf\udce9.png")) == "caf\udce9.png"     # latin-1 bytes kept as they are


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="a locale whose file names are not UTF-8")
def test_an_ascii_locale_writes_the_same_files_for_a_name_that_is_not_ascii(tmp_path):
    """``LC_ALL=C`` (Python's coercion off): the .gltf's URIs, the OBJ's, PLY's, USD's and species
    file's names and the viewer's page were a traceback (surrogates), the species file named its
    textures ``f_sh.png``, and a species file naming ``spëcies.png`` could not be read. Now every
    file's bytes are those a UTF-8 locale writes."""
    def run(env: dict[str, str], folder: Path) -> dict[str, bytes]:
        folder.mkdir()
        species = folder / "spëcies.txt"
        commands = [["species", "--random", "--seed", "3", "-o", str(species)],
                    *(["build", str(species), "-o", str(folder / f"fïsh.{ext}")]
                      for ext in ("gltf", "obj", "ply", "usdz")),
                    ["view", "--no-serve", str(folder / "fïsh.gltf"), "-o", str(folder / "vïew.html")]]
        for args in commands:
            done = subprocess.run([sys.executable, "-m", "fishgen", "-q", *args], capture_output=True,
                                  cwd=ROOT, env={**os.environ, **env})
            assert done.returncode == 0 and not done.stderr, (args, done.stderr.decode("utf-8", "replace"))
        return {p.name: p.read_bytes() for p in folder.iterdir()}

    ascii_locale = run(ASCII_LOCALE, tmp_path / "c")
    utf8 = run({"LC_ALL": "C.UTF-8", "PYTHONUTF8": "1"}, tmp_path / "u")
    assert sorted(ascii_locale) == sorted(utf8) and "fïsh.bin" in utf8 and "spëcies.png" in utf8
    assert ascii_locale == utf8
    assert b'"uri":"f%C3%AFsh.bin"' in utf8["fïsh.gltf"] and "mtllib fïsh.mtl".encode() in utf8["fïsh.obj"]
