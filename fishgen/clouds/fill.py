"""The randomized fill of report section 4.5, vectorised with numpy: positions, radii, densities.

Particles are produced in fixed chunks of ``CHUNK`` rows; chunk ``j`` draws from
its own generator seeded with ``(seed, j)``, so the result is byte-identical for
a seed whatever the thread count, and chunks can run on all cores (numpy
releases the GIL in its ufuncs and random fills). Temporaries are float32 and
chunk-sized, so memory stays close to the ~31 bytes per particle of the result.

Positions are drawn in *normalised cube coordinates* ``s`` in [-1, 1] per axis
(the centred form of eq. 4.4/4.8), shifted by the report's sine phase shifts
(eq. 4.5-4.7, with the departures listed in docs/decisions.md), and
redrawn in batches while outside the cube (Figure 4.2).
"""
from __future__ import annotations

import math
import numbers
import os
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from fishgen.clouds.model import METHODS, Cloud, CubeFile
from fishgen.errors import FishgenError, UsageError

CHUNK = 1 << 16
CLUMP = 0.25
"""Phase shifts (radians, |P| <= 3*pi/2) move a particle by CLUMP*P/pi half-extents: at most 37.5 %."""
MAX_ROUNDS = 64
"""Rejection rounds per chunk; about 77 % of paper draws are accepted, so 4-5 rounds suffice."""

UNLIT = 255
"""An unlit cloud is white; its colours come from the sun (fishgen.clouds.light.light_cloud)."""

_F32 = np.float32
_HALF_PI = _F32(math.pi / 2)
_PI = _F32(math.pi)
_RADIUS_NORM = _F32(1 + math.pi / 2 * math.sin(1.0))  # eq. 4.12 at the maximum, u = 1
_TINY = np.finfo(np.float32).smallest_subnormal


def fill_cloud(cube_file: CubeFile, *, seed: int = 0, method: str = "paper",
               offset: Sequence[float] = (0.0, 0.0, 0.0), workers: int | None = None,
               advance: Callable[[int], None] | None = None) -> Cloud:
    """Fill every cube with its particles; ``offset`` moves the whole cloud in the scene.
    ``advance(k)`` as each k particles are placed (a progress bar's), on the calling thread."""
    # a library caller's arguments get the command line's kind of error, not numpy's
    if method not in METHODS:
        raise FishgenError(f"expected a fill method of {' or '.join(METHODS)}, found {method!r}")
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise FishgenError(f"expected a seed as a whole number of 0 or more, found {seed!r}")
    if np.shape(offset) != (3,):
        shown = ", ".join(f"{v:g}" if isinstance(v, (int, float)) else repr(v)
                          for v in np.ravel(offset).tolist())
        raise FishgenError(f"expected an offset of three numbers (x, y, z), found ({shown})")
    cubes = cube_file.cubes
    counts = np.array([c.particles for c in cubes], np.int64)
    if (counts < 0).any():   # a CubeFile made in Python; the parser refuses these
        bad = cubes[int(np.argmax(counts < 0))]
        raise FishgenError(f"expected a cube of 0 or more particles, found {bad.particles}",
                           cube_file.path or None, bad.line or None)
    from fishgen.clouds.memory import check_fits

    check_fits(int(counts.sum()), ".npy")   # before the arrays: the parser's cap is the caller's to skip
    size = np.array([c.size for c in cubes], np.float64).reshape(-1, 3)
    centre = np.array([c.centre for c in cubes], np.float64).reshape(-1, 3)
    centre = centre + np.asarray(offset, np.float64).reshape(1, 3)
    lo, hi = centre - size / 2, centre + size / 2
    lo32, hi32 = _float32_bounds(cube_file, offset, lo, hi)
    tables = _Tables(centre=centre.astype(_F32), half=(size / 2).astype(_F32), lo=lo32, hi=hi32,
                     rmax=np.array([c.max_radius for c in cubes], np.float32))

    n = int(counts.sum())
    cube_index = np.repeat(np.arange(len(cubes), dtype=np.int32), counts)
    textures = tuple(c.texture for c in cubes) if any(c.texture for c in cubes) else ()
    out = Cloud(centers=np.empty((n, 3), _F32), radii=np.empty(n, _F32),
                density=np.empty(n, _F32), colors=np.full((n, 3), UNLIT, np.uint8),
                cube_index=cube_index, cube_bounds=np.stack([lo, hi], axis=1), textures=textures)

    kept = threading.local()  # each worker thread's scratch, reused from chunk to chunk

    def work(start: int) -> None:
        scratch = getattr(kept, "scratch", None)
        if scratch is None:
            scratch = kept.scratch = _Scratch(min(CHUNK, n))
        _fill_chunk(out, tables, start, min(start + CHUNK, n), int(seed), method, scratch)

    starts = range(0, n, CHUNK)
    threads = 1 if len(starts) <= 1 else min(workers or os.cpu_count() or 1, len(starts))
    if threads <= 1:
        for start in starts:
            work(start)
            if advance is not None:
                advance(min(CHUNK, n - start))
    else:
        with ThreadPoolExecutor(threads) as pool:
            for start, _ in zip(starts, pool.map(work, starts), strict=True):
                if advance is not None:
                    advance(min(CHUNK, n - start))
    return out


def _float32_bounds(cube_file: CubeFile, offset, lo: np.ndarray, hi: np.ndarray):
    """The cube bounds rounded inward to float32; refuse cubes (after the offset) that
    float32 particles cannot hold, before allocating.

    Outside +-3.4e38 every particle would be clamped to the float32 maximum (or
    become infinite), so the output would be silently wrong.
    """
    limit = float(np.finfo(np.float32).max)
    shift = tuple(float(v) for v in np.asarray(offset, np.float64).reshape(3))
    if not all(math.isfinite(v) and abs(v) <= limit for v in shift):
        raise FishgenError(f"expected an offset within float32 range (-{limit:.3g} to "
                           f"{limit:.3g} per axis), found {_xyz(shift)}", cube_file.path)
    outside = ~((np.abs(lo) <= limit) & (np.abs(hi) <= limit))   # NaN compares False too
    with np.errstate(over="ignore", invalid="ignore"):  # cubes out of range are refused below
        lo32, hi32 = _round_inward(lo, up=True), _round_inward(hi, up=False)
    thin = ~outside & (lo32 > hi32)  # e.g. 1 unit wide at y = 3e38, where float32 steps are 2e31
    for bad, fault in ((outside, f"within float32 range (-{limit:.3g} to {limit:.3g} per axis)"),
                       (thin, "at least one float32 step wide on each axis")):
        if not bad.any():
            continue
        k = int(np.flatnonzero(bad.any(axis=1))[0])
        cube = cube_file.cubes[k]
        corners = f"corners {_xyz(lo[k])} to {_xyz(hi[k])}"
        if any(shift) and _holds(lo[k] - shift, hi[k] - shift):
            # the cube is fine where its file puts it: the offset is what to change
            where = f"{cube_file.path}:{cube.line}" if cube.line else str(cube_file.path)
            raise UsageError(f"expected an offset that keeps each cube {fault}, found "
                             f"{_xyz(shift)}, which moves the cube of {where} to {corners}")
        tail = " (too thin for float32 there)" if bad is thin else ""
        raise FishgenError(f"expected a cube {fault}, found {corners}{tail}",
                           cube_file.path, cube.line or None)
    return lo32, hi32


def _holds(lo: np.ndarray, hi: np.ndarray) -> bool:
    """Whether float32 can hold a cube from ``lo`` to ``hi``: in range, a float32 step wide."""
    limit = float(np.finfo(np.float32).max)
    if not ((np.abs(lo) <= limit) & (np.abs(hi) <= limit)).all():
        return False
    with np.errstate(over="ignore"):
        return bool((_round_inward(lo, up=True) <= _round_inward(hi, up=False)).all())


def _xyz(values) -> str:
    return "(" + ", ".join(f"{float(v):.6g}" for v in values) + ")"


def merge_clouds(clouds: Sequence[Cloud]) -> Cloud:
    """One scene from several clouds; cube indices are renumbered to stay unique.

    Light them after merging, so they shadow each other. Clouds lit alike before keep
    their light; otherwise the merged cloud is unlit (its colours kept).
    """
    if not clouds:
        raise FishgenError("expected at least one cloud to merge, found none")
    if len(clouds) == 1:
        return clouds[0]
    shifts = np.cumsum([0] + [len(c.cube_bounds) for c in clouds[:-1]])
    lit = all(c.light is not None and c.lighting == clouds[0].lighting for c in clouds)
    return Cloud(
        centers=np.concatenate([c.centers for c in clouds]),
        radii=np.concatenate([c.radii for c in clouds]),
        density=np.concatenate([c.density for c in clouds]),
        colors=np.concatenate([c.colors for c in clouds]),
        cube_index=np.concatenate([c.cube_index + np.int32(k) for c, k in zip(clouds, shifts, strict=True)]),
        cube_bounds=np.concatenate([c.cube_bounds for c in clouds]),
        light=np.concatenate([c.light for c in clouds if c.light is not None]) if lit else None,
        lighting=clouds[0].lighting if lit else None,
        textures=(tuple(t for c in clouds for t in (c.textures or (None,) * len(c.cube_bounds)))
                  if any(c.textures for c in clouds) else ()))


class _Tables:
    """Per-cube float32 lookup tables shared by the chunk workers."""

    def __init__(self, centre, half, lo, hi, rmax):
        self.centre, self.half, self.lo, self.hi, self.rmax = centre, half, lo, hi, rmax


def _round_inward(bound: np.ndarray, up: bool) -> np.ndarray:
    """float32 bounds rounded towards the cube, so a clipped float32 centre is truly inside."""
    b32 = bound.astype(_F32)
    wrong = b32 < bound if up else b32 > bound
    return np.where(wrong, np.nextafter(b32, _F32(np.inf if up else -np.inf)), b32)


class _Scratch:
    """One worker thread's buffers for chunks of up to ``m`` particles. A fill's arithmetic is a
    few nanoseconds a particle, and on a VM the first touch of a fresh page costs about as much a
    byte: made anew for each step, the temporaries' pages cost more than the steps did."""

    def __init__(self, m: int):
        draws = m + m // 3 + 16   # the first round's over-draw, the largest
        self.draws = np.empty(3 * draws, _F32)
        self.rows = np.empty((5, draws), _F32)
        self.mask = np.empty(draws, np.bool_)
        self.offsets = np.empty(3 * m, _F32)
        self.u = np.empty((2, m), _F32)


def _fill_chunk(out: Cloud, t: _Tables, start: int, stop: int, seed: int, method: str,
                scratch: _Scratch | None = None) -> None:
    m = stop - start
    work = scratch or _Scratch(m)
    rng = np.random.default_rng([seed, start // CHUNK])
    idx = out.cube_index[start:stop]
    s = _paper_offsets(rng, m, work) if method == "paper" else _uniform_offsets(rng, m, work.offsets)

    # Particles are sorted by cube, so a chunk is a few runs of equal cube index: each run is
    # placed with its cube's numbers as scalars, an axis at a time into the (m, 3) centres (no
    # per-particle copies of the tables, no transposed copy of the whole chunk).
    first, last = int(idx[0]), int(idx[-1])
    ends = [0, m] if first == last else [0, *np.cumsum(np.bincount(idx - first, minlength=last - first + 1))]
    u, sine = work.u[0, :m], work.u[1, :m]
    rng.random(m, dtype=_F32, out=u)
    np.subtract(_F32(1), u, out=u)  # (0, 1]: a radius is never 0
    if method == "paper":
        # eq. 4.9-4.12 in units of the cube's maximum radius, renormalised into (0, 1].
        np.sin(u, out=sine)
        sine *= _HALF_PI
        u += sine
        u /= _RADIUS_NORM
    centers, radii = out.centers[start:stop], out.radii[start:stop]
    for cube, (a, b) in enumerate(zip(ends[:-1], ends[1:], strict=True), start=first):
        if a == b:
            continue
        for axis in range(3):
            column = centers[a:b, axis]
            np.multiply(s[axis, a:b], t.half[cube, axis], out=column)
            column += t.centre[cube, axis]
            np.clip(column, t.lo[cube, axis], t.hi[cube, axis], out=column)
        np.multiply(u[a:b], t.rmax[cube], out=radii[a:b])
        np.clip(radii[a:b], _TINY, t.rmax[cube], out=radii[a:b])

    # Gaussian fall-off from the cube centre: 1 at the core, e^-1 at a face centre.
    np.square(s, out=s)
    density = out.density[start:stop]
    np.add(s[0], s[1], out=density)
    density += s[2]
    np.negative(density, out=density)
    np.exp(density, out=density)


def _uniform_offsets(rng: np.random.Generator, m: int, into: np.ndarray | None = None) -> np.ndarray:
    """(3, m) uniform draws in [-1, 1), drawn into the start of the flat float32 ``into``."""
    s = rng.random((3, m), dtype=_F32, out=None if into is None else into[:3 * m].reshape(3, m))
    s *= _F32(2)
    s -= _F32(1)
    return s


def _paper_offsets(rng: np.random.Generator, m: int, work: _Scratch) -> np.ndarray:
    """(3, m) normalised positions: eq. 4.2-4.7 draws, rejected and redrawn in batches."""
    out = work.offsets[:3 * m].reshape(3, m)
    filled = 0
    for _ in range(MAX_ROUNDS):
        need = m - filled
        if need == 0:
            return out
        d = need + need // 3 + 16  # over-draw for the ~23 % rejected
        s = _uniform_offsets(rng, d, work.draws)
        rows = work.rows[:, :d]
        _phase_shift(s, rows)
        worst, other = rows[0], rows[1]
        np.abs(s[0], out=worst)
        np.maximum(worst, np.abs(s[1], out=other), out=worst)
        np.maximum(worst, np.abs(s[2], out=other), out=worst)
        inside = np.less_equal(worst, 1, out=work.mask[:d])
        # the first ``need`` kept draws, straight into ``out``: one nonzero for the three axes, and
        # take with mode="clip" (the indices are in range), which does not buffer ``out`` as
        # compress (take's "raise") does
        kept = np.flatnonzero(inside)[:need]
        take = len(kept)
        for axis in range(3):
            np.take(s[axis], kept, out=out[axis, filled:filled + take], mode="clip")
        filled += take
    if filled < m:  # cannot happen with CLUMP as set: acceptance is ~77 %
        raise RuntimeError("rejection sampling did not converge")
    return out


def _phase_shift(s: np.ndarray, rows: np.ndarray | None = None) -> None:
    """Eq. 4.5-4.7 in place, with phase angle theta = pi*s so a cube spans one period; ``rows``:
    five rows as long as ``s`` for the temporaries.

    Algebraically x += k*(pi/2 sin(theta_y/2) + pi sin(P_x theta_z/2)), with the
    constants folded and in-place ufuncs: this is the hot loop, and every extra
    pass over the batch costs about as much as a sine.
    """
    x, y, z = s
    if rows is None:
        rows = np.empty((5, x.shape[0]), x.dtype)
    half_theta_z, z_term, tmp, sine_y, sine_x = rows
    k = CLUMP / math.pi                              # eq. 4.7, scaled to the cube
    np.multiply(z, _HALF_PI, out=half_theta_z)
    np.multiply(half_theta_z, _HALF_PI, out=z_term)  # multiplies sin(theta/2) in eq. 4.6's argument
    for source, sine in ((y, sine_y), (x, sine_x)):  # both before either coordinate moves
        np.multiply(source, _HALF_PI, out=sine)
        np.sin(sine, out=sine)                       # eq. 4.5: P = pi/2 sin(0.5 theta_other)
    for moved, sine in ((x, sine_y), (y, sine_x)):
        np.multiply(sine, z_term, out=tmp)           # P * theta_z / 2
        np.sin(tmp, out=tmp)
        tmp *= _F32(k * math.pi)                     # eq. 4.6 (for y: P_y as meant, not P_x)
        moved += tmp
        sine *= _F32(k * math.pi / 2)
        moved += sine
    np.sin(half_theta_z, out=half_theta_z)
    half_theta_z *= _F32(k * math.pi / 2)            # P_z = pi/2 sin(0.5 theta_z)
    z += half_theta_z
