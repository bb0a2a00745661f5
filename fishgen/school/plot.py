"""The measures over time beside a top-down view of the tracks (matplotlib, an optional extra)."""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from fishgen.atomic import write_bytes
from fishgen.errors import FishgenError


def plot_school(path: Path, run, per_frame: dict) -> Path:
    try:
        import matplotlib
    except ModuleNotFoundError:
        raise FishgenError("expected matplotlib for --plot (pip install 'fishgen[plot]'), found it missing",
                           path) from None
    matplotlib.use("Agg")
    from matplotlib import pyplot as plt

    times = np.asarray(run.tracks.times)
    series = [(k, v) for k, v in per_frame.items()
              if isinstance(v, np.ndarray) and v.shape[:1] == times.shape]
    fig = plt.figure(figsize=(12, 6), dpi=100)
    grid = fig.add_gridspec(max(1, len(series)), 2, width_ratios=(1.3, 1))
    for row, (name, values) in enumerate(series):
        ax = fig.add_subplot(grid[row, 0])
        ax.plot(times, values.reshape(len(times), -1), lw=1)
        ax.set_ylabel(name.replace("_", " "), fontsize=8)
        ax.tick_params(labelsize=7)
        if row < len(series) - 1:
            ax.set_xticklabels([])
    fig.axes[-1].set_xlabel("seconds") if series else None
    top = fig.add_subplot(grid[:, 1])
    positions = run.tracks.positions
    for g, name in enumerate(run.species_names):
        members = np.flatnonzero(np.asarray(run.tracks.group) == g)[:200]
        for i in members:
            top.plot(positions[:, i, 0], positions[:, i, 2], lw=0.4, alpha=0.5, color=f"C{g}")
        top.plot([], [], color=f"C{g}", label=name)
    if run.tracks.predator is not None:
        top.plot(run.tracks.predator[:, 0], run.tracks.predator[:, 2], "k--", lw=1, label="predator")
    if run.tracks.target is not None:
        top.plot(run.tracks.target[:, 0], run.tracks.target[:, 2], "r:", lw=1, label="target")
    top.set_aspect("equal")
    top.set_title("top view (x, z), metres", fontsize=9)
    top.legend(fontsize=7, loc="upper right")
    buf = io.BytesIO()
    fig.tight_layout()
    fig.savefig(buf, format="png", metadata={"Software": None})
    plt.close(fig)
    write_bytes(path, buf.getvalue())
    return path
