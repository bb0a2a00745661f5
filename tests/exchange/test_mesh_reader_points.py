"""A PLY of vertices alone is a point set: its columns come through as fishgen's clouds carry them."""
from __future__ import annotations

import numpy as np

from fishgen.clouds import export_cloud, fill_cloud, light_cloud, load_cubes
from fishgen.exchange.mesh_reader import read_mesh_file
from fishgen.numeric import srgb8_to_linear16
from tests.conftest import PARAMS


def test_a_clouds_ply_reads_back_as_it_was_written(tmp_path):
    cloud = light_cloud(fill_cloud(load_cubes(PARAMS / "clouds" / "table_4_3.awn"), seed=0))
    export_cloud(cloud, tmp_path / "cloud.ply")
    scene = read_mesh_file(tmp_path / "cloud.ply")
    assert [n.name for n in scene.nodes] == ["cloud0"]
    (prim,) = scene.meshes[0].primitives
    assert prim.mode == "POINTS"
    a = prim.attributes
    np.testing.assert_array_equal(a["POSITION"], cloud.centers)
    np.testing.assert_array_equal(a["_RADIUS"], cloud.radii)
    np.testing.assert_array_equal(a["_DENSITY"], cloud.density)
    # sRGB bytes to 16-bit linear light, exactly as the cloud's own scene holds its colours
    np.testing.assert_array_equal(a["COLOR_0"], srgb8_to_linear16()[cloud.colors])


def test_colour_bytes_of_at_most_one_are_bytes_not_fractions(tmp_path):
    """A dark cloud's bytes (all 0 or 1) were taken as floats of 0 to 1: 1 became white."""
    path = tmp_path / "dark.ply"
    rows = np.zeros(3, [("x", "<f4"), ("y", "<f4"), ("z", "<f4"),
                        ("red", "u1"), ("green", "u1"), ("blue", "u1")])
    rows["x"] = [0, 1, 2]
    rows["red"] = rows["green"] = rows["blue"] = [0, 1, 1]
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
              "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n")
    path.write_bytes(header.encode("ascii") + rows.tobytes())
    colour = read_mesh_file(path).meshes[0].primitives[0].attributes["COLOR_0"]
    assert colour.dtype == np.uint16
    np.testing.assert_array_equal(colour[:, 0], srgb8_to_linear16()[[0, 1, 1]])
    assert colour.max() < 100                      # sRGB 1 of 255 is nearly black in linear light


def test_colours_of_16_bits_span_their_range(tmp_path):
    """ushort 65535 was divided by 255 and came out 534,881 times full light (review, 2026-12-05)."""
    path = tmp_path / "wide.ply"
    rows = np.zeros(2, [("x", "<f4"), ("y", "<f4"), ("z", "<f4"),
                        ("red", "<u2"), ("green", "<u2"), ("blue", "<u2")])
    rows["red"] = [65535, 0]
    rows["green"] = [32768, 0]
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
              "property float z\nproperty ushort red\nproperty ushort green\nproperty ushort blue\n"
              "end_header\n")
    path.write_bytes(header.encode("ascii") + rows.tobytes())
    colour = read_mesh_file(path).meshes[0].primitives[0].attributes["COLOR_0"]
    np.testing.assert_allclose(colour[0, :3], [1.0, 0.2140, 0.0], atol=1e-3)   # sRGB 0.5: linear 0.214
    np.testing.assert_array_equal(colour[1, :3], 0)
