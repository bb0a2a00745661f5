"""The OBJ/PLY reader refuses malformed and oversized files in one ``expected ..., found ...`` line.

Sizes are checked by stat (the asset and its side files) and from the PLY
header (element counts x property sizes against the bytes there) before
trimesh reads or allocates anything; valid edge cases (several MTL libraries
on one line, a Latin-1 byte) load.
"""
from __future__ import annotations

import re
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest

from fishgen.errors import FishgenError
from fishgen.exchange.mesh_reader import read_mesh_file
from tests.conftest import run_cli

TRI = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"


def refused(path: Path, pattern: str, named: Path | None = None) -> str:
    """The one-line message, naming ``named`` (else ``path``), checked for its form and ``pattern``."""
    with pytest.raises(FishgenError) as err:
        read_mesh_file(path)
    text = str(err.value)
    assert text.startswith(f"{named or path}") and ": expected " in text and ", found " in text, text
    assert "\n" not in text and re.search(pattern, text), text
    return text


def _sparse(path: Path, size: int, head: bytes = b"") -> Path:
    with path.open("wb") as f:
        f.write(head)
        f.truncate(size)  # sparse: the size by stat, nothing on disk
    return path


@pytest.mark.parametrize("vertex", ["v 0 0", "v 0", "v a b c", "v 0 nan 0", "v 0 0 inf", "v 1 2 3 4 5 6 7 8"])
def test_obj_vertex_without_three_finite_coordinates(tmp_path, vertex):
    path = tmp_path / "bad.obj"
    path.write_text(f"# a comment\n{TRI}{vertex}\nf 1 2 3\n")
    text = refused(path, r"expected a vertex of 3 finite coordinates \(v x y z\), found ")
    assert text.startswith(f"{path}:5: ")


@pytest.mark.parametrize("face", ["f 1 2", "f 1", "f", "f 1/1/1 2/2/2 # and a comment"])
def test_obj_face_of_fewer_than_three_corners(tmp_path, face):
    """A file cut off mid-face (or a face of two corners) was half a fish, read with no word."""
    path = tmp_path / "bad.obj"
    path.write_text(f"{TRI}f 1 2 3\n{face}\n")
    text = refused(path, r"expected a face of 3 or more corners \(f a b c\), found ")
    assert text.startswith(f"{path}:5: ")


def test_obj_vertex_colours_and_w_are_fine(tmp_path):
    path = tmp_path / "ok.obj"
    path.write_text("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 1.0\nf 1 2 3\n")
    assert read_mesh_file(path).counts()["triangles"] == 1


def test_two_mtl_libraries_on_one_line(tmp_path):
    (tmp_path / "a.mtl").write_text("newmtl red\nKd 1 0 0\n")
    (tmp_path / "b.mtl").write_text("newmtl glass\nKd 0 1 0\nd 0.5\n")
    path = tmp_path / "two.obj"
    path.write_text(f"mtllib a.mtl b.mtl\n{TRI}v 1 1 0\nusemtl red\nf 1 2 3\nusemtl glass\nf 2 4 3\n")
    scene = read_mesh_file(path)
    materials = {m.name: m for m in scene.materials}
    assert set(materials) == {"red", "glass"}
    assert materials["glass"].alpha_mode == "BLEND" and materials["glass"].base_color[3] == 0.5
    assert materials["red"].base_color[0] == pytest.approx(1)


def test_mtl_library_with_a_space_in_its_name(tmp_path):
    (tmp_path / "my lib.mtl").write_text("newmtl glass\nKd 0 1 0\nd 0.25\n")
    path = tmp_path / "one.obj"
    path.write_text(f"mtllib my lib.mtl\n{TRI}usemtl glass\nf 1 2 3\n")
    (material,) = read_mesh_file(path).materials
    assert material.alpha_mode == "BLEND" and material.base_color[3] == 0.25


def test_latin1_bytes_load(tmp_path):
    (tmp_path / "m.mtl").write_bytes(b"# Gr\xfcn\nnewmtl gr\xfcn\nKd 0 1 0\nd 0.5\n")
    path = tmp_path / "latin.obj"
    path.write_bytes(b"# caf\xe9\nmtllib m.mtl\no caf\xe9\n" + TRI.encode() + b"usemtl gr\xfcn\nf 1 2 3\n")
    scene = read_mesh_file(path)
    assert scene.counts()["triangles"] == 1
    assert [m.alpha_mode for m in scene.materials] == ["BLEND"]


def test_obj_and_side_files_over_the_caps_are_refused_by_stat(tmp_path):
    big = _sparse(tmp_path / "big.obj", 3 * 2**30, b"v 0 0 0\n")
    refused(big, r"an OBJ file of at most 256\.0 MiB, found 'big\.obj' of 3\.0 GiB")
    _sparse(tmp_path / "big.mtl", 2**30, b"newmtl m\n")
    path = tmp_path / "tri.obj"
    path.write_text(f"mtllib big.mtl\n{TRI}f 1 2 3\n")
    refused(path, r"an MTL file of at most 64\.0 MiB, found 'big\.mtl' of 1\.0 GiB")
    (tmp_path / "big.mtl").write_text("newmtl m\nmap_Kd huge.png\n")
    _sparse(tmp_path / "huge.png", 2**30)
    refused(path, r"a texture file of at most 64\.0 MiB, found 'huge\.png' of 1\.0 GiB")


def _png_header(width: int, height: int) -> bytes:
    ihdr = b"IHDR" + struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + ihdr + struct.pack(">I", zlib.crc32(ihdr))
            + struct.pack(">I", 0) + b"IEND" + struct.pack(">I", zlib.crc32(b"IEND")))


def test_huge_or_damaged_mtl_texture_is_refused_before_decoding(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl m\nKd 1 1 1\nmap_Kd skin.png\n")
    (tmp_path / "skin.png").write_bytes(_png_header(12000, 12000))
    path = tmp_path / "tex.obj"
    path.write_text(f"mtllib m.mtl\n{TRI}vt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n")
    text = refused(path, r"at most 8192 px a side .* found 12000x12000", tmp_path / "m.mtl")
    assert text.startswith(f"{tmp_path / 'm.mtl'}:3: ")
    (tmp_path / "skin.png").write_bytes(b"\x89PNG\r\n\x1a\n garbage")
    refused(path, r"a PNG or JPEG image at 'skin\.png', found unreadable data", tmp_path / "m.mtl")


def _binary_ply(path: Path, count: int, data: bytes) -> Path:
    path.write_bytes(f"ply\nformat binary_little_endian 1.0\nelement vertex {count}\nproperty float x\n"
                     f"property float y\nproperty float z\nend_header\n".encode() + data)
    return path


def test_ply_declaring_more_than_its_bytes_is_refused_before_allocating(tmp_path):
    path = _binary_ply(tmp_path / "huge.ply", 10**9, struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0))
    refused(path, r"at least 12,000,000,000 bytes of binary_little_endian data for 1,000,000,000 vertex, "
                  r"found 36 bytes after the header")
    ascii_ply = tmp_path / "huge_ascii.ply"
    ascii_ply.write_text("ply\nformat ascii 1.0\nelement vertex 1000000000\nproperty float x\n"
                         "property float y\nproperty float z\nend_header\n0 0 0\n")
    refused(ascii_ply, r"1,000,000,000 rows of vertex \(x y z\), found the file ending after 1$")
    assert refused(ascii_ply, "").startswith(f"{ascii_ply}:9: ")
    faces = tmp_path / "faces.ply"
    faces.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                      b"property float y\nproperty float z\nelement face 100000000\n"
                      b"property list uchar int vertex_indices\nend_header\n"
                      + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 2))
    refused(faces, r"at least 100,000,036 bytes .* for 3 vertex, 100,000,000 face")


@pytest.mark.parametrize("header,pattern", [
    ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n", r"no end_header"),
    ("solid\n", r"expected a PLY header \(ply \.\.\. end_header\), found no 'ply' first"),
    ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nend_header\n"
     "0 0\n0 0\n0 0\n",
     r"vertex properties x, y and z, found x, y"),
    ("ply\nformat ascii 1.0\nelement vertex 3\nproperty quad x\nend_header\n", r"property TYPE NAME"),
    ("ply\nformat ascii 1.0\nelement vertex -3\nend_header\n", r"element NAME COUNT"),
    ("ply\nformat xml 1.0\nend_header\n", r"format ascii, binary_little_endian or binary_big_endian"),
    ("ply\nproperty float x\nend_header\n", r"an element before its properties"),
])
def test_ply_header_faults(tmp_path, header, pattern):
    path = tmp_path / "bad.ply"
    path.write_text(header)
    refused(path, pattern)


ASCII_HEAD = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
              "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n")


@pytest.mark.parametrize("body,pattern", [
    ("0 0 0\n1 0 0\nzz 1 0\n3 0 1 2\n", r":12: expected numbers for a vertex \(x y z\), found 'zz 1 0'$"),
    ("0,0,0\n1 0 0\n0 1 0\n3 0 1 2\n", r":10: expected numbers for a vertex \(x y z\), found '0,0,0'$"),
    ("0 0 0\n1 0 0\n0 1 0\n3 0 1 x\n",
     r":13: expected numbers for a face \(vertex_indices\), found '3 0 1 x'"),
    ("0 0 0\n1 0 0\n0 1 0\n3 0 1\n",
     r":13: expected 4 numbers for a face \(vertex_indices\), found 3: '3 0 1'"),
    ("0 0 0\n1 0 0\n0 1 0\ninf 0 1\n", r":13: expected a whole count before a face's list, found 'inf 0 1'"),
])
def test_an_ascii_ply_body_fault_is_said_at_its_line_in_its_own_words(tmp_path, body, pattern):
    """numpy's "string or file could not be read to its end due to unmatched data" (or, for a
    short face list, "an empty asset") said nothing of where: the first bad line is named."""
    path = tmp_path / "bad.ply"
    path.write_text(ASCII_HEAD + body)
    text = refused(path, pattern)
    assert "unmatched data" not in text and "empty asset" not in text


def test_a_well_formed_ascii_ply_with_faces_loads(tmp_path):
    path = tmp_path / "ok.ply"
    path.write_text(ASCII_HEAD + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    assert read_mesh_file(path).meshes


def test_ply_over_the_cap_is_refused_by_stat(tmp_path):
    path = _sparse(tmp_path / "big.ply", 2**30, b"ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
                   b"property float x\nproperty float y\nproperty float z\nend_header\n")
    refused(path, r"a PLY file of at most 512\.0 MiB, found 'big\.ply' of 1\.0 GiB")


def test_non_finite_ply_positions_are_refused(tmp_path):
    path = _binary_ply(tmp_path / "nan.ply", 3, struct.pack("<9f", 0, 0, 0, np.nan, 0, 0, 0, 1, 0))
    refused(path, r"finite vertex coordinates, found \[nan, 0\.0, 0\.0\] at vertex 2")


def test_valid_binary_ply_points_still_load(tmp_path):
    path = _binary_ply(tmp_path / "ok.ply", 3, struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0))
    assert read_mesh_file(path).counts()["particles"] == 3


@pytest.mark.parametrize("case", ["obj", "ply"])
def test_cli_prints_one_line(tmp_path, case):
    if case == "obj":
        path = tmp_path / "flat.obj"
        path.write_text("v 0 0\nv 1 0\nv 0 1\nf 1 2 3\n")
        start = f"{path}:1: expected a vertex of 3 finite coordinates"
    else:
        path = _binary_ply(tmp_path / "huge.ply", 10**9, b"\0" * 36)
        start = f"{path}: expected at least 12,000,000,000 bytes"
    result = run_cli("preview", path, "-o", tmp_path / "x.png", "--size", "64x48")
    assert result.returncode == 2 and result.stderr.startswith(start), result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr


@pytest.mark.parametrize("missing", ["f.mtl", "f_skin.png"])
def test_a_side_file_an_obj_names_must_be_there_for_preview_and_view_alike(tmp_path, missing):
    """Issue 26: preview rendered an OBJ whose .mtl was missing (exit 0) and view refused it (exit 2).
    One rule for both: what the asset names must be there."""
    from tests.conftest import PARAMS, run_cli

    assert run_cli("build", PARAMS / "bonybream.txt", "-o", tmp_path / "f.obj").returncode == 0
    (tmp_path / missing).unlink()
    for command in (["preview", tmp_path / "f.obj", "-o", tmp_path / "p.png"],
                    ["view", tmp_path / "f.obj", "--no-serve", "-o", tmp_path / "p.html"]):
        result = run_cli(*command)
        assert result.returncode == 2 and f"{missing!r}" in result.stderr and "found none" in result.stderr
        assert result.stderr.count("\n") == 1


def test_a_library_fault_is_said_about_the_file_not_named_by_its_exception():
    """A reader library's own bug (TypeError, UnboundLocalError...) says the file holds content the
    reader cannot parse; a message about the data is kept (issue 26)."""
    from fishgen.exchange.guards import what_was_found

    assert what_was_found(TypeError("unhashable type: 'list'"), "OBJ") == (
        "content the OBJ reader cannot parse")
    assert what_was_found(UnboundLocalError("cannot access local variable 'v'"), "PLY") == (
        "content the PLY reader cannot parse")
    assert what_was_found(ValueError("could not convert string to float: 'x'"), "OBJ") == (
        "could not convert string to float: 'x'")


def test_an_obj_that_trimesh_reads_as_flat_vertices_is_refused_in_one_line():
    """Fuzz run seed 31, obj #21176: a mutated OBJ that trimesh loads with two coordinates a vertex;
    posing it raised numpy's ValueError. The reader now refuses it, naming the file."""
    from fishgen.errors import FishgenError
    from fishgen.exchange.mesh_reader import read_mesh_file
    from tests.conftest import ROOT

    path = ROOT / "tests" / "fixtures" / "obj_read_as_2d" / "pineapplefish.obj"
    with pytest.raises(FishgenError, match="expected vertices of three coordinates each, found 2"):
        read_mesh_file(path)
