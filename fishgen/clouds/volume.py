"""A lit particle cloud as a sparse voxel volume: a density grid and a light grid, in 8^3 leaves.

Each particle is the Gaussian the lighting casts shadows with (``fishgen.clouds.light``): width
``sigma = SIGMA x radius``, cut at ``CUT`` sigma, and a column through its centre whose optical
depth is ``peak_optical_depth(density, extinction)``. As a 3-D extinction field that is
``peak / (sigma sqrt(2 pi)) exp(-|x - c|^2 / 2 sigma^2)`` per unit length, so a renderer that
reads the ``density`` grid as extinction per world unit sees the optical depths the baked light
was computed with. A voxel holds the field's mean over its cube (products of per-axis ``erf``
differences): a particle narrower than a voxel keeps its whole mass. The ``light`` grid is the
baked sunlight (``_LIGHT``) averaged over the particles reaching a voxel, weighted by their
density there. Voxel ``(i, j, k)`` is centred at ``voxel_size x (i, j, k)``.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from fishgen.clouds.model import DEFAULT_VOXEL_SIZE, MAX_VOXELS
from fishgen.errors import FishgenError

__all__ = ["DEFAULT_VOXEL_SIZE", "MAX_VOXELS", "Volume", "particle_volume", "voxel_box"]

LEAF = 8
"""Voxels along a leaf's side (OpenVDB's and NanoVDB's 8^3 leaves)."""
TILE = 32
"""Particles are splatted in runs of neighbours from tiles of this many voxels a side."""
SPARSE = 2
"""A chunk whose box holds more than this many voxels per footprint voxel is added in place
(``np.add.at``) rather than summed over its box (``np.bincount``): about where they cost the same."""
CHUNK = 1 << 20
"""Footprint voxels evaluated at a time: the splat's temporaries stay about 40 MB."""


@dataclass(frozen=True)
class Volume:
    """Sparse float grids sharing one topology. ``origins`` (L, 3) int32 are the leaves' first
    voxels (multiples of 8), ``active`` (L, 8, 8, 8) bool the voxels any particle reaches, and
    ``grids`` (name, (L, 8, 8, 8) float32 indexed ``[x, y, z]``) their values, 0 where inactive."""

    voxel_size: float
    origins: np.ndarray
    active: np.ndarray
    grids: tuple[tuple[str, np.ndarray], ...]

    @property
    def voxel_count(self) -> int:
        return int(np.count_nonzero(self.active))


def voxel_box(lo, hi, voxel_size: float, where=None) -> tuple[np.ndarray, np.ndarray]:
    """The leaf-aligned voxel index box ``[first, last)`` covering world ``lo``..``hi``; refused
    (FishgenError) above ``MAX_VOXELS`` or beyond int32 indices, before anything is allocated."""
    with np.errstate(over="ignore", invalid="ignore"):  # a tiny voxel overflows: refused just below
        lo_v = np.floor(np.asarray(lo, np.float64) / voxel_size + 0.5)
        hi_v = np.floor(np.asarray(hi, np.float64) / voxel_size + 0.5)
        total = math.prod(float(n) for n in hi_v - lo_v + 1)  # Python floats: inf, never a warning
    limit = 2.0 ** 30
    if not np.all(np.isfinite([lo_v, hi_v])) or math.isnan(total):
        total = math.inf
    far = float(np.abs(np.concatenate([np.ravel(lo), np.ravel(hi)]).astype(np.float64)).max())
    reach = far / limit * 1.001           # the least voxel whose indices reach the farthest corner
    if total <= MAX_VOXELS and (np.abs(lo_v).max() > limit or np.abs(hi_v).max() > limit):
        # few voxels, but so far from the origin that a grid's 32-bit indices cannot reach them
        raise FishgenError(f"expected a volume within 2^30 voxels of the origin (a grid's indices), "
                           f"found it {far:.6g} from the origin at voxel size {voxel_size:g}; use "
                           f"--voxel-size {_rounded_up(reach)} or more, or a cloud nearer the origin",
                           where)
    if not total <= MAX_VOXELS:
        least = max(_least_voxel_size(np.asarray(hi, np.float64) - np.asarray(lo, np.float64)), reach)
        found = (f"{total:,.0f}" if total < 1e15 else f"about {total:.2g}" if math.isfinite(total)
                 else "too many to count")
        raise FishgenError(f"expected at most {MAX_VOXELS:,} voxels in the volume's bounding box, found "
                           f"{found} at voxel size {voxel_size:g}; use --voxel-size {_rounded_up(least)} "
                           "or more", where)
    first = (np.floor_divide(lo_v, LEAF) * LEAF).astype(np.int64)
    last = ((np.floor_divide(hi_v, LEAF) + 1) * LEAF).astype(np.int64)
    return first, last


def _rounded_up(size: float) -> str:
    """``size`` to three significant figures, rounded up: a suggested voxel size that is met."""
    if not (math.isfinite(size) and size > 0):
        return f"{size:.3g}"
    step = 10.0 ** (math.floor(math.log10(size)) - 2)
    return f"{math.ceil(size / step * (1 - 1e-12)) * step:.3g}"


def _least_voxel_size(sides: np.ndarray) -> float:
    """About the smallest voxel side giving a box of ``sides`` at most ``MAX_VOXELS`` (bisection,
    with a voxel of rounding each way per axis)."""
    if not np.all(np.isfinite(sides)):
        return math.inf
    lo, hi = 0.0, max(float(sides.max()), 1e-30)
    for _ in range(100):
        mid = (lo + hi) / 2
        lo, hi = (lo, mid) if float(np.prod(sides / mid + 2)) <= MAX_VOXELS else (mid, hi)
    return hi


def check_cube_files(files, offsets, voxel_size: float, where=None) -> None:
    """Refuse, before filling, a volume of these cube files (``CubeFile``s, placed at ``offsets``
    or all at the origin) whose bounding box would hold more than ``MAX_VOXELS``: every particle
    lies in its cube, and reaches at most its cube's maximum radius further."""
    # a file may hold 100,000 cubes: their boxes as arrays, not one numpy call per cube
    cubes = [(c, k) for k, f in enumerate(files) for c in f.cubes if c.particles]
    if not cubes:
        return
    shifts = np.array([offsets[k] if offsets else (0.0, 0.0, 0.0) for _, k in cubes], np.float64)
    centres = np.array([c.centre for c, _ in cubes], np.float64) + shifts
    half = (np.array([c.size for c, _ in cubes], np.float64) / 2
            + reach(np.array([c.max_radius for c, _ in cubes], np.float64))[:, None])
    voxel_box((centres - half).min(axis=0), (centres + half).max(axis=0), voxel_size, where)


def reach(radii) -> np.ndarray:
    """How far each particle's footprint reaches from its centre along an axis."""
    from fishgen.clouds.light import CUT
    from fishgen.clouds.sprite import SIGMA

    return np.asarray(radii, np.float64) * (SIGMA * CUT)


def particle_volume(centers: np.ndarray, radii: np.ndarray, density: np.ndarray, light: np.ndarray | None,
                    extinction: float, voxel_size: float, where=None,
                    advance: Callable[[int], None] | None = None) -> Volume:
    """Splat particles (world ``centers``, ``radii``, ``density``, baked ``light`` or None) into
    a ``density`` grid (extinction per world unit) and, when lit, a ``light`` grid; ``advance(k)``
    as each k particles are splatted (a progress bar's: 10^6 particles took 20 s at the default
    voxel size)."""
    from fishgen.clouds.light import peak_optical_depth
    from fishgen.clouds.sprite import SIGMA

    if not voxel_size > 0:
        raise FishgenError(f"expected a voxel size above 0, found {voxel_size!r}", where)
    if len(centers) == 0:
        raise FishgenError("expected at least 1 particle to make a volume of, found 0", where)
    c = np.asarray(centers, np.float64)
    far = reach(radii)
    first, last = voxel_box((c - far[:, None]).min(0), (c + far[:, None]).max(0), voxel_size, where)
    shape = tuple(int(v) for v in last - first)
    sigma = np.asarray(radii, np.float64) * SIGMA
    # voxel mean of peak/(sigma sqrt(2 pi)) e^(-r^2/2 sigma^2): peak 2 pi sigma^2 / vs^3 x the
    # product of the per-axis shares of a unit Gaussian's mass in the voxel
    scale = peak_optical_depth(density, extinction) * (2 * math.pi) * sigma ** 2 / voxel_size ** 3
    start = np.floor((c - far[:, None]) / voxel_size + 0.5).astype(np.int64)
    stop = np.floor((c + far[:, None]) / voxel_size + 0.5).astype(np.int64)
    width = (stop - start + 1).max(1)
    total = np.zeros(shape, np.float32)
    lit = np.zeros_like(total) if light is not None else None
    grids = [(total, None)] if lit is None or light is None else [(total, None), (lit, light)]
    # equal widths together (one padded block each), neighbours together within (by tiles of
    # TILE voxels), so a chunk's footprints mostly fill a small box that one bincount sums
    tile = (start - first) // TILE
    order = np.lexsort((tile[:, 2], tile[:, 1], tile[:, 0], width))
    bounds = np.flatnonzero(np.diff(width[order])) + 1
    for group in np.split(order, bounds):
        k = int(width[group[0]])
        step = max(1, CHUNK // k ** 3)
        for at in range(0, len(group), step):
            members = group[at:at + step]
            cells, shares = _footprints(c[members], sigma[members], far[members], start[members],
                                        stop[members], k, first, shape, voxel_size)
            low = [int(a[:, 0].min()) for a in cells]
            box = [int(a[:, -1].max()) + 1 - lo for a, lo in zip(cells, low, strict=True)]
            size = box[0] * box[1] * box[2]
            sparse = size > SPARSE * len(members) * k ** 3  # footprints scattered in a big box
            if sparse:                                      # index the whole grid, add in place
                low, box = [0, 0, 0], list(shape)
            x, y, z = (a - lo for a, lo in zip(cells, low, strict=True))
            rows_y = (x * box[1])[:, :, None] + y[:, None, :]                       # (n, k, k)
            index = (rows_y[..., None] * box[2] + z[:, None, None, :]).ravel()
            plane = shares[1][:, :, None] * shares[2][:, None, :]                      # (n, k, k)
            rows = shares[0] * scale[members, None]
            for grid, carried in grids:
                weight = rows if carried is None else rows * np.asarray(carried, np.float64)[members, None]
                values = (weight[:, :, None, None] * plane[:, None]).ravel()
                if sparse:
                    np.add.at(grid.reshape(-1), index, values.astype(np.float32))
                else:
                    part = tuple(slice(lo, lo + b) for lo, b in zip(low, box, strict=True))
                    grid[part] += np.bincount(index, values, size).reshape(box).astype(np.float32)
            if advance is not None:
                advance(len(members))
    volume = _leaves(total, lit, first, voxel_size)
    if not len(volume.origins):  # every particle's mass per voxel underflowed float32
        raise FishgenError(f"expected a voxel of density above 0, found none at voxel size {voxel_size:g}; "
                           "use a smaller --voxel-size", where)
    return volume


def _footprints(c, sigma, far, start, stop, k, first, shape, voxel_size):
    """Per axis, each particle's ``k`` footprint cells (n, k), counted from the grid's ``first``
    voxel, and the share of its Gaussian's mass in each (0 in the padding of particles narrower
    than ``k``, whose cells stop at the grid's edge)."""
    steps = np.arange(k)
    cells, shares = [], []
    root2s = math.sqrt(2) * sigma[:, None]
    for axis in range(3):
        cell = start[:, axis, None] + steps[None, :]                     # (n, k) voxel indices
        lo = np.maximum((cell - 0.5) * voxel_size, (c[:, axis] - far)[:, None])
        hi = np.minimum((cell + 0.5) * voxel_size, (c[:, axis] + far)[:, None])
        share = 0.5 * (erfc((lo - c[:, axis, None]) / root2s) - erfc((hi - c[:, axis, None]) / root2s))
        share[cell > stop[:, axis, None]] = 0.0
        cells.append(np.minimum(cell - first[axis], shape[axis] - 1))
        shares.append(share)
    return cells, shares


def erfc(x: np.ndarray) -> np.ndarray:
    """The complementary error function, to a relative 1.2e-7 everywhere (Numerical Recipes'
    ``erfcc``, a Chebyshev fit): scipy.special takes a second to import."""
    z = np.abs(x)
    t = 1 / (1 + 0.5 * z)
    poly = 0.17087277
    for a in (-0.82215223, 1.48851587, -1.13520398, 0.27886807, -0.18628806, 0.09678418, 0.37409196,
              1.00002368, -1.26551223):
        poly = a + t * poly
    tail = t * np.exp(-z * z + poly)
    return np.where(x >= 0, tail, 2 - tail)


def _leaves(total: np.ndarray, lit: np.ndarray | None, first: np.ndarray, voxel_size: float) -> Volume:
    """The 8^3 blocks of the dense box holding any active voxel, in x, y, z block order."""
    blocks = tuple(s // LEAF for s in total.shape)

    def blocked(a: np.ndarray) -> np.ndarray:
        return a.reshape(blocks[0], LEAF, blocks[1], LEAF, blocks[2], LEAF).transpose(0, 2, 4, 1, 3, 5)

    dense = blocked(total)
    on = dense > 0
    keep = on.any(axis=(3, 4, 5))
    where = np.argwhere(keep)
    origins = (first[None, :] + where * LEAF).astype(np.int32)
    density = np.ascontiguousarray(dense[keep])
    active = np.ascontiguousarray(on[keep])
    grids: list[tuple[str, np.ndarray]] = [("density", density)]
    if lit is not None:
        light = np.zeros_like(density)
        np.divide(blocked(lit)[keep], density, out=light, where=active)
        grids.append(("light", light))
    return Volume(float(voxel_size), origins, active, tuple(grids))
