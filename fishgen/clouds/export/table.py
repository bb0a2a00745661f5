"""Data-pipeline formats: NPY (one structured array) and CSV (one row per particle)."""
from __future__ import annotations

import io
import os

import numpy as np

from fishgen.atomic import atomic_open
from fishgen.clouds.export.records import PARTICLE_WITH_CUBE, record_chunks
from fishgen.clouds.model import Cloud


def write_npy(cloud: Cloud, path: str | os.PathLike) -> None:
    """A 1-D structured array (x y z radius density red green blue cube), streamed."""
    header = {"descr": np.lib.format.dtype_to_descr(PARTICLE_WITH_CUBE),
              "fortran_order": False, "shape": (len(cloud),)}
    with atomic_open(path) as handle:
        np.lib.format.write_array_header_1_0(handle, header)
        for rec in record_chunks(cloud, PARTICLE_WITH_CUBE):
            handle.write(memoryview(rec).cast("B"))


def write_csv(cloud: Cloud, path: str | os.PathLike) -> None:
    """Header row, then floats as %.9g (round-trips float32 exactly) and integers."""
    names = PARTICLE_WITH_CUBE.names
    fmt = ",".join("%.9g" if PARTICLE_WITH_CUBE[n].kind == "f" else "%d" for n in names)
    with atomic_open(path) as handle:
        handle.write((",".join(names) + "\n").encode("ascii"))
        for rec in record_chunks(cloud, PARTICLE_WITH_CUBE):
            text = io.StringIO()
            np.savetxt(text, rec, fmt=fmt)  # structured rows, one per line
            handle.write(text.getvalue().encode("ascii"))
