"""Every export format round-trips; glTF passes the Khronos validator; writes are atomic."""
from __future__ import annotations

import csv
import io
import json
import struct

import numpy as np
import pytest
import trimesh
from cloud_tables import TABLES
from PIL import Image

from fishgen.clouds import export_cloud, fill_cloud, load_cubes
from fishgen.clouds.scene import TRIANGLES_PER_BILLBOARD, cloud_scene, turns
from fishgen.errors import FishgenError, SystemFailure
from fishgen.exchange import particles


@pytest.fixture(scope="module")
def cloud():
    return fill_cloud(load_cubes(TABLES["4.4"]), seed=21)


def glb_parts(path):
    data = path.read_bytes()
    magic, version, length = struct.unpack_from("<4sII", data)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    json_len, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON"
    doc = json.loads(data[20:20 + json_len])
    bin_len, kind = struct.unpack_from("<I4s", data, 20 + json_len)
    assert kind == b"BIN\0"
    return doc, data[28 + json_len:28 + json_len + bin_len]


def accessor_array(doc, blob, index, dtype, width):
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    stride = view.get("byteStride", np.dtype(dtype).itemsize * width)
    raw = np.frombuffer(blob, np.uint8, acc["count"] * stride, view["byteOffset"])
    rows = raw.reshape(acc["count"], stride)[:, :np.dtype(dtype).itemsize * width]
    return rows.copy().view(dtype).reshape(acc["count"], width)


def test_ply_loads_in_trimesh_and_plyfile(cloud, tmp_path):
    path = tmp_path / "cloud.ply"
    export_cloud(cloud, path)
    assert path.read_bytes().startswith(b"ply\nformat binary_little_endian 1.0\n")
    points = trimesh.load(path)
    np.testing.assert_array_equal(np.asarray(points.vertices, np.float32), cloud.centers)
    np.testing.assert_array_equal(np.asarray(points.colors)[:, :3], cloud.colors)
    plyfile = pytest.importorskip("plyfile")
    vertex = plyfile.PlyData.read(str(path))["vertex"].data
    assert vertex.dtype.names == ("x", "y", "z", "radius", "density", "red", "green", "blue")
    np.testing.assert_array_equal(vertex["radius"], cloud.radii)
    np.testing.assert_array_equal(vertex["density"], cloud.density)
    np.testing.assert_array_equal(vertex["green"], cloud.colors[:, 1])


def test_glb_points(cloud, tmp_path, gltf_validator):
    path = tmp_path / "cloud.glb"
    export_cloud(cloud, path)
    gltf_validator(path)
    doc, blob = glb_parts(path)
    prim = doc["meshes"][0]["primitives"][0]
    assert prim["mode"] == 0 and set(prim["attributes"]) == {"POSITION", "COLOR_0", "_RADIUS", "_DENSITY",
                                                             "_CUBE"}
    np.testing.assert_array_equal(accessor_array(doc, blob, prim["attributes"]["POSITION"], "<f4", 3),
                                  cloud.centers)
    # glTF's COLOR_0 is linear (16 bits, so each sRGB byte stays distinct); the cloud's are sRGB bytes
    from fishgen.numeric import linear_to_srgb
    rgb = accessor_array(doc, blob, prim["attributes"]["COLOR_0"], "<u2", 3)
    assert doc["accessors"][prim["attributes"]["COLOR_0"]]["normalized"] is True
    np.testing.assert_array_equal(np.round(linear_to_srgb(rgb / 65535.0) * 255), cloud.colors)
    np.testing.assert_array_equal(accessor_array(doc, blob, prim["attributes"]["_CUBE"], "<f4", 1)[:, 0],
                                  cloud.cube_index)
    np.testing.assert_array_equal(accessor_array(doc, blob, prim["attributes"]["_RADIUS"], "<f4", 1)[:, 0],
                                  cloud.radii)
    np.testing.assert_array_equal(accessor_array(doc, blob, prim["attributes"]["_DENSITY"], "<f4", 1)[:, 0],
                                  cloud.density)
    pygltflib = pytest.importorskip("pygltflib")
    gltf = pygltflib.GLTF2().load(str(path))
    assert gltf.accessors[gltf.meshes[0].primitives[0].attributes.POSITION].count == len(cloud)
    scene = trimesh.load(path)
    (geometry,) = scene.geometry.values()
    assert isinstance(geometry, trimesh.PointCloud) and len(geometry.vertices) == len(cloud)


def test_glb_billboards(cloud, tmp_path, gltf_validator):
    path = tmp_path / "billboards.glb"
    export_cloud(cloud, path, billboards=True)
    gltf_validator(path)
    doc, blob = glb_parts(path)
    material = doc["materials"][0]
    assert material["alphaMode"] == "BLEND" and "KHR_materials_unlit" in doc["extensionsUsed"]
    prim = doc["meshes"][0]["primitives"][0]
    # three crossed quads per particle, each a square of half width = radius around its centre
    quads = accessor_array(doc, blob, prim["attributes"]["POSITION"], "<f4", 3).reshape(-1, 3, 4, 3)
    assert len(quads) == len(cloud)
    np.testing.assert_allclose(quads.mean(axis=2), np.repeat(cloud.centers[:, None], 3, axis=1), atol=1e-5)
    right, up = quads[:, :, 1] - quads[:, :, 0], quads[:, :, 3] - quads[:, :, 0]
    r2 = np.repeat(cloud.radii[:, None], 3, axis=1)
    np.testing.assert_allclose(np.linalg.norm(right, axis=-1), 2 * r2, rtol=1e-4)
    np.testing.assert_allclose(np.linalg.norm(up, axis=-1), 2 * r2, rtol=1e-4)
    normals = np.cross(right, up)
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    gram = np.einsum("nqd,npd->nqp", normals, normals)  # the three quads are mutually perpendicular
    np.testing.assert_allclose(gram, np.broadcast_to(np.eye(3), gram.shape), atol=1e-4)
    image = doc["images"][0]
    view = doc["bufferViews"][image["bufferView"]]
    sprite = Image.open(io.BytesIO(blob[view["byteOffset"]:view["byteOffset"] + view["byteLength"]]))
    alpha = np.asarray(sprite.convert("RGBA"))[..., 3]
    assert alpha[sprite.height // 2, sprite.width // 2] > 240 and alpha[0, 0] == 0
    mesh = trimesh.load(path, force="mesh")
    assert len(mesh.faces) == TRIANGLES_PER_BILLBOARD * len(cloud) == 6 * len(cloud)


def test_billboards_are_turned_alike_whatever_the_cloud(tmp_path):
    """Particle k's quads are turned by the k-th rotation of a fixed sequence: no seed, no
    randomness, and no view direction sees every particle's quads edge-on."""
    rot = turns(4000).astype(np.float64)
    np.testing.assert_allclose(np.einsum("nij,nkj->nik", rot, rot), np.broadcast_to(np.eye(3), rot.shape),
                               atol=1e-5)
    np.testing.assert_array_equal(turns(10), turns(4000)[:10])
    normals = np.einsum("qd,nde->nqe", np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0]], float), rot)
    for view in ([0, 0, 1], [1, 0, 0], [0, 1, 0], [1, 1, 1]):
        edge_on = np.abs(normals @ (np.array(view) / np.linalg.norm(view))) < 0.05   # within 3 degrees
        assert edge_on.mean() < 0.06, view


@pytest.mark.parametrize("billboards", [False, True])
def test_gltf_with_bin(cloud, tmp_path, gltf_validator, billboards):
    path = tmp_path / "cloud.gltf"
    export_cloud(cloud, path, billboards=billboards)
    gltf_validator(path)
    doc = json.loads(path.read_text())
    assert doc["buffers"][0]["uri"] == "cloud.bin"
    assert (tmp_path / "cloud.bin").stat().st_size == doc["buffers"][0]["byteLength"]


@pytest.mark.parametrize("stem,uri", [("a%20b", "a%2520b.bin"), ("x#y", "x%23y.bin"),
                                      ("sky cloud?v=1", "sky%20cloud%3Fv%3D1.bin"),
                                      ("wolke ü", "wolke%20%C3%BC.bin")])
def test_gltf_bin_uri_is_percent_encoded(cloud, tmp_path, gltf_validator, stem, uri):
    # Unencoded, "a%20b.bin" made loaders look for "a b.bin" (IO_ERROR) and "x#y.bin"
    # was read as "x" plus a fragment (NON_RELATIVE_URI warnings).
    path = tmp_path / f"{stem}.gltf"
    export_cloud(cloud, path)
    assert json.loads(path.read_text())["buffers"][0]["uri"] == uri
    assert (tmp_path / f"{stem}.bin").is_file()
    gltf_validator(path)


def test_csv_round_trip(cloud, tmp_path):
    path = tmp_path / "cloud.csv"
    export_cloud(cloud, path)
    rows = list(csv.DictReader(path.open()))
    assert list(rows[0]) == ["x", "y", "z", "radius", "density", "red", "green", "blue", "cube"]
    assert len(rows) == len(cloud)
    got = np.array([[float(r[k]) for k in ("x", "y", "z")] for r in rows], np.float32)
    np.testing.assert_array_equal(got, cloud.centers)  # %.9g round-trips float32 exactly
    np.testing.assert_array_equal(np.array([float(r["radius"]) for r in rows], np.float32), cloud.radii)
    assert [int(r["cube"]) for r in rows] == cloud.cube_index.tolist()


def _printf_rows(rec) -> bytes:
    """The reference: ``%.9g`` / ``%d`` per field, as np.savetxt wrote the CSV before."""
    fmt = ",".join("%.9g" if rec.dtype[n].kind == "f" else "%d" for n in rec.dtype.names)
    return b"".join((fmt % tuple(row.tolist()) + "\n").encode() for row in rec)


def test_csv_text_matches_printf_for_every_kind_of_float32():
    from fishgen.exchange.csv_text import format_csv_rows
    PARTICLE_WITH_CUBE = np.dtype([(n, "<f4") for n in ("x", "y", "z", "radius", "density")]
                                  + [(n, "u1") for n in ("red", "green", "blue")] + [("cube", "<i4")])
    rng = np.random.default_rng(5)
    n = 50_000
    rec = np.zeros(n, PARTICLE_WITH_CUBE)
    # Random bit patterns cover every exponent (subnormals to 3.4e38) and both notations.
    floats = rng.integers(0, 2**32, (n, 5), dtype=np.uint64).astype(np.uint32).view(np.float32)
    floats[~np.isfinite(floats)] = 1.5
    tricky = np.array([0, -0.0, 1, -1, 0.5, 1234567.125, 1e9, 999999999, 99999999.5, 1e-4,
                       9.9999999e-5, 1e-5, 123456789, 1.23456789e9, 3.4028235e38, 1.4e-45,
                       -1.17549435e-38, 100, 0.1, 16777216, 1e8, 0.001, 2.5e-4], np.float32)
    floats[:len(tricky)] = tricky[:, None]
    floats[n // 2:, :3] = (rng.random((n - n // 2, 3)) * 200 - 100).astype(np.float32)
    for k, name in enumerate(("x", "y", "z", "radius", "density")):
        rec[name] = floats[:, k]
    for name in ("red", "green", "blue"):
        rec[name] = rng.integers(0, 256, n)
    rec["cube"] = rng.integers(-2**31, 2**31 - 1, n)
    rec["cube"][:3] = [0, -2**31, 2**31 - 1]
    assert format_csv_rows(rec) == _printf_rows(rec)
    odd = rec[:4].copy()
    odd["x"] = [np.nan, np.inf, -np.inf, 2]   # never produced by the fill; still printf's text
    assert format_csv_rows(odd) == _printf_rows(odd)


def _records(cloud):
    (prim,) = cloud_scene(cloud).meshes[0].primitives
    return next(particles.particle_chunks(prim, particles.particle_columns(prim))).copy()


def test_csv_is_not_formatted_row_by_row(cloud, tmp_path, monkeypatch):
    # np.savetxt formats each row in Python: 1M particles took 6.9-7.7 s (PLY: 0.07 s).
    expected = tmp_path / "expected.csv"
    expected.write_bytes(b"x,y,z,radius,density,red,green,blue,cube\n"
                         + _printf_rows(_records(cloud)))
    def refuse(*args, **kwargs):
        raise AssertionError("per-row formatting")
    monkeypatch.setattr(np, "savetxt", refuse)
    export_cloud(cloud, tmp_path / "cloud.csv")
    assert (tmp_path / "cloud.csv").read_bytes() == expected.read_bytes()


def test_npy_round_trip(cloud, tmp_path):
    path = tmp_path / "cloud.npy"
    export_cloud(cloud, path)
    data = np.load(path)
    assert data.shape == (len(cloud),)
    np.testing.assert_array_equal(np.stack([data["x"], data["y"], data["z"]], 1), cloud.centers)
    np.testing.assert_array_equal(data["density"], cloud.density)
    np.testing.assert_array_equal(np.stack([data["red"], data["green"], data["blue"]], 1), cloud.colors)
    np.testing.assert_array_equal(data["cube"], cloud.cube_index)


@pytest.mark.parametrize("name", ["a.ply", "a.glb", "a.gltf", "a.csv", "a.npy"])
def test_same_seed_byte_identical_files(tmp_path, name):
    cubes = load_cubes(TABLES["4.3"])
    for run, seed in (("1", 8), ("2", 8), ("3", 9)):
        export_cloud(fill_cloud(cubes, seed=seed), tmp_path / run / name)
    one, two, other = ((tmp_path / run / name).read_bytes() for run in "123")
    assert one == two and one != other


def test_failed_export_leaves_no_file_and_keeps_the_old_one(cloud, tmp_path, monkeypatch):
    old = tmp_path / "keep.ply"
    old.write_bytes(b"previous good output")

    def broken(*args, **kwargs):
        yield from ()
        raise OSError("disk full")

    monkeypatch.setattr("fishgen.exchange.ply.particle_chunks", broken)
    for target in (old, tmp_path / "new.ply"):
        with pytest.raises(SystemFailure, match=f"cannot write {target}: disk full"):  # the path named
            export_cloud(cloud, target)
    assert old.read_bytes() == b"previous good output"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.ply"]


@pytest.mark.parametrize("name,billboards", [("a.ply", False), ("a.npy", False), ("a.csv", False),
                                             ("a.glb", False), ("b.glb", True)])
def test_streaming_in_small_blocks_gives_the_same_bytes(cloud, tmp_path, monkeypatch, name, billboards):
    whole = tmp_path / "whole" / name
    export_cloud(cloud, whole, billboards=billboards)
    monkeypatch.setattr(particles, "ROWS", 64)   # 615 particles -> 10 blocks
    monkeypatch.setattr("fishgen.exchange.table.CSV_ROWS", 10)  # CSV: 7 pieces per block
    blocks = tmp_path / "blocks" / name
    export_cloud(cloud, blocks, billboards=billboards)
    assert whole.read_bytes() == blocks.read_bytes()


def test_unknown_extension_and_billboards_outside_gltf(cloud, tmp_path):
    with pytest.raises(FishgenError, match=r"expected a format that holds points, found .obj .*"
                                           r"use .glb or .gltf or .ply or .csv or .npy"):
        export_cloud(cloud, tmp_path / "cloud.obj")
    with pytest.raises(FishgenError, match="with --billboards"):
        export_cloud(cloud, tmp_path / "cloud.ply", billboards=True)
    assert list(tmp_path.iterdir()) == []
