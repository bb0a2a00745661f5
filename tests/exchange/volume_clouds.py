"""What the volume writers' tests share: Table 4.4 lit as `fishgen clouds` lights it, its volume,
and that volume's active voxels as flat arrays."""
from __future__ import annotations

import functools

import numpy as np

from fishgen.clouds import Lighting, fill_cloud, light_cloud, load_cubes
from fishgen.clouds.model import Cloud
from fishgen.clouds.volume import Volume, particle_volume
from tests.conftest import PARAMS

TABLE_4_4 = PARAMS / "clouds" / "table_4_4.awn"


@functools.cache
def table_cloud() -> Cloud:
    return light_cloud(fill_cloud(load_cubes(TABLE_4_4), seed=0))


@functools.cache
def table_volume(voxel_size: float) -> Volume:
    cloud = table_cloud()
    return particle_volume(cloud.centers, cloud.radii, cloud.density, cloud.light, Lighting().extinction,
                           voxel_size)


def active_voxels(volume: Volume) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """(N, 3) int coordinates of the active voxels in the files' index space (the volume's first
    leaf at 0), sorted x, y, z, and each grid's values there."""
    leaf, x, y, z = np.nonzero(volume.active)
    first = volume.origins.min(axis=0).astype(np.int64)
    coords = volume.origins[leaf].astype(np.int64) - first + np.stack([x, y, z], axis=1)
    order = np.lexsort(coords.T[::-1])
    return coords[order], {name: values[leaf, x, y, z][order] for name, values in volume.grids}
