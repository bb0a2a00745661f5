"""Per-frame measures of a simulated school, and their means after a warm-up.

`measures(tracks, body_lengths, start=0, only=None)` returns float arrays with one row per frame
(frames before `start` are NaN; `only` names the measures to compute, the others are left out):

- `polarization` (F, G): order parameter |mean unit velocity| of each species (1 = all parallel,
  about 1/sqrt(n) for random headings); NaN for a species with no fish.
- `rotation` (F, G): the rotation order parameter of each species, |mean of r_i x v_i| with r_i
  the unit vector from the species' centre to fish i and v_i its unit velocity (Couzin et al.
  2002's angular momentum m_group): 1 for a perfect mill (torus), 0 for a parallel school.
- `nearest_neighbour` (F,): mean over fish of the distance to the nearest other fish (any
  species), in the fish's own body lengths.
- `overlaps` (F,): pairs whose centres are closer than OVERLAP body lengths, where a pair's body
  length is the mean of its two fish's. Fish are slender (about 0.2-0.4 body lengths wide), so
  side by side at half a body length they touch at most; nose to tail closer than that they
  intersect. The simulator keeps centres 0.6 mean body lengths apart.
- `groups` (F, G): separate groups of each species: connected components of the graph linking
  each fish to those of its nearest same-species fish (up to 8) closer than LINK body lengths
  (pair mean): fish that see each other, directly or through others.
- `mixed_groups` (F,): components of the graph that also links each fish to its 4 nearest of any
  species by the same rule, holding more than one species: species that mingle.
- `heading_angle` (F,): mean angle (radians) between a fish's heading (+Z of its quaternion) and
  its velocity; `heading_angle_max` (F,) the largest.
- `turn` (F,): largest heading change from the previous frame, radians (0 in frame 0).
- `target_distance` (F,): mean fish-to-target distance in body lengths (when tracks.target).
- `predator_distance` (F,): mean fish-to-predator distance in body lengths (when tracks.predator).

Neighbours come from the simulation's own lists (`tracks.neighbours`, rebuilt every frame below
300 fish and at most half a second apart above), with every distance measured at the frame
itself; tracks made elsewhere get lists from a k-d tree per frame. The order parameters and the
heading checks (LOGGED) the simulation takes as it runs (`tracks.order`), where the state is at
hand; they are computed from the tracks when tracks carry none.

`body_lengths`: a number, or one body length (metres) per group; a fish's length is its group's
times its `tracks.scale`.
"""
from __future__ import annotations

import math
from collections.abc import Collection, Sequence

import numpy as np

from fishgen.school.model import NeighbourLog, Tracks

OVERLAP = 0.5   # body lengths
LINK = 3.0      # body lengths
MATES = 8       # same-species neighbours a fish links to (at most)
NEAR = 4        # neighbours of any species a fish links to
CHUNK_ELEMENTS = 1 << 19  # frames x fish x neighbours per vectorised pass
LOGGED = ("polarization", "rotation", "heading_angle", "heading_angle_max", "turn")
"""Measures the simulation takes as it runs (Tracks.order): cheaper there, where the state is at hand."""
MEASURES = ("polarization", "rotation", "nearest_neighbour", "overlaps", "groups", "mixed_groups",
            "heading_angle", "heading_angle_max", "turn", "target_distance", "predator_distance")


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


def measures(tracks: Tracks, body_lengths: float | Sequence[float] | np.ndarray, *, start: int = 0,
             only: Collection[str] | None = None) -> dict[str, np.ndarray]:
    """The measures (module docstring) of frames `start` on; `only`: just these."""
    want = set(MEASURES if only is None else only)
    unknown = want - set(MEASURES)
    if unknown:
        raise ValueError(f"unknown measure {sorted(unknown)[0]!r}")
    pos = np.asarray(tracks.positions, dtype=np.float64)
    frames, n = pos.shape[:2]
    start = min(max(int(start), 0), frames)
    group = np.asarray(tracks.group, dtype=np.int64)
    n_groups = int(group.max()) + 1 if n else 0
    length = fish_lengths(tracks, body_lengths)
    # component-major (3, F', N) copies of the frames measured: numpy's passes run along the fish
    p = np.ascontiguousarray(pos[start:].transpose(2, 0, 1))
    out: dict[str, np.ndarray] = {}

    def column(name: str, values: np.ndarray) -> None:
        full = np.full((frames,) + values.shape[1:], np.nan)
        full[start:] = values
        out[name] = full

    logged = tracks.order or {}
    for name in sorted(want & set(logged)):     # the simulation measured these as it ran
        column(name, np.asarray(logged[name], np.float64)[start:])
    want -= set(logged)
    if want & {"polarization", "rotation"}:
        v = np.ascontiguousarray(np.asarray(tracks.velocities, np.float64)[start:].transpose(2, 0, 1))
        polar, rotation = order_parameters(p, v / np.maximum(_norm(v), 1e-12), group, n_groups)
        for name, values in (("polarization", polar), ("rotation", rotation)):
            if name in want:
                column(name, values)
    if want & {"nearest_neighbour", "overlaps", "groups", "mixed_groups"}:
        p32 = p.astype(np.float32)  # distances to a micrometre are plenty; half the memory traffic
        for name, values in _neighbour_measures(tracks, p32, start, group, n_groups, length, want).items():
            column(name, values)
    if want & {"heading_angle", "heading_angle_max", "turn"}:
        q = np.asarray(tracks.headings, np.float64)
        v = np.asarray(tracks.velocities, np.float64)
        before = _nose(q[start - 1].T) if start > 0 else None
        mean, most, turn = heading_checks(q[start:], v[start:], before)
        for name, values in (("heading_angle", mean), ("heading_angle_max", most), ("turn", turn)):
            if name in want:
                column(name, values)
    for name, path in (("target_distance", tracks.target), ("predator_distance", tracks.predator)):
        if name in want and path is not None:
            away = p - np.asarray(path, np.float64)[start:].T[:, :, None]
            column(name, (_norm(away) / length).mean(axis=1))
    return {name: out[name] for name in MEASURES if name in out}


def order_parameters(pos: np.ndarray, unit: np.ndarray, group: np.ndarray, n_groups: int,
                     member: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Polarization and rotation order parameter of each species, from component-major positions
    and unit headings (3, ..., N): two arrays (..., G), NaN for a species with no fish.

    The simulation calls this every frame, so the sums over the fish are dot products: the
    rotation's sum of (r_i / |r_i|) x v_i is sum of r_i x (v_i / |r_i|), one pass per component.
    `member`: membership_matrix(group, n_groups), when the caller keeps one."""
    if n_groups == 1 and pos.ndim == 2:   # one species, one frame: the simulation's case
        n = pos.shape[1]
        if n == 0:
            return np.full(1, np.nan), np.full(1, np.nan)
        hx, hy, hz = unit.sum(axis=1).tolist()
        r = pos - pos.sum(axis=1, keepdims=True) / n
        # r_a . (v_b / |r|) for every pair of components a, b, in one product; a fish at the
        # centre has r = 0 and adds nothing, whatever 1 / |r| is there
        m = (r @ (unit / np.sqrt(np.einsum("ij,ij->j", r, r) + 1e-300)).T).tolist()
        sx, sy, sz = m[1][2] - m[2][1], m[2][0] - m[0][2], m[0][1] - m[1][0]
        return (np.array([math.sqrt(hx * hx + hy * hy + hz * hz) / n]),
                np.array([math.sqrt(sx * sx + sy * sy + sz * sz) / n]))
    if member is None:
        member = membership_matrix(group, n_groups)
    count = member.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        inv = np.where(count > 0, 1.0 / count, np.nan)
        r = pos - ((pos @ member) * inv)[..., group]
        w = unit / np.maximum(_norm(r), 1e-12)
        spin = np.stack([r[1] * w[2] - r[2] * w[1], r[2] * w[0] - r[0] * w[2], r[0] * w[1] - r[1] * w[0]])
        return _norm(unit @ member) * inv, _norm(spin @ member) * inv


def membership_matrix(group: np.ndarray, n_groups: int) -> np.ndarray:
    """(N, G): 1 where fish n is of species g."""
    member = np.zeros((group.size, n_groups))
    member[np.arange(group.size), group] = 1.0
    return member


def heading_checks(q: np.ndarray, v: np.ndarray,
                   before: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per frame of headings `q` (F, N, 4) and velocities `v` (F, N, 3): the mean and the largest
    angle between a fish's nose (+Z) and its velocity, and the largest turn of a nose since the
    frame before (`before`: the noses (3, N) of the frame before the first; 0 without it)."""
    frames, n = q.shape[:2]
    mean, most, turn = np.zeros(frames), np.zeros(frames), np.zeros(frames)
    if n == 0 or frames == 0:
        return mean, most, turn
    chunk = max(1, CHUNK_ELEMENTS // (8 * n))   # a few frames at a time: temporaries stay in cache
    for lo in range(0, frames, chunk):
        hi = min(lo + chunk, frames)
        nose = _nose(np.moveaxis(q[lo:hi], -1, 0))
        ang = _angle(nose, np.moveaxis(v[lo:hi], -1, 0))
        mean[lo:hi], most[lo:hi] = ang.mean(axis=1), ang.max(axis=1)
        if before is not None:
            nose = np.concatenate([before[:, None], nose], axis=1)
        if nose.shape[1] > 1:
            turn[hi - (nose.shape[1] - 1):hi] = _angle(nose[:, 1:], nose[:, :-1]).max(axis=1)
        before = nose[:, -1]
    return mean, most, turn


def _neighbour_measures(tracks: Tracks, p: np.ndarray, start: int, group: np.ndarray, n_groups: int,
                        length: np.ndarray, want: set[str]) -> dict[str, np.ndarray]:
    """nearest_neighbour, overlaps, groups and mixed_groups of frames start.. from the neighbour lists.

    A school's links change far more slowly than its frames: components are searched only in
    frames whose links differ from the frame before's, and carried over otherwise."""
    measured, n = p.shape[1], p.shape[2]
    nn = np.full(measured, np.nan)
    overlaps = np.zeros(measured)
    groups = np.zeros((measured, n_groups))
    mixed = np.zeros(measured)
    if n < 2:
        groups[:] = np.bincount(group, minlength=n_groups) > 0
        return {"nearest_neighbour": nn, "overlaps": overlaps, "groups": groups, "mixed_groups": mixed}
    log = tracks.neighbours if tracks.neighbours is not None and tracks.neighbours.starts else None
    if log is None:
        log = _search(p, group, n_groups)
        which = np.arange(measured)
    else:
        which = log.index(np.arange(start, start + measured))
    m = min(MATES, log.mates[0].shape[0])
    listed = np.stack(log.mates)[:, :m]
    if n_groups > 1 or m < log.near[0].shape[0]:  # else the nearest of any species lead the mates' lists
        listed = np.concatenate([listed, np.stack(log.near)[:, :NEAR]], axis=1)
    ok_all = listed >= 0
    idx_all = np.where(ok_all, listed, 0).astype(np.int64)
    # per list: squared thresholds, never met where the entry is no fish
    pair = 0.5 * (length + length[idx_all])
    link2_all = np.where(ok_all, (LINK * pair) ** 2, -1.0).astype(np.float32)
    overlap2_all = np.where(ok_all, (OVERLAP * pair) ** 2, -1.0).astype(np.float32)
    inv_len2 = 1.0 / (length * length)
    k = idx_all.shape[1]
    count_groups = "groups" in want
    count_mixed = n_groups > 1 and "mixed_groups" in want
    before: dict[str, np.ndarray | None] = {"groups": None, "mixed": None}
    chunk = max(1, CHUNK_ELEMENTS // (n * k))
    for lo in range(0, measured, chunk):
        hi = min(lo + chunk, measured)
        f = hi - lo
        lists = which[lo:hi]
        idx = idx_all[lists]                                                        # (f, k, N)
        flat = p[:, lo:hi].reshape(3, f * n)
        other = idx + (np.arange(f) * n)[:, None, None]
        off = np.take(flat, other, axis=1) - p[:, lo:hi, None, :]
        d2 = off[0] * off[0] + off[1] * off[1] + off[2] * off[2]                   # (f, k, N)
        if "nearest_neighbour" in want:
            nearest = np.where(ok_all[lists], d2, np.inf).min(axis=1)
            nn[lo:hi] = np.sqrt(nearest * inv_len2).mean(axis=1)
        if "overlaps" in want:
            close = d2 < overlap2_all[lists]
            if close.any():
                fr, _, me = np.nonzero(close)
                them = idx[close].astype(np.int64)
                keys = np.unique((fr * n + np.minimum(me, them)) * n + np.maximum(me, them))
                overlaps[lo:hi] = np.bincount(keys // (n * n), minlength=f)
        if not (count_groups or count_mixed):
            continue
        linked = d2 < link2_all[lists]
        if count_groups:
            groups[lo:hi] = _count(np.where(linked[:, :m], idx[:, :m], -1), group, n_groups, before,
                                   "groups", mixed=False)
        if count_mixed:
            mixed[lo:hi] = _count(np.where(linked, idx, -1), group, n_groups, before, "mixed", mixed=True)
    return {"nearest_neighbour": nn, "overlaps": overlaps, "groups": groups, "mixed_groups": mixed}


def _count(links: np.ndarray, group: np.ndarray, n_groups: int, before: dict, key: str,
           mixed: bool) -> np.ndarray:
    """Per frame of `links` (f, k, N: the fish each fish links to, -1 for none): components per
    species (f, G), or with `mixed` the components holding several species (f,). Only frames whose
    links differ from the frame before's are searched; `before[key]` carries the last frame's
    links and counts from chunk to chunk."""
    from scipy.sparse import csr_array  # type: ignore[import-untyped]
    from scipy.sparse.csgraph import connected_components  # type: ignore[import-untyped]

    f, _, n = links.shape
    last = before[key]
    new = np.ones(f, dtype=bool)
    new[1:] = np.any(links[1:] != links[:-1], axis=(1, 2))
    if last is not None:
        new[0] = not np.array_equal(links[0], last[0])
    frames = np.flatnonzero(new)
    shape = (f, n_groups) if not mixed else (f,)
    counts = np.zeros(shape)
    if frames.size:
        sub = links[frames]
        src = np.broadcast_to((np.arange(frames.size) * n)[:, None, None] + np.arange(n), sub.shape)
        has = sub >= 0
        dst = sub + (np.arange(frames.size) * n)[:, None, None]
        nodes = frames.size * n
        ones = np.ones(int(has.sum()), dtype=np.int8)
        graph = csr_array((ones, (src[has], dst[has])), shape=(nodes, nodes))
        _, labels = connected_components(graph, directed=False)
        species = np.tile(group, frames.size)
        rep = np.zeros(int(labels.max()) + 1, dtype=np.int64)
        rep[labels] = np.arange(nodes)              # one fish of each component: its frame and species
        if mixed:
            kinds = np.zeros((rep.size, n_groups), dtype=bool)
            kinds[labels, species] = True
            counts[frames] = np.bincount(rep[kinds.sum(axis=1) > 1] // n, minlength=frames.size)
        else:
            counts[frames] = np.bincount((rep // n) * n_groups + species[rep],
                                         minlength=frames.size * n_groups).reshape(frames.size, n_groups)
    # frames whose links did not change keep the frame before's counts
    source = np.maximum.accumulate(np.where(new, np.arange(f), -1))
    carried = source < 0
    if carried.any() and last is not None:
        counts[carried] = last[1]
    counts[~carried] = counts[source[~carried]]
    before[key] = (links[-1].copy(), counts[-1].copy())
    return counts


def _search(p: np.ndarray, group: np.ndarray, n_groups: int) -> NeighbourLog:
    """Lists for tracks that carry none (made elsewhere): a k-d tree per frame."""
    from scipy.spatial import cKDTree  # type: ignore[import-untyped]

    n = p.shape[2]
    log = NeighbourLog()
    members = [np.flatnonzero(group == g) for g in range(n_groups)]
    m = min(NEAR, n - 1)
    for f in range(p.shape[1]):
        pts = p[:, f].T
        _, near = cKDTree(pts).query(pts, k=m + 1)
        near = near.reshape(n, m + 1)[:, 1:]
        mates = np.zeros((n, MATES), dtype=np.int64)
        ok = np.zeros((n, MATES), dtype=bool)
        for ids in members:
            kk = min(MATES, ids.size - 1)
            if kk < 1:
                continue
            _, li = cKDTree(pts[ids]).query(pts[ids], k=kk + 1)
            li = li.reshape(ids.size, kk + 1)[:, 1:]
            mates[ids, :kk] = ids[li]
            ok[ids, :kk] = ids[li] != ids[:, None]
        log.append(f, mates.T, ok.T, near.T, (near != np.arange(n)[:, None]).T)
    return log


def _norm(v: np.ndarray) -> np.ndarray:
    return np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


def _nose(q: np.ndarray) -> np.ndarray:
    """+Z of component-major quaternions (4, ...) -> (3, ...)."""
    x, y, z, w = q[0], q[1], q[2], q[3]
    return np.stack([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle between component-major vectors (3, ...); atan2(|a x b|, a . b) stays exact near 0,
    where arccos of a dot product a rounding error away from 1 reads 1e-8 radians."""
    cross = np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
    return np.arctan2(_norm(cross), a[0] * b[0] + a[1] * b[1] + a[2] * b[2])


def summary(measures: dict[str, np.ndarray], warmup_frames: int) -> dict[str, float | list[float]]:
    """Mean of each measure over the frames after `warmup_frames` (per species for (F, G) ones);
    `overlaps`, `groups`, `mixed_groups`, `heading_angle_max` and `turn` also give their maxima
    as `<name>_peak`, and `polarization` and `rotation` their minima as `<name>_least`."""
    out: dict[str, float | list[float]] = {}
    for name, arr in measures.items():
        tail = _tail(arr, warmup_frames)
        with np.errstate(all="ignore"):
            finite = np.isfinite(tail)
            mean = (np.where(finite, tail, 0.0).sum(axis=0) / finite.sum(axis=0))
        out[name] = [float(x) for x in mean] if tail.ndim == 2 else float(mean)
        for suffix, names, pick in (("_peak", PEAKS, np.fmax.reduce), ("_least", LEASTS, np.fmin.reduce)):
            if name in names:
                extreme = pick(tail, axis=0)
                out[name + suffix] = [float(x) for x in extreme] if tail.ndim == 2 else float(extreme)
    return out


PEAKS = ("overlaps", "groups", "mixed_groups", "heading_angle_max", "turn")
LEASTS = ("polarization", "rotation")


def _tail(arr: np.ndarray, warmup_frames: int) -> np.ndarray:
    """The frames after the warm-up (the last frame when there are none)."""
    arr = np.asarray(arr, dtype=np.float64)
    return arr[warmup_frames:] if arr.shape[0] > warmup_frames else arr[-1:]


# (measure, label, unit scale, format, which way is worse); per-species measures get one row each.
# The rotation order parameter's worst is its least in a school that mills (mean 0.5 or more: a
# torus losing its mill) and its most in one that does not (a mill where none is wanted).
TABLE = (
    ("polarization", "polarization (1 = parallel)", 1.0, "{:.2f}", "min"),
    ("rotation", "rotation (1 = milling)", 1.0, "{:.2f}", "state"),
    ("groups", "separate groups", 1.0, "{:.0f}", "max"),
    ("nearest_neighbour", "nearest neighbour (body lengths)", 1.0, "{:.2f}", "min"),
    ("overlaps", "overlapping pairs", 1.0, "{:.0f}", "max"),
    ("mixed_groups", "groups mixing species", 1.0, "{:.0f}", "max"),
    ("heading_angle", "heading vs velocity (deg)", np.degrees(1.0), "{:.1f}", "max"),
    ("turn", "largest turn per frame (deg)", np.degrees(1.0), "{:.1f}", "max"),
    ("target_distance", "distance to target (body lengths)", 1.0, "{:.2f}", "max"),
    ("predator_distance", "distance to predator (body lengths)", 1.0, "{:.2f}", "min"),
)
PRINTED = tuple(row[0] for row in TABLE)
"""The measures the summary table prints: what `measures(..., only=PRINTED)` needs for it."""


def summary_table(per_frame: dict[str, np.ndarray], warmup_frames: int,
                  species: Sequence[str]) -> list[tuple[str, str, str]]:
    """Rows (measure, mean, worst) over the frames after the warm-up, worst being the minimum or
    maximum, whichever is bad for that measure; per-species measures get a row per species."""
    rows = []
    for key, label, scale, fmt, worse in TABLE:
        if key not in per_frame:
            continue
        tail = _tail(per_frame[key], warmup_frames)
        columns = tail.T if tail.ndim == 2 else tail[None]
        for g, column in enumerate(columns):
            column = column[np.isfinite(column)] * scale
            name = f"{label}, {species[g]}" if tail.ndim == 2 and len(species) > 1 else label
            if column.size == 0:
                rows.append((name, "-", "-"))
                continue
            way = ("min" if column.mean() >= 0.5 else "max") if worse == "state" else worse
            worst = column.min() if way == "min" else column.max()
            rows.append((name, fmt.format(column.mean()), fmt.format(worst)))
    return rows


def format_table(rows: Sequence[tuple[str, str, str]], title: str) -> str:
    """The rows as aligned text under a header line."""
    width = max(len(title), *(len(r[0]) for r in rows)) if rows else len(title)
    lines = [f"{title:<{width}}  {'mean':>7}  {'worst':>7}"]
    lines += [f"{name:<{width}}  {mean:>7}  {worst:>7}" for name, mean, worst in rows]
    return "\n".join(lines)
