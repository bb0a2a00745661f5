"""OpenVDB (.vdb): tinyvdb reads what `fishgen clouds -o cloud.vdb` writes back voxel for voxel, and
Blender 5 (its bundled OpenVDB) imports it and renders a volume whose silhouette is the particle
cloud's. The Blender test needs a Python with PyPI's `bpy` ($FISHGEN_BPY_PYTHON or
/tmp/bpyvenv/bin/python) and is skipped without one."""
from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest
import tinyvdb

from fishgen.clouds import Lighting, export_cloud, fill_cloud, light_cloud, load_cubes, merge_clouds
from fishgen.clouds.light import CUT, peak_optical_depth
from fishgen.clouds.sprite import SIGMA
from fishgen.clouds.volume import particle_volume, reach
from fishgen.exchange.volumes import shifted, tree

from .volume_clouds import TABLE_4_4, active_voxels, table_cloud

BPY = next((p for p in (os.environ.get("FISHGEN_BPY_PYTHON"), "/tmp/bpyvenv/bin/python")
            if p and Path(p).is_file()), None)
SCRIPT = Path(__file__).with_name("blender_volume.py")
TINYVDB_CHILDREN = 64
"""tinyvdb 0.9.0 keeps at most 64 children of an internal node (it reads back 64 of 100 leaves
of one 16^3 node from a file it wrote itself); the voxel-exact test uses a cloud within that."""


@pytest.mark.parametrize("apart,uppers,lowers", [(None, 1, 1), (100.0, 1, 2), (3000.0, 2, 2)])
def test_tinyvdb_reads_both_grids_back_voxel_for_voxel(tmp_path, apart, uppers, lowers):
    # Table 4.4 alone, or twice: 100 apart (two 16^3 internal nodes), 3000 apart (two 32^3 ones)
    size = 0.6
    cubes = load_cubes(TABLE_4_4)
    cloud = table_cloud() if apart is None else light_cloud(merge_clouds(
        [fill_cloud(cubes, seed=0), fill_cloud(cubes, seed=1, offset=(apart, 0.0, 30.0))]))
    volume = particle_volume(cloud.centers, cloud.radii, cloud.density, cloud.light, Lighting().extinction,
                             size)
    t = tree(shifted(volume)[0].origins, lambda uppers: np.lexsort(uppers.T[::-1]).argsort())
    assert np.bincount(t.leaf_parent).max() <= TINYVDB_CHILDREN
    assert (len(t.uppers), len(t.lowers)) == (uppers, lowers)
    path = tmp_path / "cloud.vdb"
    export_cloud(cloud, path, voxel_size=size)
    f = tinyvdb.open(str(path))
    assert f.header["file_version"] == 224 and f.header["compression_flags"] == 0
    f.read_grids()
    coords, values = active_voxels(volume)
    assert f.grid_count == 2
    for k, name in enumerate(("density", "light")):
        grid = f.grid(k)
        assert (grid.name, grid.type_name, grid.float_background()) == (name, "Tree_float_5_4_3", 0.0)
        assert grid.metadata == {"class": "fog volume", "name": name}
        assert grid.transform["type"] == "uniform_scale_translate"
        assert grid.transform["voxel_size"] == (size,) * 3
        # index space starts at the first leaf; the translation puts it back
        assert grid.transform["translation"] == pytest.approx(tuple(volume.origins.min(0) * size))
        sparse = grid.to_sparse()
        got = np.frombuffer(sparse["coords"], np.int32).reshape(-1, 3).astype(np.int64)
        order = np.lexsort(got.T[::-1])
        np.testing.assert_array_equal(got[order], coords)
        np.testing.assert_array_equal(np.frombuffer(sparse["values"], np.float32)[order], values[name])


def test_the_written_offsets_lead_where_the_grids_are(tmp_path):
    # the descriptor's three stream offsets: the grid, its leaf buffers, its end (the next grid)
    import struct

    path = tmp_path / "cloud.vdb"
    export_cloud(table_cloud(), path)
    data = path.read_bytes()
    at = 8 + 4 * 3 + 1 + 36 + 4 + 4      # header, file metadata (none), grid count
    ends = []
    for name in ("density", "light"):
        for expect in (name, "Tree_float_5_4_3", ""):
            n = struct.unpack_from("<I", data, at)[0]
            assert data[at + 4:at + 4 + n].decode() == expect
            at += 4 + n
        grid, leaves, end = struct.unpack_from("<qqq", data, at)
        assert grid == at + 24 and struct.unpack_from("<I", data, grid)[0] == 0   # compression: none
        assert data[leaves + 64] == 6    # a leaf's mask, then "all values follow"
        ends.append(end)
        at = end
    assert ends[-1] == len(data)


def particle_opacity(cx: float, cy: float, width: float, px: int, py: int) -> np.ndarray:
    """1 - e^-tau of the particle cloud seen from the front through the camera of blender_volume.py:
    tau the sum of each particle's Gaussian column (the lighting's: width SIGMA x radius, cut at
    CUT sigma, peak its optical depth)."""
    cloud = table_cloud()
    height = width * py / px
    x = cx - width / 2 + (np.arange(px) + 0.5) * width / px
    y = cy + height / 2 - (np.arange(py) + 0.5) * height / py
    gx, gy = np.meshgrid(x, y)
    sigma = cloud.radii.astype(np.float64) * SIGMA
    peak = peak_optical_depth(cloud.density, Lighting().extinction)
    d2 = ((gx[..., None] - cloud.centers[:, 0]) ** 2 + (gy[..., None] - cloud.centers[:, 1]) ** 2)
    tau = np.where(d2 <= (CUT * sigma) ** 2, peak * np.exp(-d2 / (2 * sigma ** 2)), 0.0).sum(-1)
    return 1 - np.exp(-tau)


@pytest.mark.skipif(BPY is None, reason="no Python with bpy ($FISHGEN_BPY_PYTHON)")
def test_blender_imports_the_vdb_and_renders_the_clouds_silhouette(tmp_path):
    path = tmp_path / "cloud.vdb"
    export_cloud(table_cloud(), path)
    cloud = table_cloud()
    far = reach(cloud.radii)[:, None]
    lo, hi = (cloud.centers - far).min(0), (cloud.centers + far).max(0)
    cx, cy = (lo[:2] + hi[:2]) / 2
    width, px, py = float(max(hi[0] - lo[0], (hi[1] - lo[1]) * 4 / 3)) * 1.1, 128, 96
    alpha = tmp_path / "opacity.npy"
    run = subprocess.run([BPY, str(SCRIPT), str(path), str(alpha), str(cx), str(cy), str(width), str(px),
                          str(py)], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    report = json.loads(next(line for line in run.stdout.splitlines() if line.startswith("{")))
    assert report["objects"] == 1 and sorted(report["grids"]) == ["density", "light"]
    assert all(g["type"] == "FLOAT" for g in report["grids"].values())
    # Blender's bounds are its leaves': around the particles' reach, within a leaf of voxels
    leaf = 8 * 0.2
    assert np.all(np.asarray(report["min"]) <= lo + 1e-4) and np.all(np.asarray(report["min"]) >= lo - leaf)
    assert np.all(np.asarray(report["max"]) >= hi - 0.2) and np.all(np.asarray(report["max"]) <= hi + leaf)
    rendered = np.load(alpha) >= 0.1
    particles = particle_opacity(cx, cy, width, px, py) >= 0.1
    iou = (rendered & particles).sum() / (rendered | particles).sum()
    assert 0.3 < particles.mean() < 0.8      # the cloud fills the frame, with sky around it
    assert iou >= 0.8, iou
