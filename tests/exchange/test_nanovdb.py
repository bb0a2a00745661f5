"""NanoVDB (.nvdb): tinyvdb, an independent reader (its own C, with PNanoVDB.h's accessor), reads
what `fishgen clouds -o cloud.nvdb` writes back voxel for voxel."""
from __future__ import annotations

import struct

import numpy as np
import pytest
import tinyvdb._tinyvdb_nanovdb as nanovdb

from fishgen.clouds import export_cloud
from fishgen.clouds.model import DEFAULT_VOXEL_SIZE
from fishgen.exchange.nanovdb import GRID, LEAF_NODE, LOWER_NODE, META, ROOT, TILE, TREE, UPPER_NODE

from .volume_clouds import active_voxels, table_cloud, table_volume


def one_grid_file(data: bytes, k: int) -> bytes:
    """Grid ``k`` of a NanoVDB segment of several as a file of its own: tinyvdb 0.9.0 points every
    grid of a segment at the first one's buffer (it does not step past a grid it has read)."""
    count = struct.unpack_from("<H", data, 12)[0]
    metas, at = [], 16
    for _ in range(count):
        name_size = struct.unpack_from("<I", data, at + 136)[0]
        metas.append(data[at:at + META.itemsize + name_size])
        at += META.itemsize + name_size
    sizes = [struct.unpack_from("<Q", m, 0)[0] for m in metas]
    start = at + sum(sizes[:k])
    return data[:12] + struct.pack("<H", 1) + data[14:16] + metas[k] + data[start:start + sizes[k]]


def test_node_layouts_are_nanovdbs():
    # PNanoVDB.h: PNANOVDB_GRID_SIZE 672, TREE 64, the float root 64 and its tiles 32, the float
    # upper/lower/leaf sizes 270400/33856/2144 with their tables at 8256/1088 and values at 96
    assert (GRID.itemsize, TREE.itemsize, ROOT.itemsize, TILE.itemsize) == (672, 64, 64, 32)
    assert (UPPER_NODE.itemsize, LOWER_NODE.itemsize, LEAF_NODE.itemsize, META.itemsize) == (
        270400, 33856, 2144, 176)
    assert (UPPER_NODE.fields["table"][1], LOWER_NODE.fields["table"][1], LEAF_NODE.fields["values"][1],
            GRID.fields["matf"][1], GRID.fields["voxel_size"][1]) == (
        8256, 1088, 96, 296, 608)


def test_tinyvdb_reads_both_grids_back_voxel_for_voxel(tmp_path):
    path = tmp_path / "cloud.nvdb"
    assert export_cloud(table_cloud(), path) == [path]
    volume = table_volume(DEFAULT_VOXEL_SIZE)
    coords, values = active_voxels(volume)
    data = path.read_bytes()
    f = nanovdb.NanoVDBFile(str(path))
    assert f.grid_count() == 2 and [f.grid_name(k) for k in (0, 1)] == ["density", "light"]
    for k, name in enumerate(("density", "light")):
        assert (f.grid_type(k), f.grid_class(k)) == ("Float", "FogVolume")
        assert f.voxel_size(k) == DEFAULT_VOXEL_SIZE and f.active_voxel_count(k) == len(coords)
        first = coords.min(0) + volume.origins.min(0)          # back in the world's index space
        assert f.world_bbox(k)[0] == pytest.approx(volume.voxel_size * first)
        assert f.bbox(k) == (tuple(coords.min(0).astype(float)), tuple(coords.max(0).astype(float)))
        alone = tmp_path / f"{name}.nvdb"
        alone.write_bytes(one_grid_file(data, k))
        grid = nanovdb.NanoVDBFile(str(alone))
        assert grid.grid_name(0) == name
        got = np.array([grid.get(0, *map(int, c)) for c in coords], np.float32)
        np.testing.assert_array_equal(got, values[name])
        assert (got > 0).all() if name == "density" else (got >= 0).all() and got.max() <= 1.0001
        # voxels no particle reaches read as the background, 0: around the box, and inside a leaf
        lo, hi = coords.min(0), coords.max(0)
        outside = [lo - 1, hi + 1, (lo + hi) // 2 + (hi - lo) * 10]
        inside = np.argwhere(~volume.active[0])[:20] + volume.origins[0] - volume.origins.min(axis=0)
        assert all(grid.get(0, *map(int, c)) == 0.0 for c in [*outside, *inside])



def test_node_statistics_are_those_of_the_active_voxels_below():
    from fishgen.exchange.volumes import leaf_stats, stats

    rng = np.random.default_rng(0)
    values = rng.random((50, 512)).astype(np.float32) * 10
    active = rng.random((50, 512)) < 0.3
    groups = rng.integers(0, 5, 50)
    got = stats(leaf_stats(values, active), groups, 5)
    for k in range(5):
        mine = values[groups == k][active[groups == k]].astype(np.float64)
        np.testing.assert_allclose(got[k], [mine.min(), mine.max(), mine.mean(), mine.std()], rtol=1e-6)
