"""Asset readers refuse side files outside the asset's folder and turn every bad file into one line."""
from __future__ import annotations

import json
import os
import shutil
import struct

import numpy as np
import pytest

from fishgen.errors import FishgenError
from fishgen.preview.inputs import load_input
from tests.conftest import run_cli
from tests.preview.test_readers import point_sets

SECRET = b"top secret, not part of any asset\n"


@pytest.fixture
def nest(tmp_path):
    """``tmp_path/asset/`` for assets, with a secret file beside that folder (outside it)."""
    (tmp_path / "secret.txt").write_bytes(SECRET)
    (tmp_path / "secret.png").write_bytes(_png())
    folder = tmp_path / "asset"
    folder.mkdir()
    return folder


def _png() -> bytes:
    import io

    from PIL import Image

    buf = io.BytesIO()
    Image.new("RGBA", (4, 4), (255, 0, 0, 255)).save(buf, "PNG")
    return buf.getvalue()


def _gltf_with_buffer(folder, uri: str):
    """A one-triangle glTF whose buffer is the file ``uri``."""
    data = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    (folder / "tri.bin").write_bytes(data)
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                          "min": [0, 0, 0], "max": [1, 1, 0]}],
           "bufferViews": [{"buffer": 0, "byteLength": 36}],
           "buffers": [{"uri": uri, "byteLength": 36}]}
    path = folder / "tri.gltf"
    path.write_text(json.dumps(doc))
    return path


def _obj(folder, mtllib: str = "tri.mtl", mtl: str | None = "newmtl m\nKd 1 1 1\n"):
    path = folder / "tri.obj"
    path.write_text(f"mtllib {mtllib}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                    "usemtl m\nf 1/1 2/2 3/3\n")
    if mtl is not None:
        (folder / "tri.mtl").write_text(mtl)
    return path


@pytest.mark.parametrize("uri", ["../secret.txt", "%2E%2E/secret.txt", "/etc/hostname",
                                 "file:///etc/hostname", "http://example.com/tri.bin", "..\\secret.txt"])
def test_gltf_uri_outside_the_folder_is_refused(nest, uri):
    path = _gltf_with_buffer(nest, uri)
    with pytest.raises(FishgenError) as err:
        load_input(path)
    assert str(path) in str(err.value) and repr(uri) in str(err.value)


def test_gltf_symlink_out_of_the_folder_is_refused(nest):
    os.symlink(nest.parent / "secret.txt", nest / "link.bin")
    with pytest.raises(FishgenError, match="outside"):
        load_input(_gltf_with_buffer(nest, "link.bin"))


def test_gltf_buffer_in_a_subfolder_is_fine(nest):
    (nest / "data").mkdir()
    path = _gltf_with_buffer(nest, "data/tri.bin")
    shutil.move(nest / "tri.bin", nest / "data" / "tri.bin")
    assert load_input(path).counts()["triangles"] == 1


@pytest.mark.parametrize("mtllib", ["../secret.txt", "/etc/hostname"])
def test_obj_mtllib_outside_the_folder_is_refused(nest, mtllib):
    path = _obj(nest, mtllib, mtl=None)
    with pytest.raises(FishgenError) as err:
        load_input(path)
    assert str(path) in str(err.value) and mtllib in str(err.value)


@pytest.mark.parametrize("texture", ["../secret.png", "/etc/hostname", "-imfchan m ../secret.png"])
def test_mtl_texture_outside_the_folder_is_refused(nest, texture):
    path = _obj(nest, mtl=f"newmtl m\nKd 1 1 1\nmap_Kd {texture}\n")
    with pytest.raises(FishgenError, match="secret.png|hostname"):
        load_input(path)


def test_ascii_ply_point_cloud_keeps_radius_and_colour(tmp_path):
    path = tmp_path / "cloud.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nproperty float radius\nproperty uchar red\nproperty uchar green\n"
                    "property uchar blue\nproperty float density\nend_header\n"
                    "0 0 0 0.1 255 0 0 1\n1 0 0 0.2 0 255 0 0.5\n0 1 0 0.3 0 0 255 0.25\n")
    ((_, radii, colors),) = point_sets(load_input(path))
    assert np.allclose(radii, [0.1, 0.2, 0.3])
    assert np.allclose(colors[:, 3], [1, 0.5, 0.25])
    assert colors[0, 0] == pytest.approx(1) and colors[0, 1] == pytest.approx(0)


def test_ascii_ply_bare_points_render(tmp_path):
    path = tmp_path / "p.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n")
    ((centres, radii, _),) = point_sets(load_input(path))
    assert len(centres) == 3 and np.all(radii > 0)


def _bad_face_ply(tmp_path):
    path = tmp_path / "bad.ply"
    header = (b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
              b"property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n")
    path.write_bytes(header + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 7))
    return path


def test_ply_face_index_out_of_range_is_an_error(tmp_path):
    with pytest.raises(FishgenError, match="found 7"):
        load_input(_bad_face_ply(tmp_path))


def test_mtl_opacity_that_is_not_a_number_names_the_line(nest):
    path = _obj(nest, mtl="newmtl m\nKd 1 1 1\nd abc\n")
    with pytest.raises(FishgenError) as err:
        load_input(path)
    assert str(err.value).startswith(f"{nest / 'tri.mtl'}:3: expected an opacity number")


@pytest.mark.usefixtures("gl_available")
@pytest.mark.parametrize("case", ["ascii_ply", "bad_face", "bad_mtl", "outside"])
def test_cli_reports_bad_assets_in_one_line(nest, tmp_path, case):
    if case == "ascii_ply":
        path = nest / "p.ply"
        path.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n")
    elif case == "bad_face":
        path = _bad_face_ply(nest)
    elif case == "bad_mtl":
        path = _obj(nest, mtl="newmtl m\nd abc\n")
    else:
        path = _obj(nest, mtl="newmtl m\nmap_Kd ../secret.png\n")
    out = tmp_path / "out.png"
    result = run_cli("preview", path, "-o", out, "--size", "64x48")
    assert "Traceback" not in result.stderr
    if case == "ascii_ply":
        assert result.returncode == 0, result.stderr
        assert out.is_file()
    else:
        assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1, result.stderr
        assert not out.exists()
