"""Packed per-particle records shared by the PLY, NPY and CSV writers."""
from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from fishgen.clouds.model import Cloud

ROWS = 1 << 18
"""Rows packed per write: keeps the packing buffer ~7 MB whatever the cloud size."""

FIELDS = [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("radius", "<f4"), ("density", "<f4"),
          ("red", "u1"), ("green", "u1"), ("blue", "u1")]
PARTICLE = np.dtype(FIELDS)                       # the PLY vertex, 23 bytes
PARTICLE_WITH_CUBE = np.dtype(FIELDS + [("cube", "<i4")])  # NPY/CSV keep the source cube


def field_names(dtype: np.dtype) -> tuple[str, ...]:
    """The field names of a structured dtype such as ``PARTICLE`` (numpy types them optional)."""
    if dtype.names is None:
        raise TypeError(f"expected a structured dtype, found {dtype}")
    return dtype.names


def record_chunks(cloud: Cloud, dtype: np.dtype = PARTICLE) -> Iterator[np.ndarray]:
    """Yield the cloud as packed structured arrays of at most ``ROWS`` rows."""
    buffer = np.empty(min(ROWS, len(cloud)), dtype)
    for start in range(0, len(cloud), ROWS):
        stop = min(start + ROWS, len(cloud))
        rec = buffer[: stop - start]
        for axis, name in enumerate("xyz"):
            rec[name] = cloud.centers[start:stop, axis]
        rec["radius"] = cloud.radii[start:stop]
        rec["density"] = cloud.density[start:stop]
        for channel, name in enumerate(("red", "green", "blue")):
            rec[name] = cloud.colors[start:stop, channel]
        if "cube" in field_names(dtype):
            rec["cube"] = cloud.cube_index[start:stop]
        yield rec
