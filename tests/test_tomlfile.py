"""fishgen.tomlfile: TOML parse errors and key lines for FILE:LINE messages."""
import pytest

from fishgen.errors import FishgenError
from fishgen.tomlfile import Where, loads

TEXT = """\
out = "../out"
seed = 3

[[build]]
input = "a.txt"
output = "a.glb"

[[build]]
output = "b.glb"
input = "b.txt"

[school]
count = 10
[school.options]
count = 5
"""


def test_where_finds_each_key_in_its_own_table_entry():
    where = Where(TEXT, "m.toml")
    assert where.line("out") == 1
    assert where.line("seed") == 2
    assert where.line("output", "build", 0) == 6
    assert where.line("output", "build", 1) == 9
    assert where.line("input", "build", 1) == 10
    assert where.line("count", "school") == 13
    assert where.line("count", "school.options") == 15


def test_where_falls_back_to_the_table_header_and_knows_no_missing_top_level_key():
    where = Where(TEXT, "m.toml")
    assert where.line("missing", "build", 1) == 8
    assert where.line("missing") is None
    assert where.line("output", "build", 2) is None
    assert where.line("count") is None  # a table's key is not a top-level key


def test_loads_reports_the_line_of_a_syntax_error():
    with pytest.raises(FishgenError) as err:
        loads('a = 1\nb = = 2\n', "bad.toml")
    assert str(err.value).startswith("bad.toml:2: expected TOML, found ")


def test_an_integer_of_thousands_of_digits_is_one_line_at_its_place():
    """Issue 26, fault 6: Python's int-string limit raised a traceback from inside tomllib."""
    from fishgen.errors import FishgenError
    from fishgen.tomlfile import loads

    with pytest.raises(FishgenError) as caught:
        loads('out = "o"\n\nframes = ' + "9" * 5000 + "\n", "m.toml")
    assert str(caught.value) == ("m.toml:3: expected a number of at most a few hundred digits, "
                                 "found one of 5000 digits")


def test_a_scene_file_that_is_not_utf8_is_said_at_its_line(tmp_path):
    from fishgen.school.scene_file import load_scene_file

    path = tmp_path / "s.toml"
    path.write_bytes(b'frames = 10\n# caf\xe9 in Latin-1\n')
    with pytest.raises(FishgenError, match=r":2: expected UTF-8 text \(TOML\), found the byte 0xe9$"):
        load_scene_file(path)
