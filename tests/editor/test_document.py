"""The editor's document: the page's cubes to cube file text, and that text read back by fishgen's parser."""
from __future__ import annotations

import json
import math

import pytest

from fishgen.clouds.parser import load_cubes
from fishgen.editor.document import (
    EditCube,
    cube_text,
    cubes_from_json,
    document_json,
    number_text,
    read_back,
)
from fishgen.errors import FishgenError
from tests.clouds.cloud_tables import TABLES


def _as_page_sends(cubes) -> list[dict]:
    """Cubes as the page holds them, through JSON as the browser sends them."""
    page = [EditCube(c.particles, c.size, c.centre, c.max_radius).json() for c in cubes]
    return json.loads(json.dumps(page))


@pytest.mark.parametrize("table", sorted(TABLES))
def test_a_report_table_saved_again_keeps_every_cube_exactly(table):
    original = load_cubes(TABLES[table])
    cubes = cubes_from_json(_as_page_sends(original.cubes))
    text = cube_text(cubes, "particles", "again.awn")
    again = read_back(text, "particles", "again.awn", cubes)
    assert [(c.particles, c.size, c.centre, c.max_radius) for c in again.cubes] == \
           [(c.particles, c.size, c.centre, c.max_radius) for c in original.cubes]
    assert text.splitlines()[:2] == [str(original.total), str(len(original.cubes))]


def test_the_totals_on_the_first_two_lines_follow_the_cubes():
    cubes = [EditCube(5, (1, 1, 1), (0, 0, 0), 2), EditCube(0, (1, 2, 3), (4, 5, 6), 0.5)]
    assert cube_text(cubes, "particles").splitlines() == ["5", "2", "5, 1, 1, 1, 0, 0, 0, 2",
                                                         "0, 1, 2, 3, 4, 5, 6, 0.5"]


def test_numbers_are_written_in_the_shortest_text_that_reads_back_the_same():
    for value in (6.12438e-07, -0.600002, 0.1 + 0.2, 1e-30, 3.4e38, 2.0, -0.0, 123456789.0):
        assert float(number_text(value)) == value
    assert number_text(2.0) == "2" and number_text(7) == "7" and number_text(0.5) == "0.5"


def test_a_texture_cloud_line_ends_with_its_texture():
    cubes = [EditCube(3, (1, 1, 1), (0, 0, 0), 2, "clouds/billow.png")]
    assert cube_text(cubes, "texture").splitlines()[2] == "3, 1, 1, 1, 0, 0, 0, 2, clouds/billow.png"


@pytest.mark.parametrize("texture, found", [(None, "none"), ("two words.png", "'two words.png'"),
                                            ("a,b.png", "'a,b.png'"), ("x.png\n1", "'x.png\\n1'")])
def test_a_texture_cloud_needs_a_texture_a_cube_line_can_hold(texture, found):
    with pytest.raises(FishgenError) as err:
        cube_text([EditCube(1, (1, 1, 1), (0, 0, 0), 1, "a.png"),
                   EditCube(1, (1, 1, 1), (0, 0, 0), 1, texture)], "texture", "sky.awa")
    assert str(err.value).startswith("sky.awa:4: expected a texture") and str(err.value).endswith(found)


WHOLE = "x.awn:3: expected a whole number of 0 or more for the particle count"


@pytest.mark.parametrize("cube, message", [
    (EditCube(1, (1, 1, 1), (0, 0, 0), 0), "x.awn:3: expected a maximum radius greater than 0, found '0'"),
    (EditCube(1, (1, -2, 1), (0, 0, 0), 1), "x.awn:3: expected a y size greater than 0, found '-2'"),
    (EditCube(2.5, (1, 1, 1), (0, 0, 0), 1), WHOLE + ", found '2.5'"),
    (EditCube(-1, (1, 1, 1), (0, 0, 0), 1), WHOLE + ", found '-1'"),
    (EditCube(1, (1, 1, 1), (math.nan, 0, 0), 1), "x.awn:3: expected a finite number for the centre x"),
    (EditCube(1, (1e39, 1, 1), (0, 0, 0), 1), "x.awn:3: expected an x size within float32 range"),
    (EditCube(0, (1, 1, 1), (0, 0, 0), 1), "x.awn:1: expected at least 1 particle in the cubes, found 0"),
])
def test_values_the_parser_refuses_are_its_one_line_with_the_cube_line(cube, message):
    with pytest.raises(FishgenError) as err:
        read_back(cube_text([cube], "particles", "x.awn"), "particles", "x.awn", [cube])
    assert str(err.value).startswith(message)


def test_an_empty_workspace_is_not_a_file():
    with pytest.raises(FishgenError, match=r"^x.awn:2: expected at least 1 cube, found 0$"):
        read_back(cube_text([], "particles", "x.awn"), "particles", "x.awn", [])


def _cube(**change) -> list[dict]:
    return [{"particles": 1, "size": [1, 1, 1], "centre": [0, 0, 0], "radius": 1, **change}]


@pytest.mark.parametrize("value, message", [
    ({"particles": 1}, "expected the cubes as a list, found a dict of 1"),
    ([{"particles": 1, "size": [1, 1, 1], "centre": [0, 0, 0]}], "expected cube 1 as {particles, size"),
    (_cube(colour=1), "expected cube 1 as"),
    (_cube(particles="1\n2"), "expected cube 1's count as a number, found the text"),
    (_cube(particles=True), "expected cube 1's count as a number"),
    (_cube(size=[1, 1]), "expected cube 1's size as three numbers"),
    (_cube(centre=[0, 0, "0, 5"]), "expected cube 1's centre as a number"),
    (_cube(texture=5), "expected cube 1's texture as a name or null"),
])
def test_the_page_json_must_have_the_cubes_shape(value, message):
    """Nothing but numbers reaches the file's number fields: no text that could add fields or lines."""
    with pytest.raises(FishgenError) as err:
        cubes_from_json(value)
    assert str(err.value).startswith(message)


def test_too_many_cubes_are_refused_before_any_is_read():
    with pytest.raises(FishgenError, match="expected at most 100,000 cubes, found 100,001"):
        cubes_from_json([None] * 100_001)


def test_a_texture_cloud_opens_with_its_texture_names(tmp_path):
    (tmp_path / "textures" / "clouds").mkdir(parents=True)
    for name in ("a.png", "b.png"):
        (tmp_path / "textures" / "clouds" / name).write_bytes(_png())
    folder = tmp_path / "skies"
    folder.mkdir()
    (folder / "own.png").write_bytes(_png())
    (folder / "sky.awa").write_text("3\n3\n1, 1, 1, 1, 0, 0, 0, 1, clouds/a.png\n"
                                    "1, 1, 1, 1, 2, 0, 0, 1, ./clouds/b.png\n"
                                    "1, 1, 1, 1, 4, 0, 0, 1, own.png\n")
    from fishgen.clouds.parser import texture_roots

    doc = document_json(load_cubes(folder / "sky.awa"), texture_roots(folder / "sky.awa"))
    assert doc["mode"] == "texture"
    assert [c["texture"] for c in doc["cubes"]] == ["clouds/a.png", "clouds/b.png", "own.png"]


def _png() -> bytes:
    import io

    from PIL import Image

    out = io.BytesIO()
    Image.new("RGBA", (4, 4), (255, 255, 255, 128)).save(out, "PNG")
    return out.getvalue()
