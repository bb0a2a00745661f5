"""Seeded 3D gradient noise for cloud detail (report section 6.4 c): Perlin's improved noise, vectorised.

Perlin (2002), "Improving noise": a lattice of pseudo-random gradients (12 cube-edge directions,
picked by a permutation table), each corner's dot product with the offset to the point, blended
with the quintic fade 6t^5 - 15t^4 + 10t^3. The permutation is drawn from the seed, so one seed
gives one noise field, bit for bit. ``fbm`` sums octaves (fractional Brownian motion, as Ebert et
al. 2002 build cloud detail from noise). Values lie in [-1, 1].

:func:`roughen` applies it to a filled cloud: each particle's radius and density are scaled by two
independent fields sampled at its position, so neighbouring particles change alike (the detail is
spatially coherent) and two clouds from one cube file, given other seeds, differ.

Points are processed in chunks of 65,536 (all temporaries chunk-sized, float64 for the lattice
arithmetic: a cloud 10^5 units across still resolves its noise cells).
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from fishgen.clouds.model import Cloud

CHUNK = 1 << 16
_GRADIENTS = np.array([[1, 1, 0], [-1, 1, 0], [1, -1, 0], [-1, -1, 0], [1, 0, 1], [-1, 0, 1], [1, 0, -1],
                       [-1, 0, -1], [0, 1, 1], [0, -1, 1], [0, 1, -1], [0, -1, -1]], np.float64)
"""Perlin's 12 gradients (the cube's edge midpoints)."""
PEAK = 1.0
"""Improved noise stays within [-1, 1] with these gradients (its proven bound is about 1.04 in
theory for arbitrary gradients; the edge set reaches about 1.0); :func:`perlin3` clips to it."""
CONTRAST = np.float32(2.0)
"""fBm of two octaves has a standard deviation of about 0.2: :func:`roughen` doubles it (clipped to
[-1, 1]), so ``amount`` 0.5 changes a typical radius by about 20 %."""
MAX_AMOUNT = 0.9
"""The most a field may scale a radius by (1 +- amount): radii stay positive."""


def permutation(seed: int) -> np.ndarray:
    """The noise's lattice hash for ``seed``: a permutation of 0..255, repeated (512 entries)."""
    perm = np.random.default_rng([int(seed), 0x6E6F697365]).permutation(256)   # "noise"
    return np.concatenate([perm, perm]).astype(np.intp)


def perlin3(points: np.ndarray, perm: np.ndarray, fields: int = 1) -> np.ndarray:
    """Improved Perlin noise at ``points`` (N, 3): float32 (fields, N) in [-1, 1] (or (N,) for one
    field), 0 at every lattice point. Field ``k`` > 0 picks its gradients by the corner's hash
    hashed again (shifted by ``k x REHASH``): independent fields for the cost of one lattice walk."""
    if not 1 <= fields <= (len(perm) - 256) // REHASH:
        raise ValueError(f"fields must be within 1 .. {(len(perm) - 256) // REHASH}, not {fields}")
    points = np.asarray(points, np.float64)
    out = np.empty((fields, len(points)), np.float32)
    starts = range(0, len(points), CHUNK)

    def work(start: int) -> None:
        out[:, start:start + CHUNK] = _perlin_chunk(points[start:start + CHUNK], perm, fields)

    _each(work, starts)
    return out[0] if fields == 1 else out


def _each(work, starts) -> None:
    """``work(start)`` for every chunk, on all cores (numpy releases the GIL in its loops)."""
    import os
    from concurrent.futures import ThreadPoolExecutor

    threads = min(os.cpu_count() or 1, len(starts))
    if threads <= 1:
        for start in starts:
            work(start)
        return
    with ThreadPoolExecutor(threads) as pool:
        list(pool.map(work, starts))


REHASH = 101
"""Field k > 0 hashes each corner's hash again, shifted by k x REHASH (within the 512-entry table)."""
_GX, _GY, _GZ = (np.ascontiguousarray(_GRADIENTS[:, k], np.float32) for k in range(3))
_MOD12 = (np.arange(512 + 16) % 12).astype(np.intp)


def _perlin_chunk(p: np.ndarray, perm: np.ndarray, fields: int) -> np.ndarray:
    cell = np.floor(p)
    f = (p - cell).astype(np.float32)                               # (n, 3) in [0, 1)
    i = cell.astype(np.int64) & 255
    fx, fy, fz = f[:, 0], f[:, 1], f[:, 2]
    six, fifteen, ten = np.float32(6), np.float32(15), np.float32(10)
    ux, uy, uz = (t * t * t * (t * (t * six - fifteen) + ten) for t in (fx, fy, fz))
    x, y, z = i[:, 0], i[:, 1], i[:, 2]
    a = perm[x] + y
    b = perm[x + 1] + y
    hashes = [perm[perm[a] + z], perm[perm[a] + z + 1], perm[perm[a + 1] + z], perm[perm[a + 1] + z + 1],
              perm[perm[b] + z], perm[perm[b] + z + 1], perm[perm[b + 1] + z], perm[perm[b + 1] + z + 1]]
    one = np.float32(1)
    gx_, gy_, gz_ = (fx - one, fy - one, fz - one)
    offsets = [(fx, fy, fz), (fx, fy, gz_), (fx, gy_, fz), (fx, gy_, gz_),
               (gx_, fy, fz), (gx_, fy, gz_), (gx_, gy_, fz), (gx_, gy_, gz_)]   # corner order: x, y, z bits
    out = np.empty((fields, len(p)), np.float32)
    for k in range(fields):
        dots = []
        for h, (ox, oy, oz) in zip(hashes, offsets, strict=True):
            g = _MOD12[perm[h + REHASH * k] if k else h]
            d = _GX[g] * ox
            d += _GY[g] * oy
            d += _GZ[g] * oz
            dots.append(d)
        # trilinear blend with the fade weights: z, then y, then x
        zs = [d0 + uz * (d1 - d0) for d0, d1 in zip(dots[0::2], dots[1::2], strict=True)]
        ys = [z0 + uy * (z1 - z0) for z0, z1 in zip(zs[0::2], zs[1::2], strict=True)]
        np.clip(ys[0] + ux * (ys[1] - ys[0]), -PEAK, PEAK, out=out[k])
    return out


def fbm(points: np.ndarray, perm: np.ndarray, octaves: int = 2, gain: float = 0.5,
        fields: int = 1) -> np.ndarray:
    """Octaves of :func:`perlin3` at doubling frequency and ``gain`` times the amplitude, divided
    by the sum of the amplitudes: float32 in [-1, 1], (fields, N) or (N,). Each octave is shifted by
    an irrational offset, so the lattice zeros of one octave do not line up with the next's."""
    points = np.asarray(points, np.float64)
    total = np.zeros((fields, len(points)), np.float32)
    amplitude, weight = 1.0, 0.0
    for k in range(octaves):
        shift = np.array([0.5 * math.sqrt(2), 0.5 * math.sqrt(3), 0.5 * math.sqrt(5)]) * k
        total += np.float32(amplitude) * perlin3(points * 2.0**k + shift, perm, fields).reshape(fields, -1)
        weight += amplitude
        amplitude *= gain
    total /= np.float32(weight)
    return total[0] if fields == 1 else total


def roughen(cloud: Cloud, amount: float, *, seed: int, scale: float, origin=(0.0, 0.0, 0.0)) -> Cloud:
    """``cloud`` with radii times ``1 + amount x n1`` and densities times ``1 + amount x n2``
    (clipped to (0, 1]), n1 and n2 two seeded :func:`fbm` fields of feature size ``scale`` (world
    units) sampled at each particle's position relative to ``origin``. ``amount`` 0 returns the
    cloud as it is; at most :data:`MAX_AMOUNT`."""
    if not 0 <= amount <= MAX_AMOUNT:
        raise ValueError(f"amount must be within 0 .. {MAX_AMOUNT}, not {amount}")
    if not (scale > 0 and math.isfinite(scale)):
        raise ValueError(f"scale must be a positive number, not {scale}")
    if amount == 0 or len(cloud) == 0:
        return cloud
    perm = permutation(seed)
    where = (np.asarray(cloud.centers, np.float64) - np.asarray(origin, np.float64)) / scale
    # two independent fields from one walk of the lattice
    sizes, densities = np.clip(CONTRAST * fbm(where, perm, fields=2), -1, 1)
    radii = cloud.radii * (np.float32(1) + np.float32(amount) * sizes)
    density = cloud.density * (np.float32(1) + np.float32(amount) * densities)
    np.clip(density, np.finfo(np.float32).tiny, 1, out=density)
    return replace(cloud, radii=radii.astype(np.float32), density=density.astype(np.float32))
