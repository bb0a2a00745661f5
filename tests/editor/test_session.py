"""The editor's server, spoken to as the page speaks to it: what it reads, fills, writes and refuses."""
from __future__ import annotations

import hashlib
import json
import os

import pytest

from fishgen.clouds.parser import load_cubes
from fishgen.editor.document import EditCube
from tests.conftest import run_cli
from tests.editor.test_document import _as_page_sends


def _cubes(path) -> list[tuple]:
    return [(c.particles, c.size, c.centre, c.max_radius, c.texture and os.path.basename(c.texture))
            for c in load_cubes(path).cubes]


def _tree(root) -> dict[str, str]:
    """Every file under ``root`` and a hash of its bytes: to show nothing was written."""
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "link"
            for p in sorted(root.rglob("*")) if p.is_file() or p.is_symlink()}


def test_the_page_is_one_document_with_the_editor_inside(skies, start_editor):
    page = start_editor(skies / "table_4_3.awn").get("/")
    text = page.body.decode()
    assert page.status == 200 and "<title>table_4_3.awn · fishgen edit</title>" in text
    assert "TransformControls" in text or "transform" in text  # the bundle is inlined
    assert 'src="http' not in text and "<script src" not in text  # nothing fetched from elsewhere


def test_it_starts_with_the_file_it_was_given(skies, start_editor):
    doc = start_editor(skies / "table_4_3.awn").get("/api/document").json()
    assert doc["name"] == "table_4_3.awn" and doc["exists"] and doc["mode"] == "particles"
    assert [(c["particles"], tuple(c["size"]), tuple(c["centre"]), c["radius"]) for c in doc["cubes"]] == \
           [c[:4] for c in _cubes(skies / "table_4_3.awn")]
    assert doc["files"] == ["table_4_3.awn", "two.awa"]
    assert doc["textures"] == ["clouds/billow.png", "clouds/cumulus.png", "clouds/wisp.png"]


def test_a_file_that_does_not_exist_yet_is_an_empty_workspace(skies, start_editor):
    doc = start_editor(skies / "mycloud.awa").get("/api/document").json()
    assert (doc["name"], doc["exists"], doc["mode"], doc["cubes"]) == ("mycloud.awa", False, "texture", [])
    assert not (skies / "mycloud.awa").exists()


def test_save_writes_the_cubes_exactly_after_reading_them_back(skies, start_editor):
    client = start_editor(skies / "table_4_3.awn")
    cubes = _as_page_sends(load_cubes(skies / "table_4_3.awn").cubes)
    cubes.append(EditCube(25, (1.5, 0.25, 2), (0.1, 0.2, 0.3), 1.75).json())
    answer = client.post("/api/save", {"name": "copy.awn", "mode": "particles", "cubes": cubes})
    assert answer.status == 200, answer.body
    assert answer.json()["saved"] == "copy.awn" and answer.json()["particles"] == 554 + 25
    added = (25, (1.5, 0.25, 2), (0.1, 0.2, 0.3), 1.75, None)
    assert _cubes(skies / "copy.awn") == _cubes(skies / "table_4_3.awn") + [added]
    assert (skies / "copy.awn").read_text().splitlines()[:2] == ["579", "18"]
    assert "copy.awn" in answer.json()["files"]


def test_a_texture_cloud_saves_with_its_textures(skies, start_editor):
    client = start_editor(skies / "two.awa")
    doc = client.get("/api/document").json()
    doc["cubes"][1]["texture"] = "clouds/cumulus.png"
    answer = client.post("/api/save", {"name": "two.awa", "mode": "texture", "cubes": doc["cubes"]})
    assert answer.status == 200, answer.body
    assert [c[4] for c in _cubes(skies / "two.awa")] == ["billow.png", "cumulus.png"]
    assert (skies / "two.awa").read_text().splitlines()[3].endswith(", clouds/cumulus.png")


@pytest.mark.parametrize("change, message", [
    ({"radius": 0}, "bad.awn:4: expected a maximum radius greater than 0, found '0'"),
    ({"particles": 2.5}, "bad.awn:4: expected a whole number of 0 or more for the particle count"),
    ({"size": [1, 1e39, 1]}, "bad.awn:4: expected a y size within float32 range"),
])
def test_a_file_that_would_not_parse_is_never_written_and_the_page_gets_one_line(skies, start_editor, change,
                                                                                message):
    client = start_editor(skies / "table_4_3.awn")
    cubes = _as_page_sends(load_cubes(skies / "table_4_3.awn").cubes)
    cubes[1].update(change)
    before = _tree(skies.parent)
    for name in ("bad.awn", "table_4_3.awn"):  # nor is a good file replaced by a bad one
        answer = client.post("/api/save", {"name": name, "mode": "particles", "cubes": cubes})
        assert answer.status == 422 and answer.json()["error"].startswith(message.replace("bad.awn", name))
        assert "\n" not in answer.json()["error"] and answer.json()["line"] == 4
    assert _tree(skies.parent) == before


def test_a_name_must_suit_the_system(skies, start_editor):
    client = start_editor(skies / "two.awa")
    doc = client.get("/api/document").json()
    answer = client.post("/api/save", {"name": "two.awn", "mode": "texture", "cubes": doc["cubes"]})
    assert answer.status == 422 and answer.json()["error"] == \
        "expected a name ending in .awa for a texture cloud, found 'two.awn'"


SAVE = {"name": "x.awn", "mode": "particles", "cubes": [EditCube(5, (1, 1, 1), (0, 0, 0), 1).json()]}


def test_a_name_past_the_file_systems_bytes_is_refused_in_one_line(skies, start_editor):
    """200 characters of é are 400 bytes: the name passed the 255-character check and the system's
    ENAMETOOLONG closed the connection with no answer (QA pass 15)."""
    client = start_editor(skies / "table_4_3.awn")
    name = "é" * 200 + ".awn"
    for route in ("/api/open", "/api/save"):
        answer = client.post(route, dict(SAVE, name=name) if route == "/api/save" else {"name": name})
        assert answer.status == 422, answer.body
        assert answer.json()["error"].startswith("expected a name of at most 255 bytes (the file "
                                                 "system's limit)")


@pytest.mark.parametrize("case", ["foreign host", "rebound name", "no token", "wrong token", "../ name",
                                  "absolute name", "link out", "oversized", "not json"])
def test_every_refusal_writes_nothing(skies, start_editor, case):
    """The issue's security list: a foreign Host, a missing token, a ../ name, an oversized request."""
    client = start_editor(skies / "table_4_3.awn")
    os.symlink(skies.parent / "elsewhere.awn", skies / "link.awn")
    body = dict(SAVE, name={"../ name": "../escape.awn", "absolute name": str(skies.parent / "abs.awn"),
                            "link out": "link.awn"}.get(case, "x.awn"))
    data = json.dumps(body).encode() if case != "not json" else b"{name: x.awn"
    before = _tree(skies.parent)
    # oversized: a body declared one byte over 16 MiB is refused before a byte of it is read
    host = {"foreign host": "example.com", "rebound name": f"evil.example:{client.server.port}"}.get(case)
    token = {"no token": "", "wrong token": client.server.token[:-2] + "xy"}.get(case)
    length = (16 << 20) + 1 if case == "oversized" else None
    answer = client.ask("POST", "/api/save", data, length=length, host=host, token=token)
    expected = {"foreign host": 403, "rebound name": 403, "no token": 403, "wrong token": 403,
                "oversized": 413, "not json": 400}.get(case, 422)
    assert answer.status == expected, answer.body
    assert _tree(skies.parent) == before and not (skies / "x.awn").exists()
    assert b"expected" in answer.body or b"only 127.0.0.1" in answer.body


def test_the_pages_reads_are_refused_the_same_way(skies, start_editor):
    client = start_editor(skies / "table_4_3.awn")
    (skies.parent / "secret.awn").write_text("1\n1\n1, 1, 1, 1, 0, 0, 0, 1\n")
    for name in ("../secret.awn", str(skies.parent / "secret.awn"), "nothere.awn"):
        body = {"name": name}
        answer = client.post("/api/open", body)
        assert answer.status == 422 and answer.json()["error"].startswith("expected")
    assert client.get("/api/document", token="").status == 403
    assert client.get("/api/texture?name=../skies/table_4_3.awn").status == 422
    assert client.get("/api/texture?name=clouds/../../skies/table_4_3.awn").status == 422
    assert client.get("/api/texture?name=clouds/wisp.png").body[:8] == b"\x89PNG\r\n\x1a\n"
    assert client.get("/etc/passwd").status == 404


def test_open_reads_another_cube_file_of_the_folder(skies, start_editor):
    doc = start_editor(skies / "table_4_3.awn").post("/api/open", {"name": "two.awa"}).json()
    assert doc["mode"] == "texture" and [c["texture"] for c in doc["cubes"]] == ["clouds/billow.png",
                                                                                "clouds/wisp.png"]


def test_a_declared_total_that_does_not_add_up_is_a_warning_for_the_page(skies, start_editor):
    (skies / "off.awn").write_text("9\n1\n5, 1, 1, 1, 0, 0, 0, 1\n")
    doc = start_editor(skies / "off.awn").get("/api/document").json()
    assert doc["warnings"] == ["off.awn:1: warning: declared total 9 particles, but the cubes hold 5; "
                               "using the cubes' counts"]


@pytest.mark.parametrize("file, options", [("table_4_3.awn", ["--seed", "7"]),
                                           ("table_4_3.awn", ["--seed", "3", "--sun", "1,0.2,-0.5"]),
                                           ("two.awa", ["--seed", "5"])])
def test_the_fill_is_what_fishgen_clouds_writes(skies, start_editor, tmp_path, file, options):
    """The page gets the GLB `fishgen clouds FILE -o x.glb` writes with the same seed and sun, to the byte."""
    from fishgen.clouds.lighting import Lighting

    sun = [float(v) for v in options[3].split(",")] if "--sun" in options else None
    client = start_editor(skies / file, lighting=Lighting() if sun is None else Lighting(sun=tuple(sun)))
    doc = client.get("/api/document").json()
    answer = client.post("/api/fill", {"name": file, "mode": doc["mode"], "cubes": doc["cubes"],
                                       "seed": int(options[1]), "sun": sun})
    assert answer.status == 200, answer.body
    facts, glb = answer.fill()
    out = tmp_path / "batch.glb"
    made = run_cli("clouds", skies / file, "-o", out, *options)
    assert made.returncode == 0, made.stderr
    assert glb == out.read_bytes()
    assert facts["particles"] == load_cubes(skies / file).total and facts["note"] is None


def test_the_page_sun_and_seed_change_the_fill(skies, start_editor):
    client = start_editor(skies / "table_4_3.awn")
    doc = client.get("/api/document").json()
    glbs = [client.post("/api/fill", {"name": "table_4_3.awn", "mode": "particles", "cubes": doc["cubes"],
                                      "seed": seed, "sun": sun}).fill()[1]
            for seed, sun in ((0, None), (1, None), (0, [-1, 0.2, 0]), (0, None))]
    assert glbs[0] == glbs[3] and len({glbs[0], glbs[1], glbs[2]}) == 3


def test_a_cloud_past_the_preview_limit_is_scaled_down_alike_and_says_so(skies, start_editor):
    client = start_editor(skies / "big.awn")
    cubes = [EditCube(150_000, (4, 4, 4), (0, 0, 0), 0.5).json(),
             EditCube(50_000, (2, 2, 2), (5, 0, 0), 0.5).json(),
             EditCube(0, (1, 1, 1), (9, 0, 0), 0.5).json()]
    facts, _ = client.post("/api/fill", {"name": "big.awn", "mode": "particles", "cubes": cubes}).fill()
    assert (facts["particles"], facts["whole"]) == (100_000, 200_000)
    assert facts["note"] == "previewing 100,000 of its 200,000 particles, every cube scaled alike"


@pytest.mark.parametrize("body, message", [
    ({"name": "x.awn", "mode": "clouds", "cubes": []}, "expected the system as 'particles' or 'texture'"),
    ({"name": "x.awn", "mode": "particles", "cubes": [], "seed": -1}, "expected a seed from 0"),
    ({"name": "x.awn", "mode": "particles", "cubes": [], "sun": [0, 0, 0]}, "expected sun as X,Y,Z"),
    ({"name": "x.awn", "mode": "particles", "cubes": []}, "x.awn:2: expected at least 1 cube, found 0"),
    ({"mode": "particles", "cubes": []}, "expected a JSON object with 'name'"),
])
def test_a_fill_the_parser_or_the_options_refuse_is_one_line(skies, start_editor, body, message):
    answer = start_editor(skies / "table_4_3.awn").post("/api/fill", body)
    assert answer.status == 422 and answer.json()["error"].startswith(message), answer.body


def test_a_save_over_a_file_another_program_changed_since_is_refused(skies, start_editor):
    """QA pass 15: another program's write between the page's read and its save was lost without a
    word. The page sends the stamp it read; a file changed since is refused (409) and kept."""
    path = skies / "table_4_3.awn"
    client = start_editor(path)
    doc = client.get("/api/document").json()
    body = {"name": "table_4_3.awn", "mode": "particles", "cubes": doc["cubes"], "stamp": doc["stamp"]}
    answer = client.post("/api/save", body)
    assert answer.status == 200, answer.body
    mine = path.read_bytes()
    path.write_text("7\n1\n7, 2, 2, 2, 0, 0, 0, 1\n")              # another program's edit
    answer = client.post("/api/save", dict(body, stamp=answer.json()["stamp"]))
    assert answer.status == 409 and "changed on disk since" in answer.json()["error"], answer.body
    assert path.read_text() == "7\n1\n7, 2, 2, 2, 0, 0, 0, 1\n" and path.read_bytes() != mine
    fresh = client.post("/api/open", {"name": "table_4_3.awn"}).json()       # read again: saved
    assert client.post("/api/save", dict(body, stamp=fresh["stamp"])).status == 200
    new = client.post("/api/save", {**SAVE, "name": "brand_new.awn", "stamp": None})   # none there yet
    assert new.status == 200, new.body


def test_a_save_refused_says_whether_the_file_was_made_changed_or_removed_since(skies, start_editor):
    """A name the page saw free is written only if it still is (picking another file of the folder
    and saving wrote over it without a word: QA pass 22); and a refusal says which of the three
    happened, not "changed by another program" for each."""
    path = skies / "table_4_3.awn"
    client = start_editor(path)
    doc = client.get("/api/document").json()
    (skies / "made.awn").write_text("7\n1\n7, 2, 2, 2, 0, 0, 0, 1\n")
    made = client.post("/api/save", {**SAVE, "name": "made.awn", "stamp": None})
    assert made.status == 409 and "expected no file made.awn" in made.json()["error"], made.body
    assert (skies / "made.awn").read_text() == "7\n1\n7, 2, 2, 2, 0, 0, 0, 1\n"
    path.unlink()
    body = {"name": "table_4_3.awn", "mode": "particles", "cubes": doc["cubes"], "stamp": doc["stamp"]}
    removed = client.post("/api/save", body)
    assert removed.status == 409 and "found it removed since" in removed.json()["error"], removed.body
    assert client.post("/api/save", dict(body, stamp=None)).status == 200      # Save again: written anew


def test_a_save_past_the_particle_limit_is_refused_at_the_cube_that_crosses_it(skies, start_editor):
    """It was refused at line 1 with the file's total, a line that names no cube (QA pass 22)."""
    client = start_editor(skies / "table_4_3.awn")
    cubes = [EditCube(10, (1, 1, 1), (0, 0, 0), 1).json(),
             EditCube(99_999_999_999, (1, 1, 1), (2, 0, 0), 1).json(),
             EditCube(10, (1, 1, 1), (4, 0, 0), 1).json()]
    answer = client.post("/api/save", {"name": "big.awn", "mode": "particles", "cubes": cubes, "stamp": None})
    assert answer.status == 422, answer.body
    error = answer.json()
    assert (error["line"], error["error"]) == (4, "big.awn:4: expected at most 50,000,000 particles, "
                                                  "found 100,000,000,009"), error
