"""Per-frame measures of a simulated school, and their means after a warm-up.

`measures(tracks, body_lengths)` returns arrays with one row per frame:

- `polarization` (F, G): order parameter |mean unit velocity| of each species (1 = all parallel,
  about 1/sqrt(n) for random headings); NaN for a species with no fish.
- `nearest_neighbour` (F,): mean over fish of the distance to the nearest other fish (any species),
  in the fish's own body lengths.
- `overlaps` (F,): pairs whose centres are closer than OVERLAP body lengths, where a pair's body
  length is the mean of its two fish's. Fish are slender (about 0.2-0.4 body lengths wide), so
  side by side at half a body length they touch at most; nose to tail closer than that they
  intersect. The simulator keeps centres 0.6 mean body lengths apart.
- `groups` (F, G): separate groups of each species: connected components of the graph linking
  same-species fish closer than LINK body lengths (pair mean).
- `mixed_groups` (F,): components of the all-species graph (same link rule) holding more than
  one species.
- `heading_angle` (F,): mean angle (radians) between a fish's heading (+Z of its quaternion) and
  its velocity; `heading_angle_max` (F,) the largest.
- `turn` (F,): largest heading change from the previous frame, radians (0 in frame 0).
- `target_distance` (F,): mean fish-to-target distance in body lengths (when tracks.target).
- `predator_distance` (F,): mean fish-to-predator distance in body lengths (when tracks.predator).

`body_lengths`: a number, or one body length (metres) per group; a fish's length is its group's
times its `tracks.scale`.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.sparse import coo_matrix  # type: ignore[import-untyped]
from scipy.sparse.csgraph import connected_components  # type: ignore[import-untyped]
from scipy.spatial import cKDTree  # type: ignore[import-untyped]

from fishgen.school.model import Tracks

OVERLAP = 0.5   # body lengths
LINK = 3.0      # body lengths


def fish_lengths(tracks: Tracks, body_lengths: float | Sequence[float] | np.ndarray) -> np.ndarray:
    """Each fish's body length in metres (N,)."""
    bl = np.atleast_1d(np.asarray(body_lengths, dtype=np.float64))
    group = np.asarray(tracks.group, dtype=np.int64)
    base = np.full(group.shape, bl[0]) if bl.size == 1 else bl[group]
    return base * np.asarray(tracks.scale, dtype=np.float64)


def nose_directions(headings: np.ndarray) -> np.ndarray:
    """+Z of each quaternion (x, y, z, w): where the fish's head points."""
    x, y, z, w = (headings[..., i] for i in range(4))
    return np.stack([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)], axis=-1)


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle between vectors along the last axis; atan2(|a x b|, a . b) stays exact near 0, where
    arccos of a dot product a rounding error away from 1 reads 1e-8 radians."""
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.einsum("...c,...c->...", a, b))


def measures(tracks: Tracks, body_lengths: float | Sequence[float] | np.ndarray) -> dict[str, np.ndarray]:
    pos = np.asarray(tracks.positions, dtype=np.float64)
    vel = np.asarray(tracks.velocities, dtype=np.float64)
    frames, n = pos.shape[:2]
    group = np.asarray(tracks.group, dtype=np.int64)
    n_groups = int(group.max()) + 1 if n else 0
    length = fish_lengths(tracks, body_lengths)

    speed = np.linalg.norm(vel, axis=2, keepdims=True)
    unit = vel / np.maximum(speed, 1e-12)
    polar = np.full((frames, n_groups), np.nan)
    for g in range(n_groups):
        sel = group == g
        if sel.any():
            polar[:, g] = np.linalg.norm(unit[:, sel].mean(axis=1), axis=1)

    nose = nose_directions(np.asarray(tracks.headings, dtype=np.float64))
    ang = _angle(nose, unit)
    turn = np.zeros(frames)
    if frames > 1:
        turn[1:] = _angle(nose[1:], nose[:-1]).max(axis=1) if n else 0.0

    nn = np.full(frames, np.nan)
    overlaps = np.zeros(frames, dtype=np.int64)
    groups = np.zeros((frames, n_groups), dtype=np.int64)
    mixed = np.zeros(frames, dtype=np.int64)
    reach = LINK * float(length.max()) if n else 0.0
    for f in range(frames):
        if n < 2:
            groups[f] = [int((group == g).sum() > 0) for g in range(n_groups)]
            continue
        tree = cKDTree(pos[f])
        d, i = tree.query(pos[f], k=2)
        nn[f] = float(np.mean(d[:, 1] / length))
        pairs = tree.query_pairs(reach, output_type="ndarray")
        a, b = pairs[:, 0], pairs[:, 1]
        dist = np.linalg.norm(pos[f, a] - pos[f, b], axis=1)
        pair_len = 0.5 * (length[a] + length[b])
        overlaps[f] = int(np.count_nonzero(dist < OVERLAP * pair_len))
        linked = dist < LINK * pair_len
        a, b = a[linked], b[linked]
        same = group[a] == group[b]
        labels = _components(n, a[same], b[same])
        for g in range(n_groups):
            groups[f, g] = np.unique(labels[group == g]).size
        all_labels = _components(n, a, b)
        kinds = np.unique(np.stack([all_labels, group], axis=1), axis=0)
        mixed[f] = int(np.count_nonzero(np.bincount(kinds[:, 0]) > 1))

    out = {
        "polarization": polar,
        "nearest_neighbour": nn,
        "overlaps": overlaps,
        "groups": groups,
        "mixed_groups": mixed,
        "heading_angle": ang.mean(axis=1) if n else np.zeros(frames),
        "heading_angle_max": ang.max(axis=1) if n else np.zeros(frames),
        "turn": turn,
    }
    if tracks.target is not None:
        dt = np.linalg.norm(pos - np.asarray(tracks.target)[:, None, :], axis=2)
        out["target_distance"] = (dt / length).mean(axis=1)
    if tracks.predator is not None:
        dp = np.linalg.norm(pos - np.asarray(tracks.predator)[:, None, :], axis=2)
        out["predator_distance"] = (dp / length).mean(axis=1)
    return out


def _components(n: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    graph = coo_matrix((np.ones(a.size, dtype=np.int8), (a, b)), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    return labels


def summary(measures: dict[str, np.ndarray], warmup_frames: int) -> dict[str, float | list[float]]:
    """Mean of each measure over the frames after `warmup_frames` (per species for (F, G) ones);
    `overlaps`, `groups`, `mixed_groups`, `heading_angle_max` and `turn` also give their maxima
    as `<name>_peak`."""
    out: dict[str, float | list[float]] = {}
    for name, arr in measures.items():
        tail = np.asarray(arr, dtype=np.float64)[warmup_frames:]
        if tail.shape[0] == 0:
            tail = np.asarray(arr, dtype=np.float64)[-1:]
        mean = np.nanmean(tail, axis=0) if np.isfinite(tail).any() else np.full(tail.shape[1:], np.nan)
        out[name] = [float(x) for x in mean] if tail.ndim == 2 else float(mean)
        if name in ("overlaps", "groups", "mixed_groups", "heading_angle_max", "turn"):
            peak = tail.max(axis=0)
            out[name + "_peak"] = [float(x) for x in peak] if tail.ndim == 2 else float(peak)
    return out


# (measure, label, unit scale, format, which way is worse); per-species measures get one row each
_TABLE = (
    ("polarization", "polarization (1 = parallel)", 1.0, "{:.2f}", "min"),
    ("groups", "separate groups", 1.0, "{:.0f}", "max"),
    ("nearest_neighbour", "nearest neighbour (body lengths)", 1.0, "{:.2f}", "min"),
    ("overlaps", "overlapping pairs", 1.0, "{:.0f}", "max"),
    ("mixed_groups", "groups mixing species", 1.0, "{:.0f}", "max"),
    ("heading_angle", "heading vs velocity (deg)", np.degrees(1.0), "{:.1f}", "max"),
    ("turn", "largest turn per frame (deg)", np.degrees(1.0), "{:.1f}", "max"),
    ("target_distance", "distance to target (body lengths)", 1.0, "{:.2f}", "max"),
    ("predator_distance", "distance to predator (body lengths)", 1.0, "{:.2f}", "min"),
)


def summary_table(per_frame: dict[str, np.ndarray], warmup_frames: int,
                  species: Sequence[str]) -> list[tuple[str, str, str]]:
    """Rows (measure, mean, worst) over the frames after the warm-up, worst being the minimum or
    maximum, whichever is bad for that measure; per-species measures get a row per species."""
    rows = []
    for key, label, scale, fmt, worse in _TABLE:
        if key not in per_frame:
            continue
        tail = np.asarray(per_frame[key], dtype=np.float64)
        tail = tail[warmup_frames:] if tail.shape[0] > warmup_frames else tail[-1:]
        columns = tail.T if tail.ndim == 2 else tail[None]
        for g, column in enumerate(columns):
            column = column[np.isfinite(column)] * scale
            name = f"{label}, {species[g]}" if tail.ndim == 2 and len(species) > 1 else label
            if column.size == 0:
                rows.append((name, "-", "-"))
                continue
            worst = column.min() if worse == "min" else column.max()
            rows.append((name, fmt.format(column.mean()), fmt.format(worst)))
    return rows


def format_table(rows: Sequence[tuple[str, str, str]], title: str) -> str:
    """The rows as aligned text under a header line."""
    width = max(len(title), *(len(r[0]) for r in rows)) if rows else len(title)
    lines = [f"{title:<{width}}  {'mean':>7}  {'worst':>7}"]
    lines += [f"{name:<{width}}  {mean:>7}  {worst:>7}" for name, mean, worst in rows]
    return "\n".join(lines)
