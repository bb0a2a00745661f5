"""The measures over time beside a top-down view of the tracks (matplotlib, an optional extra).

One panel per measure, titled inside its own axes so that no label meets another; the warm-up is
shaded. A measure whose values stay within rounding of one value (no overlaps, one group, a
heading that is its velocity to 1e-16 rad) is drawn as that constant and says so, not as
magnified noise. The top view draws the target's and the predator's whole closed path (dashed)
and the part they swam during the run (solid).
"""
from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np

from fishgen.atomic import write_bytes
from fishgen.errors import FishgenError
from fishgen.school.model import TargetPath
from fishgen.school.paths import path_positions

# (measures drawn together, title, scale, digits a value is shown to)
PANELS = (
    (("polarization",), "polarization (1 = parallel)", 1.0, 2),
    (("rotation",), "rotation order parameter (1 = milling)", 1.0, 2),
    (("nearest_neighbour",), "nearest neighbour, body lengths", 1.0, 2),
    (("groups",), "separate groups per species", 1.0, 0),
    (("mixed_groups",), "groups mixing species", 1.0, 0),
    (("overlaps",), "overlapping pairs", 1.0, 0),
    (("heading_angle", "heading_angle_max"), "heading vs velocity, degrees (mean, largest)",
     float(np.degrees(1.0)), 1),
    (("turn",), "largest turn per frame, degrees", float(np.degrees(1.0)), 1),
    (("target_distance",), "distance to target, body lengths", 1.0, 2),
    (("predator_distance",), "distance to predator, body lengths", 1.0, 2),
)
PANEL_INCHES = 0.95
TRACKS_DRAWN = 200      # per species: enough to see the school's paths without a solid smear


def plot_school(path: Path, run, per_frame: dict) -> Path:
    try:
        import matplotlib
    except ModuleNotFoundError:
        raise FishgenError("expected matplotlib for --plot (pip install 'fishgen[plot]'), found it missing",
                           path) from None
    matplotlib.use("Agg")
    from matplotlib import pyplot as plt

    times = np.asarray(run.tracks.times)
    names = list(run.species_names)
    warm = times[min(getattr(run, "warmup_frames", 0), len(times) - 1)] if len(times) else 0.0
    panels = [(keys, title, scale, digits) for keys, title, scale, digits in PANELS
              if any(isinstance(per_frame.get(k), np.ndarray) and per_frame[k].shape[:1] == times.shape
                     for k in keys)]
    rows = max(1, len(panels))
    fig = plt.figure(figsize=(13, max(6.0, PANEL_INCHES * rows + 0.8)), dpi=100, layout="constrained")
    grid = fig.add_gridspec(rows, 2, width_ratios=(1.35, 1))
    axes: list[Any] = []
    for row, (keys, title, scale, digits) in enumerate(panels):
        ax = fig.add_subplot(grid[row, 0], sharex=axes[0] if axes else None)
        axes.append(ax)
        _panel(ax, times, [(k, per_frame[k]) for k in keys if k in per_frame], names, scale, digits, title)
        if warm > 0:
            ax.axvspan(times[0], warm, color="0.92", zorder=0, lw=0)
        if row < rows - 1:
            ax.tick_params(labelbottom=False)
    if axes:
        shaded = "; shaded: warm-up" if warm > 0 else ""
        axes[-1].set_xlabel(f"seconds (species coloured as in the top view{shaded})", fontsize=8)
    _top_view(fig.add_subplot(grid[:, 1]), run, names)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    plt.close(fig)
    write_bytes(path, buf.getvalue())
    return path


def _panel(ax, times: np.ndarray, series: list[tuple[str, np.ndarray]], names: list[str], scale: float,
           digits: int, title: str) -> None:
    """One measure (or a mean and its largest) over time; drawn as a labelled constant when every
    value rounds to one number."""
    ax.tick_params(labelsize=7)
    ax.set_title(title, fontsize=8, loc="left", pad=2)
    values = [np.asarray(v, np.float64).reshape(len(times), -1) * scale for _, v in series]
    finite = np.concatenate([v[np.isfinite(v)] for v in values]) if values else np.array([])
    if finite.size == 0:
        ax.text(0.5, 0.5, "not measured", transform=ax.transAxes, ha="center", va="center", fontsize=8)
        ax.set_yticks([])
        return
    tolerance = 0.5 * 10.0 ** -digits
    if float(finite.max() - finite.min()) < tolerance:
        value = round(float(np.median(finite)), digits) + 0.0   # + 0.0: no "-0.0"
        ax.axhline(value, color="C0", lw=1.2)
        ax.set_ylim(value - 1, value + 1)
        ax.set_yticks([value])
        ax.text(0.99, 0.8, f"{value:.{digits}f} throughout", transform=ax.transAxes, ha="right",
                va="top", fontsize=8, color="C0")
        return
    if digits == 0:  # counts: whole-number ticks
        from matplotlib.ticker import MaxNLocator

        ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    for (key, _), v in zip(series, values, strict=True):  # one colour per species, as in the top view
        dashes = "--" if key.endswith("_max") else "-"
        for g in range(v.shape[1]):
            ax.plot(times, v[:, g], color=f"C{g}", lw=1.0, ls=dashes)


def _top_view(ax, run, names: list[str]) -> None:
    positions = np.asarray(run.tracks.positions)
    group = np.asarray(run.tracks.group)
    for g, name in enumerate(names):
        members = np.flatnonzero(group == g)[:TRACKS_DRAWN]
        if members.size:
            ax.plot(positions[:, members, 0], positions[:, members, 2], lw=0.4, alpha=0.5, color=f"C{g}")
        ax.plot([], [], color=f"C{g}", label=name)
    config = run.config
    for label, swum, whole, style in (("predator", run.tracks.predator, config.predator, "k"),
                                      ("target", run.tracks.target, config.target, "r")):
        if swum is None:
            continue
        loop = _whole_path(whole, np.asarray(run.tracks.times)) if isinstance(whole, TargetPath) else None
        if loop is not None:
            ax.plot(loop[:, 0], loop[:, 2], color=style, ls="--", lw=0.8, alpha=0.6)
        ax.plot(swum[:, 0], swum[:, 2], color=style, lw=1.4, label=f"{label} (dashed: its whole path)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title("top view (x, z), metres", fontsize=9)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.06), ncols=2, frameon=False)


def _whole_path(path: TargetPath, times: np.ndarray) -> np.ndarray | None:
    """The whole of a path: one lap of a closed curve, or every point of a timed one."""
    if path.kind == "none":
        return None
    if path.kind == "points":
        return np.asarray(path.points, np.float64).reshape(-1, 4)[:, 1:]
    return path_positions(path, np.linspace(0.0, path.period, 361))
