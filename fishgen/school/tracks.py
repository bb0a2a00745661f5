"""Raw tracks for engines that animate their own way: CSV or NPZ, one row per frame and fish."""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from fishgen.atomic import atomic_open, write_bytes
from fishgen.errors import FishgenError
from fishgen.exchange.csv_text import format_csv_rows
from fishgen.school.model import Tracks

COLUMNS = ("frame", "time", "fish", "species", "x", "y", "z", "qx", "qy", "qz", "qw", "vx", "vy", "vz")
TRACK_FORMATS = (".csv", ".npz")


def track_table(tracks: Tracks) -> np.ndarray:
    """(F x N, 14) float64 rows in COLUMNS order, frame-major."""
    frames, count = tracks.positions.shape[:2]
    out = np.empty((frames, count, len(COLUMNS)))
    out[..., 0] = np.arange(frames)[:, None]
    out[..., 1] = np.asarray(tracks.times)[:, None]
    out[..., 2] = np.arange(count)[None, :]
    out[..., 3] = np.asarray(tracks.group)[None, :]
    out[..., 4:7] = tracks.positions
    out[..., 7:11] = tracks.headings
    out[..., 11:14] = tracks.velocities
    return out.reshape(-1, len(COLUMNS))


def write_tracks(tracks: Tracks, path: str | Path, species_names: list[str]) -> Path:
    """Write ``.csv`` (header, then %.6g floats) or ``.npz`` (one array per column + species names)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in TRACK_FORMATS:
        raise FishgenError(f"expected --tracks ending in {' or '.join(TRACK_FORMATS)}, found "
                           f"{suffix or 'no extension'!r}", path)
    table = track_table(tracks)
    layout = [(name, "<i4" if k in (0, 2, 3) else "<f4") for k, name in enumerate(COLUMNS)]
    records = np.empty(len(table), layout)
    for k, name in enumerate(COLUMNS):
        records[name] = table[:, k]
    if suffix == ".npz":
        buf = io.BytesIO()
        arrays: dict[str, np.ndarray] = {name: records[name] for name in COLUMNS}
        arrays["species_names"] = np.array(species_names)
        np.savez_compressed(buf, **arrays)  # type: ignore[arg-type]  # numpy's stub types the first kwarg
        write_bytes(path, buf.getvalue())
        return path
    with atomic_open(path) as handle:  # the clouds' array-at-a-time CSV formatter (%.9g, %d)
        handle.write((",".join(COLUMNS) + "\n").encode("ascii"))
        for start in range(0, len(records), 1 << 14):
            handle.write(format_csv_rows(records[start:start + (1 << 14)]))
    return path
