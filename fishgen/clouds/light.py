"""Sunlight reaching each particle: Harris's first pass (multiple forward scattering), on the CPU.

Harris (2002) sorts the particles away from the sun and splats them one at a time into
a frame buffer seen from the sun, reading back before each splat the light that
reaches the next particle (report eq. 3.12):

    I_k = T_(k-1) I_(k-1) + g_(k-1)    what the particle nearer the sun lets through,
                                        plus what it scatters forward.

Here the recurrence is taken along each ray: optical depth d on the way passes on
``e^-d`` of the light straight through and ``F (1 - e^-d)`` of it scattered forward, F
being the lighting's forward fraction (SkyWorks: albedo x extinction x p(0) x solid angle
/ 4 pi). So the light never exceeds the sun, scattering only adds to it, and with
scattering off a particle's light is ``exp(-tau)`` of the optical depth towards the sun, with a
faint share of light scattered many times that keeps it above 0 (``light_of_depth``). A
particle's optical depth across the rays is a Gaussian of width ``sigma = SIGMA x radius``
(the billboard sprite's), whose total equals the shadow of SkyWorks' splat
(``peak_optical_depth``).

A small cloud needs no grid: each particle's light comes from every other particle's
Gaussian, each shading it as far as it lies nearer the sun (``_pairs``). So does a bigger one
strung out across the sun's rays, whose pairs within reach are as few as a small cloud's. A big
one goes through a grid across the sun's rays (a deep shadow map) in *slabs* along the sun axis,
nearest the sun first, its footprints cut at ``CUT`` sigma: up to ``SLABS`` slabs of
about equal count, splatted as points into a few width classes, each blurred with its
own Gaussian (separable, mass-preserving); its particles are visited in memory order,
never in depth order (see ``_slabs``). The order is a stable sort and every sum runs in
a fixed order, so the result does not depend on the number of threads.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace

import numpy as np

from fishgen.clouds.lighting import DIFFUSE, Lighting
from fishgen.clouds.model import Cloud
from fishgen.clouds.sprite import SIGMA

SLABS = 128
"""Most slabs along the sun axis for a big cloud (more than SMALL particles): one per
SLAB_PARTICLES particles, at least FEW_SLABS (each costs an FFT of the grid, ~1 ms)."""
FEW_SLABS = 32
SLAB_PARTICLES = 64
"""A big cloud gets a slab per this many particles, up to SLABS. With a particle's light read at
its face, a sigma sunward, slabs of hundreds of particles (one per 2,048, at least 32) left
9,582 particles of random cube file 201 ranked 0.71 against the optical depth there; 128 slabs
0.92."""
SMALL = 2048
"""Up to this many particles a cloud is lit pair by pair (``_pairs``), with no grid."""
SPARSE = 16384
"""Up to this many particles a cloud is also lit pair by pair when its pairs within reach across
the rays are no more than a cloud of SMALL particles can have (``_pair_axis``): a cloud strung out
across the sun's rays, whose grid cells are too wide for its particles."""
REACH = 8.0
"""In a small cloud a particle shades the others within REACH x its sigma of its centre across the
sun's rays, and those less than that farther from the sun: beyond, its Gaussian is under e^-32 of
its peak, below anything float32 light can show (the grid of a big cloud cuts at CUT)."""
FRONT = 1.0
"""A small cloud's particle takes its light FRONT x its own sigma nearer the sun than its centre:
at the face its billboard turns to the sun. At its centre, half shaded by every neighbour at its
own depth, Table 4.2's dense clouds turned an even grey with no sunlit side; Harris's recurrence,
which reads the light as it arrives at the particle, left them 20-50x brighter than exp(-tau)."""
PAIRS = 1 << 19
"""Most pairs of a small cloud weighed at once (a few float64 arrays of this many)."""
CDF_STEPS = 1 << 14
"""Steps of the normal CDF's table over -REACH..REACH (linear interpolation: within 3e-8)."""
GRID = 256
"""Most cells along a side of a big cloud's light grid. Only a cloud wider than GRID /
CELLS_PER_SIGMA typical particle widths across the sun's rays reaches it (cube files strung out
along one direction, seen from the side): with 96, those cells grew wider than the particles,
their shadows fell on neighbours they did not cover, and the light's rank correlation with the
optical depth towards the sun fell to 0.67-0.8 (issue 32)."""
CELLS_PER_SIGMA = 2.5
LONGEST = 4
"""How many times GRID cells a big cloud's light grid may have along its longer side."""
"""Grid cells across the Gaussian width of the median particle, where the grid allows."""
CLASSES = 4
"""Width classes of a big slab's splat: sigma_max / 2^c, c = 0..3; narrower particles share the last."""
CUT = 3.0
"""A footprint ends at CUT x sigma (holding 98.9 % of its optical depth)."""
WORKERS = 2
"""Threads for a big cloud's passes (the machine this runs on has 2 cores)."""
BLUR_SLABS = 8
"""Slabs blurred in one FFT call."""
MAP_VALUES = 1 << 23
"""Most map values (slabs x classes x cells) held at once; a finer grid goes in groups of slabs."""
SPARSE_SPLATS = 16
"""A group's splats are kept as sums by cell, not as whole maps, where its maps hold more than
this many values a particle: a cloud of 9,000 particles filled and added two maps of 8 million
float64 values for each light (0.1-0.26 s of its 0.4-0.7 s), nearly all of them zero."""


LEAD = 0.4
"""How many of its sigmas nearer the sun than its centre the slabs read a particle's light, at
every size: what a particle's colour stands for is the light at its sunward face (FRONT sigma
ahead), which the pairs take exactly, each neighbour shading by its smooth Phi. The slabs count a
neighbour ahead or not (a step), which misses the sunward tails of the neighbours just behind the
face: read at the face, the shipped tables' mean light at 2,049 particles was 1.9-2.1x the pairs'
at 2,048 (10-20x the reference's with scattering off); 0.3 sigma gave 0.84-0.95x, 0.4 gives
0.97-1.10x, 0.5 1.10-1.25x. It used to fade out by 8,192 particles, to keep the rank against the
optical depth at the centre; the reference now takes it at the face, as the colour does."""


def slab_count(n: int) -> int:
    """How many slabs a big cloud of ``n`` particles goes through by default."""
    return min(n, SLABS, max(FEW_SLABS, n // SLAB_PARTICLES))


def slab_lead(n: int) -> float:
    """How many sigmas nearer the sun than its centre a cloud of ``n`` particles lit through slabs
    reads a particle's light: LEAD, whatever the size (``n`` is kept for callers)."""
    return LEAD


CROWDING = 48.0
"""Most optical depth a cloud's particles may put, on the mean, across one sigma-wide stretch at
a particle's centre (``crowding``): past it every particle's shadow is scaled down alike, so a
cloud holds its optical depth per volume, and more particles in the same cubes make it finer, not
darker. Table 4.2, the densest of the report's clouds, is 34.8-38.7 over fill seeds 0-11 (its
estimate on CROWD_SAMPLE particles 35-39.7), so 48 leaves the report's tables lit as before at any
seed. A 7x3x3 box of particles of radius 2 is 18 at 615 particles, 250 at 8,000."""
CROWD_SAMPLE = 512
"""Particles (evenly spaced in the input) the crowding of a bigger cloud is estimated on."""


def crowding(centers: np.ndarray, radii: np.ndarray, density: np.ndarray, extinction: float) -> float:
    """How crowded a cloud is: the mean over its particles of the optical depth the other
    particles put along a stretch of sqrt(2 pi) x its sigma through its centre, each a 3D Gaussian
    of width sigma and column depth ``peak_optical_depth``. 0 for one particle.

    Up to CROWD_SAMPLE particles it is exact; a bigger cloud is estimated on that many particles
    evenly spaced in the input, each pair counted n - 1 / (sample - 1) times (an unbiased mean)."""
    n = len(centers)
    if n < 2:
        return 0.0
    pick = np.unique(np.linspace(0, n - 1, min(n, CROWD_SAMPLE)).round().astype(np.intp))
    s = len(pick)
    p = centers[pick].astype(np.float64)
    p -= p.mean(axis=0)
    sigma = radii[pick].astype(np.float64) * SIGMA
    with np.errstate(divide="ignore"):
        inverse = np.where(sigma > 0, 1 / np.maximum(sigma, 1e-300), 0.0)
    peak = peak_optical_depth(density[pick], extinction) * inverse      # column / sigma_j
    total = 0.0
    rows = max(1, (1 << 18) // s)
    for start in range(0, s, rows):
        stop = min(s, start + rows)
        d2 = np.zeros((stop - start, s))
        for k in range(3):
            d2 += np.square(p[start:stop, k, None] - p[None, :, k])
        d2 *= np.square(inverse)[None, :]
        np.negative(d2, out=d2)
        d2 *= 0.5
        np.exp(d2, out=d2)
        d2[np.arange(stop - start), np.arange(start, stop)] = 0.0          # not itself
        d2 *= peak[None, :]
        total += float((d2.sum(axis=1) * sigma[start:stop]).sum())
    return total / s * (n - 1) / (s - 1)


def depth_share(centers: np.ndarray, radii: np.ndarray, density: np.ndarray, lighting: Lighting) -> float:
    """The share of its optical depth each particle of this cloud casts: 1 up to CROWDING, past it
    CROWDING / ``crowding`` (the cloud's optical depth per volume held there)."""
    crowd = crowding(centers, radii, density, lighting.extinction)
    return 1.0 if not crowd > CROWDING else CROWDING / crowd


KEY_LEVELS = 65535
CHUNK = 1 << 16
PEAK_LEVELS = 16384

_F32 = np.float32
_LEVELS = np.arange(PEAK_LEVELS + 1, dtype=np.float64)
SHARE_LEVELS = 65535
"""A particle's share of its slab nearer the sun is kept in 65535ths: a dense cloud's first slab
holds optical depths in the hundreds at a cell, and in 255ths its sunlit face read the light in
steps of 1, 0.53, 0.27."""


def light_cloud(cloud: Cloud, lighting: Lighting | None = None, *,
                advance: Callable[[int], None] | None = None) -> Cloud:
    """``cloud`` lit by the sun and the sky: its ``light`` per particle and the colours it gives.

    Light a scene after ``merge_clouds``, so its clouds shadow each other. ``advance`` as in
    :func:`incident_light`.
    """
    lighting = lighting or Lighting()
    light = incident_light(cloud.centers, cloud.radii, cloud.density, lighting, advance=advance)
    return replace(cloud, light=light, lighting=lighting, colors=lit_colors(light, lighting))


COLOR_LEVELS = 4096
"""Light is quantised to this many levels for its colour (an sRGB byte needs at most ~1,000)."""


def lit_colors(light: np.ndarray, lighting: Lighting) -> np.ndarray:
    """sRGB bytes (N, 3) of particles receiving ``light``: albedo x (sky + sun x light), linear,
    clamped to 1 (Harris's second pass seen from nowhere in particular: an even phase)."""
    from fishgen.numeric import linear_to_srgb

    level = np.linspace(0.0, 1.0, COLOR_LEVELS + 1)[:, None]
    linear = lighting.albedo * (np.array(lighting.sky_color) + np.array(lighting.sun_color) * level)
    table = np.zeros((COLOR_LEVELS + 1, 4), np.uint8)
    table[:, :3] = np.round(linear_to_srgb(np.clip(linear, 0, 1)) * 255)
    words = table.view(np.uint32).ravel()          # a colour a word: one gather a particle, not three
    light = np.asarray(light, _F32)
    out = np.empty((len(light), 3), np.uint8)
    into = out.view(_RGB_BYTES).ravel()
    for start in range(0, len(light), CHUNK):       # a chunk's temporaries stay in cache
        index = light[start:start + CHUNK] * _F32(COLOR_LEVELS)
        index += _F32(0.5)
        np.clip(index, 0, COLOR_LEVELS, out=index)
        into[start:start + CHUNK] = np.take(words, index.astype(np.int32)).view(_RGB_WORD)["rgb"]
    return out


_RGB_BYTES = np.dtype("V3")
_RGB_WORD = np.dtype({"names": ["rgb"], "formats": ["V3"], "offsets": [0], "itemsize": 4})
"""A packed sRGB colour, and the same three bytes as the first of a 32-bit word's four."""


def incident_light(centers: np.ndarray, radii: np.ndarray, density: np.ndarray,
                   lighting: Lighting | None = None, *, slabs: int | None = None,
                   grid_cells: int | None = None, share: float | None = None,
                   advance: Callable[[int], None] | None = None) -> np.ndarray:
    """The fraction of sunlight (0 to 1) reaching each particle's sunward face (FRONT sigma nearer
    the sun than its centre; the slabs read LEAD sigma ahead, which gives the same light), float32.

    ``centers`` (N, 3), ``radii`` (N,) and ``density`` (N,) as in :class:`fishgen.clouds.Cloud`.
    ``slabs``: go through that many slabs (at most N), whatever the size; by default a cloud of up
    to SMALL particles is lit pair by pair, and so is one of up to SPARSE whose pairs are as few
    (``_pair_axis``); a bigger one through FEW_SLABS to SLABS slabs.
    ``grid_cells``: at most that many cells along a side of the slabs' light map (default GRID).
    A sky, far wider than its clouds, needs more (fishgen.sky.light).
    ``share``: the share of its optical depth every particle casts (default ``depth_share`` of
    these particles: 1 unless the cloud is more crowded than CROWDING).
    ``advance(k)``, on the calling thread, as work is done: ``light_steps(N)`` in all (a progress
    bar's; the light weighs about twice the fill a particle).
    """
    lighting = lighting or Lighting()
    n = len(centers)
    done = _Done(advance, light_steps(n))
    light = np.zeros(n, _F32)
    if n == 0:
        return light
    if share is None:
        share = depth_share(centers, radii, density, lighting)
    share = float(share)
    frame = _frame(np.array(lighting.sun_unit, np.float64))   # rows: sun, across a, across b
    middle = _middle(centers)
    axis = (None if slabs is not None else 0 if n <= SMALL
            else _pair_axis(centers, radii, frame, middle) if n <= SPARSE else None)
    forward = _F32(lighting.forward_fraction)
    if axis is not None:
        _pairs(centers, radii, density, frame, middle, lighting.extinction, lighting.forward_fraction, light,
               share, axis=axis)
    else:
        count = slab_count(n) if slabs is None else max(1, min(n, int(slabs)))
        light = _slabs(centers, radii, density, frame, middle, count, lighting.extinction, forward, light,
                       grid_cells, lead=slab_lead(n), share=share, done=done)
    done.until(1.0)
    return light


def light_steps(n: int) -> int:
    """How far :func:`incident_light` advances for ``n`` particles."""
    return 2 * n


class _Done:
    """A progress counter fed in whole steps as shares of ``total`` are reached."""

    def __init__(self, advance: Callable[[int], None] | None, total: int):
        self.advance, self.total, self.given = advance, total, 0

    def until(self, share: float) -> None:
        """``share`` (0 to 1) of the work is done."""
        if self.advance is None:
            return
        target = min(self.total, int(self.total * share))
        if target > self.given:
            self.advance(target - self.given)
            self.given = target


def _pairs(centers, radii, density, frame, middle, extinction: float, forward: float, light,
           share: float = 1.0, axis: int = 0) -> None:
    """A small cloud, pair by pair: each particle's light from every other particle's Gaussian.

    Particle j's optical depth on the ray from particle i's centre towards the sun is its
    Gaussian across the rays, ``peak_j exp(-b^2 / 2 sigma_j^2)`` at i's distance b from j's
    centre, times the share of it that lies nearer the sun than i's sunward face (FRONT sigma_i
    nearer the sun than its centre), ``Phi((t - FRONT sigma_i) / sigma_j)``, t how much nearer j's
    centre is: a neighbour of i's size at i's own depth shades it 16 %, one a sigma nearer half.
    Harris's recurrence, one particle after another, gives a neighbour a hair nearer the sun its
    whole shadow and one a hair farther none; on clouds of a few hundred particles
    that ranked the light below 0.8 against the optical depth towards the sun (issue 32), and
    left the sunlit side of a dense cloud far brighter than exp(-tau) (20-50x in the mean on
    Table 4.2, scattering off). With scattering on, j's depth d on the ray passes on ``e^-d + F (1 -
    e^-d)`` of the light, F the forward fraction, as it does in the recurrence: an effective
    depth e(d), of which the same share Phi counts (as the slabs take half their own slab's).
    So with scattering off the light is exactly ``light_of_depth(tau)``.

    No grid: the particles sorted along ``axis`` across the rays (a or b), each block of them
    weighed against those within REACH of the widest sigma along it; every sum runs in that order,
    so the input's order changes nothing.
    """
    n = len(centers)
    p = centers.astype(np.float64) - middle
    x, y, z = p.T
    depth, a, b = (x * row[0] + y * row[1] + z * row[2] for row in frame)    # written out: no BLAS
    if axis:
        a, b = b, a
    order = np.lexsort((depth, b, a))
    depth, a, b = depth[order], a[order], b[order]
    sigma = radii[order].astype(np.float64) * SIGMA
    with np.errstate(divide="ignore"):                      # a particle of radius 0 shades nothing
        inverse = 1 / sigma
    peak = peak_optical_depth(density[order], extinction)
    if share != 1.0:
        peak *= share
    reach = REACH * float(sigma.max())
    tau = np.empty(n)
    rows = max(1, PAIRS // n)
    for start in range(0, n, rows):
        stop = min(n, start + rows)
        first = int(np.searchsorted(a, a[start] - reach, "left"))
        last = int(np.searchsorted(a, a[stop - 1] + reach, "right"))
        with np.errstate(over="ignore", invalid="ignore"):
            # each pair (i of the block, j of the window) in units of j's sigma: how far apart
            # across the rays, squared, and how much nearer the sun j is
            across = np.square(a[None, first:last] - a[start:stop, None])
            across += np.square(b[None, first:last] - b[start:stop, None])
            across *= np.square(inverse[first:last])
            along = depth[None, first:last] - depth[start:stop, None]
            along -= FRONT * sigma[start:stop, None]
            along *= inverse[first:last]
            near = (across < REACH * REACH) & (along > -REACH)
        i, j = np.nonzero(near)
        other = j + first != i + start
        i, j = i[other], j[other]
        shade = np.exp(-0.5 * across[i, j])
        shade *= peak[j + first]
        if forward > 0:                  # the effective depth: e^-e = e^-d + F (1 - e^-d)
            shade = -np.log1p((1 - forward) * np.expm1(-shade))
        shade *= _normal_cdf(along[i, j])
        tau[start:stop] = np.bincount(i, shade, minlength=stop - start)
    light[order] = light_of_depth(tau.astype(_F32))


def _pair_axis(centers, radii, frame, middle) -> int | None:
    """The axis across the rays (0: a, 1: b) along which ``_pairs`` would weigh the fewest pairs of
    this cloud, if they are at most SMALL x SMALL (what a cloud of SMALL particles may cost); else
    None. The same windows as ``_pairs``, counted, not weighed: two sorts."""
    n = len(centers)
    x, y, z = (centers.astype(np.float64) - middle).T
    reach = REACH * SIGMA * float(radii.max())
    rows = max(1, PAIRS // n)
    starts = np.arange(0, n, rows)
    stops = np.minimum(starts + rows, n)
    work = []
    for row in frame[1:]:
        across = np.sort(x * row[0] + y * row[1] + z * row[2])      # as ``_pairs`` writes it
        first = np.searchsorted(across, across[starts] - reach, "left")
        last = np.searchsorted(across, across[stops - 1] + reach, "right")
        work.append(int(((stops - starts) * (last - first)).sum()))
    best = int(np.argmin(work))
    return best if work[best] <= SMALL * SMALL else None


def _normal_cdf(z: np.ndarray) -> np.ndarray:
    """The standard normal CDF at ``z`` (float64, 1 above REACH), from a table of CDF_STEPS."""
    table = _cdf_table()
    u = z + REACH
    u *= CDF_STEPS / (2 * REACH)
    np.clip(u, 0, CDF_STEPS, out=u)
    k = np.minimum(u.astype(np.intp), CDF_STEPS - 1)
    u -= k
    low = table[k]
    return low + (table[k + 1] - low) * u


@functools.lru_cache(maxsize=1)
def _cdf_table() -> np.ndarray:
    """The standard normal CDF at CDF_STEPS + 1 points over -REACH..REACH (math.erfc: scipy is
    slow to import), the last made exactly 1."""
    steps = np.linspace(-REACH, REACH, CDF_STEPS + 1).tolist()
    table = np.array([0.5 * math.erfc(-v / math.sqrt(2)) for v in steps])
    table[-1] = 1.0
    return table


def _slabs(centers, radii, density, frame, middle, slabs: int, extinction, forward, light,
           grid_cells: int | None, lead: float = 0.0, share: float = 1.0,
           done: _Done | None = None) -> np.ndarray:
    """A big cloud, in ``slabs`` slabs along the sun axis, all read from and splatted into one
    light map.

    Here a particle passes on the light at each cell as it arrives there (Harris: as it
    arrives at the particle's centre): ``e^-d + F (1 - e^-d)`` of it, d its optical depth
    at that cell. That factor is ``e^-e`` for an *effective* depth e(d) <= d, so a slab's
    particles only need their effective depths summed: each splatted as a Gaussian of the
    same total (``_effective_table``), as a point into its width class, and the class maps
    blurred. A particle also sits behind the part of its own slab nearer the sun, so it reads
    the light before its slab passed through that share of the slab's depth at its centre, less
    its own: the share of the slab's particles nearer the sun than it (``_slab_numbers``). Half
    of it for every particle, as before, left a dense cloud's sunlit face in the shade of half
    the first slab: exactly 0 light where the pairs gave up to 0.57. That point is ``lead``
    sigmas nearer the sun than the centre (``slab_lead``), in whichever slab it lies; with the
    slabs in groups, a particle is read with the group that holds that slab.

    Nothing here visits the particles in depth order (on a big cloud, reading memory out of
    order cost more than all the arithmetic). Three passes in memory order, each chunk on
    its own thread: one numbers the slabs; one splats every particle into its slab's maps
    (summed in chunk order, so threads do not change a bit); then the maps go down the slabs
    in order, keeping the optical depth each slab's light came through and the depth it holds;
    and the last pass reads each particle's light from its slab's maps into ``light``,
    or, when one group holds every slab, over the across-ray coordinate it has just read (and
    returns that array): fresh pages cost more than the arithmetic on them.
    """
    done = done or _Done(None, 0)
    n = len(centers)
    spans = _spans(n, CHUNK)
    with ThreadPoolExecutor(WORKERS) as pool:
        depth, a, b = np.empty(n, _F32), np.empty(n, _F32), np.empty(n, _F32)
        ends = _project(centers, frame, middle, out=(depth, a, b), pool=pool)
        grid = _Grid(ends[1:, 0].astype(np.float64), ends[1:, 1].astype(np.float64), radii,
                     most=grid_cells)
        cells = grid.shape[0] * grid.shape[1]
        table = _peak_table(float(extinction), float(forward), float(share))
        # the slabs in groups whose maps fit in MAP_VALUES (one group but for a very fine grid)
        group = max(1, min(slabs, MAP_VALUES // (CLASSES * cells)))
        slab, face, nearer = _slab_numbers(depth, slabs, pool, ends[0],
                                           lead=(radii, _F32(lead * SIGMA)) if lead > 0 else None)
        own = depth             # each particle's own depth at its centre, once splatted
        if group >= slabs:
            light = a
        done.until(0.25)        # the projection and the slabs' numbers; then each group's passes
        groups = -(-slabs // group)
        for first in range(0, slabs, group):
            begun = 0.25 + 0.75 * (first // group) / groups
            last = min(slabs, first + group)
            place = functools.partial(_place, grid, slab, a, b, first, last, slabs)
            size = (last - first) * CLASSES * cells
            # two fixed shares of the chunks, each summed in chunk order, then added: the same
            # sums whatever runs them, and only two maps (and a chunk's) held at once
            sparse = n * SPARSE_SPLATS < size
            splat = functools.partial(_splat_share, grid, place, radii, density, table, size, own, sparse)
            layers, other = pool.map(splat, _halves(spans))
            batches = range(0, last - first, BLUR_SLABS)
            if sparse:
                blur = functools.partial(_blur_shares, grid, layers, other, last - first, CLASSES * cells)
                depths = np.concatenate(list(pool.map(blur, batches)))
            else:
                layers += other
                maps = layers.reshape(last - first, CLASSES, -1)
                depths = np.concatenate(list(pool.map(grid.blur, (maps[k:k + BLUR_SLABS] for k in batches))))
            del layers, other
            done.until(begun + 0.75 * 0.5 / groups)
            before = np.empty_like(depths)
            # depths, not light, down the slabs: a product of light factors reaches 0 in float32
            # after an optical depth of ~100, where a dense cloud's order would be lost
            reached = grid.reached.ravel()                      # a view: the grid's map
            for k in range(last - first):
                before[k] = reached
                reached += depths[k]
            # a particle is read with the group that holds the slab its face lies in
            reading = place if lead <= 0 else functools.partial(_place, grid, face, a, b, first, last, slabs)
            read = functools.partial(_read_chunk, grid, reading, own, slab if lead > 0 else None, nearer,
                                     before, depths, light, first)
            for k, _ in enumerate(pool.map(read, spans)):
                done.until(begun + 0.75 * (0.5 + 0.5 * (k + 1) / len(spans)) / groups)
    return light


def _spans(n: int, size: int) -> list[tuple[int, int]]:
    return [(start, min(n, start + size)) for start in range(0, n, size)]


def _halves(spans: list[tuple[int, int]]) -> list[list[tuple[int, int]]]:
    """The spans in two fixed shares, the first the longer: one a thread, each summed in order."""
    return [spans[:(len(spans) + 1) // 2], spans[(len(spans) + 1) // 2:]]


def _place(grid: _Grid, slab, a, b, first: int, last: int, slabs: int, span: tuple[int, int],
           bilinear: bool = True):
    """A chunk's particles of slabs first..last-1: which of the chunk (None: all), their slab
    (counted from ``first``, int32), their nearest cell and, with ``bilinear``, the cell and
    fractions to read the map at (else None)."""
    start, stop = span
    number = slab[start:stop]
    pick = None
    if (first > 0 or last < slabs) and (first > 0 or last < int(number.max(initial=0)) + 1):
        pick = np.flatnonzero((number >= first) & (number < last))
        number = number[pick]
    gx, gy = grid.coordinates(a[start:stop] if pick is None else a[start:stop][pick],
                              b[start:stop] if pick is None else b[start:stop][pick])
    number = number.astype(np.int32)
    if first:
        number -= np.int32(first)
    # Cell centres sit at whole numbers and every particle at least 2.5 cells in from the edge,
    # so truncating g + 1/2 rounds to the nearest cell exactly as floor(g) + (frac(g) >= 1/2)
    # did (g + 1/2 rounds in float32 only where it crosses a power of two >= 2, never down).
    w = np.int32(grid.shape[1])
    near = np.add(gx, _F32(0.5)).astype(np.int32)
    near *= w
    near += np.add(gy, _F32(0.5)).astype(np.int32)
    if not bilinear:
        return pick, number, None, near
    ix, iy = np.floor(gx), np.floor(gy)
    gx -= ix
    gy -= iy
    flat = ix.astype(np.int32)
    flat *= w
    flat += iy.astype(np.int32)
    return pick, number, (flat, gx, gy), near


def _splat_share(grid: _Grid, place, radii, density, table, size: int, own: np.ndarray, sparse: bool,
                 spans: list[tuple[int, int]]):
    """Chunks' optical depth splats, added in order: each particle's effective depth
    (``table``, by density) x 2 pi sigma^2 as a point at its nearest cell in its slab's map of
    its width class (the nearest of the grid's widths in log scale); and into ``own``, its own
    share of the depth at its centre. The maps (float64, ``size``), or with ``sparse`` the
    (sorted cells, sums) of those the splats reach: the same sums, each added in the same order.

    ``np.add.at`` rather than ``bincount``: a bincount a chunk allocates the whole maps
    (25 MB for 128 slabs) each time, and was slower. A sparse share's bincount runs once, over
    its cells' numbers among those reached."""
    total = np.zeros(0 if sparse else size)
    reached: list[np.ndarray] = []
    masses: list[np.ndarray] = []
    cells = np.int32(grid.shape[0] * grid.shape[1])
    for span in spans:
        pick, number, _, near = place(span, bilinear=False)
        start, stop = span
        r = radii[start:stop] if pick is None else radii[start:stop][pick]
        d = density[start:stop] if pick is None else density[start:stop][pick]
        sigma = r * _F32(SIGMA / grid.cell)
        klass = np.zeros(len(sigma), np.int32)
        for bound in grid.bounds:     # 3 compares: 15x faster than searchsorted on 3 values
            klass += sigma < bound
        level = d * _F32(PEAK_LEVELS)
        level += _F32(0.5)
        np.clip(level, 0, PEAK_LEVELS, out=level)
        mass = table[level.astype(np.int32)]
        mass *= sigma
        mass *= sigma
        mine = np.divide(mass, grid.spread[klass], out=sigma)
        if pick is None:
            own[start:stop] = mine
        else:
            own[start:stop][pick] = mine
        index = number * np.int32(CLASSES)
        index += klass
        index *= cells
        index += near
        mass *= _F32(2 * math.pi)
        if sparse:
            reached.append(index)
            masses.append(mass.astype(np.float64))
        else:
            np.add.at(total, index, mass.astype(np.float64))
    if not sparse:
        return total
    if not reached:
        return np.zeros(0, np.int64), np.zeros(0)
    # bincount adds each cell's masses in the order given, from 0, as np.add.at does on zeros
    cells, which = np.unique(np.concatenate(reached), return_inverse=True)
    return cells, np.bincount(which, np.concatenate(masses), len(cells))


def _blur_shares(grid: _Grid, first_share, second_share, slabs: int, per_slab: int, k: int) -> np.ndarray:
    """``grid.blur`` of slabs k..k+BLUR_SLABS-1 (of ``slabs``) from two sparse shares, the rows
    that hold anything made class by class: the first share's sums, plus the second's, as the
    maps of each share added."""
    stop = min(slabs, k + BLUR_SLABS)
    rows, cols = grid.shape
    found = []
    for cells, sums in (first_share, second_share):
        lo, hi = np.searchsorted(cells, (k * per_slab, stop * per_slab))
        at = cells[lo:hi] - k * per_slab
        slab, at = np.divmod(at, per_slab)
        klass, at = np.divmod(at, rows * cols)
        row, col = np.divmod(at, cols)
        found.append((klass, slab * rows + row, col, sums[lo:hi]))
    planes = []
    for c in range(CLASSES):
        picked = [(key[mine], col[mine], value[mine])
                  for klass, key, col, value in found for mine in (klass == c,)]
        keys = np.unique(np.concatenate([key for key, _, _ in picked]))
        values = np.zeros((len(keys), cols))
        for n, (key, col, value) in enumerate(picked):
            where = (np.searchsorted(keys, key), col)
            if n == 0:
                values[where] = value
            else:
                values[where] += value
        used = np.zeros((stop - k, rows), bool)
        used.ravel()[keys] = True
        planes.append((used, values))
    return grid.blur_rows(planes)


def _read_chunk(grid: _Grid, place, own: np.ndarray, slab: np.ndarray | None, nearer: np.ndarray,
                before: np.ndarray, depths: np.ndarray, light: np.ndarray, first: int,
                span: tuple[int, int]) -> None:
    """Each particle's light where it is read (``place`` numbers the slab that point lies in:
    its own, or with a lead, the slab of its face, ``slab`` then giving its own): behind the depth
    before that slab, at its centre's cell, and the share of what that slab holds there nearer the
    sun (``nearer``, in SHARE_LEVELS), less its own footprint when that slab is its own."""
    pick, number, (flat, fx, fy), near = place(span)
    start, stop = span
    share = (nearer[start:stop] if pick is None else nearer[start:stop][pick]).astype(_F32)
    share *= _F32(1 / SHARE_LEVELS)
    mine = own[start:stop] if pick is None else own[start:stop][pick]
    at = number                                         # the slab it is read in, counted from first
    if slab is not None:
        home = (slab[start:stop] if pick is None else slab[start:stop][pick]).astype(np.int32)
        if first:
            home -= np.int32(first)
        mine = np.where(at == home, mine, _F32(0))      # its own footprint is in its own slab only
    at *= np.int32(grid.shape[0] * grid.shape[1])
    flat += at
    near += at
    got = _bilinear(before.ravel(), flat, fx, fy, grid.shape[1])
    ahead = np.take(depths.ravel(), near)           # the face's slab's depth at its cell
    ahead -= mine                                   # less its own
    np.maximum(ahead, 0, out=ahead)
    ahead *= share
    got += ahead
    np.maximum(got, 0, out=got)
    got = _light_into(got, ahead)
    if pick is None:
        light[start:stop] = got
    else:
        light[start:stop][pick] = got


def light_of_depth(depth: np.ndarray) -> np.ndarray:
    """The light (float32, 1 in full sun) behind an effective optical ``depth`` towards the sun:
    ``e^-depth`` as Harris's first pass lets it through, and DIFFUSE of the sun falling as
    ``1 / (1 + depth)`` instead, as light scattered many times does through a thick cloud.

    Harris's pass keeps only the light scattered forward; with it alone a particle behind an
    optical depth of ~100 gets exactly 0 in float32, and a dense cloud's inside (depths in the
    thousands) is one black, its order towards the sun lost (issue 32). With the default sky,
    DIFFUSE moves no colour by more than one sRGB byte (under a black sky and a bright sun, the
    darkest by a few); the light still falls with depth, to float32's rounding of ``exp``.
    """
    depth = np.array(depth, _F32)
    return _light_into(depth, np.empty_like(depth))


def _light_into(depth: np.ndarray, out: np.ndarray) -> np.ndarray:
    """``light_of_depth`` into ``out``, using ``depth`` (float32, overwritten) as scratch: a big
    cloud's read allocates nothing more a chunk (fresh pages cost more than the arithmetic)."""
    np.negative(depth, out=out)
    np.exp(out, out=out)
    out *= _F32(1 - DIFFUSE)
    depth += _F32(1)
    np.reciprocal(depth, out=depth)
    depth *= _F32(DIFFUSE)
    out += depth
    return out


def peak_optical_depth(density, extinction: float) -> np.ndarray:
    """Optical depth through the centre of a particle of ``density`` (float64).

    SkyWorks draws a particle with opacity ``alpha0 G(r)``: alpha0 = 1 - e^-(extinction x
    density) and G its splat, a Gaussian of peak 1. The optical depth of that opacity,
    -ln(1 - alpha0 G), sums over the splat to Li2(alpha0) times the sum of G, so a
    Gaussian optical depth of peak Li2(alpha0) casts the same total shadow: pi^2/6 = 1.64
    for an opaque particle, extinction x density for a faint one.
    """
    alpha = -np.expm1(-np.asarray(density, np.float64) * extinction)
    return _dilog(alpha)


@functools.lru_cache(maxsize=8)
def _peak_table(extinction: float, forward: float | None, share: float = 1.0) -> np.ndarray:
    """The Gaussian peak of a particle's (effective) optical depth by density level, its shadow
    scaled by ``share``: a sky lights each cloud at its own share, so this is looked up in
    ``_effective_curve`` (one per forward fraction) rather than integrated each time."""
    peak = peak_optical_depth(_LEVELS / PEAK_LEVELS, extinction)
    if share != 1.0:
        peak *= share
    if forward is None or forward <= 0:
        return peak.astype(_F32)
    grid, curve = _effective_curve(forward)
    return np.interp(peak, grid, curve).astype(_F32)


CURVE_STEPS = 1 << 14
"""Steps of ``_effective_curve`` over peaks 0 to pi^2/6 (linear interpolation: within 1e-8)."""


@functools.lru_cache(maxsize=4)
def _effective_curve(forward: float) -> tuple[np.ndarray, np.ndarray]:
    """``_effective_table`` on CURVE_STEPS + 1 peaks from 0 to the most a particle has, pi^2/6."""
    grid = np.linspace(0.0, math.pi ** 2 / 6, CURVE_STEPS + 1)
    return grid, _effective_table(grid, forward)


def _effective_table(peak: np.ndarray, forward: float) -> np.ndarray:
    """The peak of a Gaussian holding as much *effective* depth as a footprint of ``peak``.

    Light through depth d with forward fraction F keeps e^-d + F (1 - e^-d) = e^-e(d), and
    e(d) = -ln(F + (1 - F) e^-d) <= d. Over a Gaussian footprint cut at CUT sigma,
    with g = e^-u its profile: total e = 2 pi sigma^2 integral over u in [0, CUT^2/2] of
    e(peak g(u)) du; the Gaussian of the same cut and total has that over (1 - e^(-CUT^2/2)).
    """
    if forward <= 0:
        return peak
    u = np.linspace(0, CUT * CUT / 2, 513)
    g = np.exp(-u)
    out = np.empty_like(peak)
    for start in range(0, len(peak), 256):     # 256 x 513 at a time: the whole table took 300 MB
        part = peak[start:start + 256, None]
        e = -np.log(forward + (1 - forward) * np.exp(-part * g[None, :]))
        out[start:start + 256] = ((e[:, 1:] + e[:, :-1]) / 2 * np.diff(u)).sum(axis=1)
    return out / (1 - math.exp(-CUT * CUT / 2))


def _dilog(x: np.ndarray) -> np.ndarray:
    """Li2(x) = sum x^k / k^2 for x in [0, 1], to 1e-15 (scipy.special takes 0.3-2 s to import).

    The series up to x = 1/2, Euler's reflection Li2(x) = pi^2/6 - ln x ln(1 - x) - Li2(1 - x) above.
    """
    x = np.clip(x, 0.0, 1.0)
    high = x > 0.5
    y = np.where(high, 1.0 - x, x)
    total = np.zeros_like(y)
    power = np.ones_like(y)
    for k in range(1, 51):                       # 0.5^51 / 51^2 < 1e-18
        power *= y
        total += power / (k * k)
    with np.errstate(divide="ignore", invalid="ignore"):
        cross = np.where((y > 0) & high, np.log(x) * np.log1p(-x), 0.0)
    return np.where(high, math.pi**2 / 6 - cross - total, total)


def _frame(sun: np.ndarray) -> np.ndarray:
    """Unit vectors (sun, a, b): a and b span the plane across the sun's rays."""
    helper = np.zeros(3)
    helper[int(np.argmin(np.abs(sun)))] = 1.0
    a = np.cross(sun, helper)
    a /= np.linalg.norm(a)
    return np.stack([sun, a, np.cross(sun, a)])


def _middle(centers: np.ndarray) -> np.ndarray:
    """About the middle of the cloud (float64): coordinates relative to it keep float32's detail
    for a cloud far from the origin."""
    sample = centers[::max(1, len(centers) // CHUNK)].astype(np.float64)
    return (sample.min(axis=0) + sample.max(axis=0)) / 2


def _project(centers: np.ndarray, rows: np.ndarray, middle: np.ndarray,
             out: tuple[np.ndarray, ...] | None = None, pool: ThreadPoolExecutor | None = None):
    """The centres' coordinates along each of ``rows`` (unit vectors), relative to ``middle``,
    as float32 (len(rows), N); or written into ``out`` (one float32 (N,) array per row), then
    returning each row's (least, greatest) value, (len(rows), 2) float32. The chunks on
    ``pool``'s threads if given."""
    n = len(centers)
    store = np.empty((len(rows), n), _F32) if out is None else np.empty((0, n), _F32)
    into = list(store) if out is None else list(out)
    top = float(np.finfo(_F32).max)

    def chunk(span: tuple[int, int]) -> np.ndarray:
        start, stop = span
        # one contiguous float64 row per axis: the products below then run on unit strides
        x, y, z = np.subtract(centers[start:stop].T, middle[:, None], order="C")
        ends = np.empty((len(rows), 2), _F32)
        for k, row in enumerate(rows):
            # written out: a (65536, 3) x (3, 3) matmul took 40 ms a chunk here (BLAS threads)
            value = x * row[0]
            value += y * row[1]
            value += z * row[2]
            np.clip(value, -top, top, out=value)                      # a cloud spanning all of float32
            part = into[k][start:stop]
            part[...] = value
            ends[k] = part.min(), part.max()
        return ends

    extents = _each(pool, chunk, _spans(n, CHUNK))
    if out is None:
        return store
    return np.stack([np.min(extents, axis=0)[:, 0], np.max(extents, axis=0)[:, 1]], axis=1)


def _each(pool: ThreadPoolExecutor | None, work, spans: list) -> list:
    """``work`` of each span, in order; on the pool's threads if there is one."""
    return list(pool.map(work, spans)) if pool is not None else [work(span) for span in spans]


def _slab_numbers(depth: np.ndarray, slabs: int, pool: ThreadPoolExecutor | None = None,
                  ends: np.ndarray | None = None, lead: tuple[np.ndarray, np.float32] | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each particle's slab, 0 nearest the sun (uint8, or uint16 for more than 256 slabs); the
    slab its light is read in (the same type); and the share of that slab's particles nearer the
    sun than where it is read, in SHARE_LEVELS (uint16; the level's own count half).

    The light is read at the centre, or with ``lead`` (radii, factor) that factor x the radius
    nearer the sun, in the slab found there. The depth is cut into KEY_LEVELS + 1 levels and the
    levels into ``slabs`` runs of about equal count; a level is never split, so a slab may hold
    more or fewer, or none. ``ends``: the depth's (least, greatest), when known.
    """
    n = len(depth)
    spans = _spans(n, CHUNK)
    if ends is None:
        ends = np.array(_each(pool, lambda span: (depth[span[0]:span[1]].min(), depth[span[0]:span[1]].max()),
                              spans)).T
    top, bottom = float(np.max(ends[1])), float(np.min(ends[0]))
    span = top - bottom
    scale = _F32(KEY_LEVELS / span) if span > 0 else _F32(0)
    key = np.empty(n, np.uint16)
    read = np.empty(n, np.uint16) if lead is not None else key

    def levels(share: list[tuple[int, int]]) -> np.ndarray:
        count = np.zeros(KEY_LEVELS + 1, np.int64)
        for start, stop in share:
            part = (_F32(top) - depth[start:stop]) * scale
            if lead is not None:
                ahead = lead[0][start:stop] * (lead[1] * scale)
                ahead = np.subtract(part, ahead, out=ahead)
                np.clip(ahead, 0, KEY_LEVELS, out=ahead)
                ahead += _F32(0.5)
                read[start:stop] = ahead
            np.clip(part, 0, KEY_LEVELS, out=part)
            part += _F32(0.5)
            key[start:stop] = part
            count += np.bincount(key[start:stop], minlength=KEY_LEVELS + 1)
        return count

    per_level = sum(_each(pool, levels, _halves(spans)))   # whole numbers: any order is exact
    before = np.cumsum(per_level) - per_level                # particles on nearer levels
    # the slab each level begins in; empty levels past the last particle would count as slab
    # `slabs` (all at one depth: one level), which no slab's count has
    slab_of_level = np.minimum((before * slabs) // n, slabs - 1)
    table = slab_of_level.astype(np.uint8 if slabs <= 256 else np.uint16)
    # each slab's first particle (counted over all) and count, then each level's share of its slab
    # nearer the sun: the particles of the slab's nearer levels and half its own level's
    starts = np.searchsorted(slab_of_level, np.arange(slabs + 1), "left")
    first = np.append(before, n)[starts]
    in_slab = np.diff(first)[slab_of_level]
    with np.errstate(divide="ignore", invalid="ignore"):
        fraction = (before - first[slab_of_level] + per_level / 2) / in_slab
    shares = np.rint(np.nan_to_num(fraction, nan=0.5).clip(0, 1) * SHARE_LEVELS).astype(np.uint16)
    slab = np.empty(n, table.dtype)
    face = np.empty(n, table.dtype) if lead is not None else slab
    nearer = np.empty(n, np.uint16)

    def number(span: tuple[int, int]) -> None:
        # mode="clip" (every level is in range): with the default "raise", take copies ``out``
        # into a buffer and back, reading fresh pages before writing them (a copy-on-write fault and
        # a TLB shootdown of the other threads for each page of the three arrays)
        np.take(table, key[span[0]:span[1]], out=slab[span[0]:span[1]], mode="clip")
        if lead is not None:
            np.take(table, read[span[0]:span[1]], out=face[span[0]:span[1]], mode="clip")
        np.take(shares, read[span[0]:span[1]], out=nearer[span[0]:span[1]], mode="clip")

    _each(pool, number, spans)
    return slab, face, nearer


class _Grid:
    """The deep shadow map: the optical depth ``reached`` on cells across the sun's rays (a big cloud)."""

    def __init__(self, lo: np.ndarray, hi: np.ndarray, radii: np.ndarray, most: int | None = None):
        step = max(1, len(radii) // CHUNK)
        typical = float(np.median(radii[::step])) * SIGMA
        sigma_max = float(radii.max()) * SIGMA
        margin = CUT * sigma_max
        sides = np.asarray(hi - lo, np.float64) + 2 * margin
        # GRID x GRID cells, shaped as the cloud is: a cloud strung out across the rays gets up to
        # LONGEST times GRID cells along it for the same number of cells (the same FFTs). A sky
        # sets its own side (``most``), and keeps it.
        longest, most = (LONGEST, GRID) if most is None else (1, max(16, most))
        cell = max(math.sqrt(float(sides[0] * sides[1])) / (most - 6),
                   float(sides.max()) / (longest * most - 6), typical / CELLS_PER_SIGMA)
        if not (math.isfinite(cell) and cell > 0):
            cell = max(sigma_max, float(np.max(np.abs(hi - lo))), 1.0)
        self.cell = cell
        # three spare cells on each side: stamps round to the nearest cell, splats and reads
        # take the next one
        rows, cols = (_fast_size(int(math.ceil((hi[k] - lo[k] + 2 * margin) / cell)) + 6) for k in range(2))
        self.shape = (rows, cols)
        self.corner = lo - margin - 3 * cell      # world (a, b) of cell (0, 0)'s lower corner
        self.reached = np.zeros(self.shape, _F32)
        self.kernels = _class_kernels(sigma_max / cell)
        widths = [w for w, _ in self.kernels]
        # a particle's class: the nearest width in log scale
        self.bounds = [_F32(w / math.sqrt(2)) for w in widths[:-1]]
        # a class's point splat, blurred and read back bilinearly, peaks at 1 / (2 pi spread)
        self.spread = np.array([max(w * w, 0.283) for w in widths], _F32)
        # the blurs as products of spectra (the margins keep wrap-around off the cloud)
        self.spectra = np.stack([_spectrum(kernel, self.shape) for _, kernel in self.kernels])

    def coordinates(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Grid coordinates of points across the rays (float32 cells; cell centres at whole numbers)."""
        gx = a * _F32(1 / self.cell)
        gx -= _F32(self.corner[0] / self.cell + 0.5)
        gy = b * _F32(1 / self.cell)
        gy -= _F32(self.corner[1] / self.cell + 0.5)
        return gx, gy

    def blur(self, layers: np.ndarray) -> np.ndarray:
        """Slabs' optical depth maps (float32, (slabs, cells)) from their point splats, one map
        per width class (``layers``, (slabs, CLASSES, cells)), each class blurred with its
        Gaussian and summed. A few slabs a call: one FFT per class for all of them (a call per
        map cost more than its FFT), and none for a class they do not use.

        rfft2 transforms the rows, then the columns. A sparse map's empty rows transform to
        zeros, so only its other rows are transformed (the same bits: each row is transformed on
        its own either way); a slab of a cloud of 9,000 particles has a few dozen rows of 216."""
        maps = layers.reshape(len(layers), CLASSES, *self.shape)
        planes = []
        for c in range(CLASSES):
            used = maps[:, c].any(axis=2)
            planes.append((used, maps[:, c][used]) if used.sum() <= used.size // 2 else maps[:, c])
        return self.blur_rows(planes)

    def blur_rows(self, planes: list) -> np.ndarray:
        """:meth:`blur` of a few slabs' maps given class by class: a whole (slabs, rows, cols)
        plane, or (the (slabs, rows) rows that hold anything, those rows' values)."""
        total = None
        for c, plane in enumerate(planes):
            if isinstance(plane, tuple):
                used, values = plane
                if not len(values):
                    continue
                rows = np.zeros((*used.shape, self.shape[1] // 2 + 1), complex)
                rows[used] = np.fft.rfft(values, axis=-1)
                spectrum = np.fft.fft(rows, axis=-2)
            else:
                spectrum = np.fft.rfft2(plane)
            spectrum *= self.spectra[c]
            total = spectrum if total is None else total.__iadd__(spectrum)
        slabs = len(planes[0][0]) if isinstance(planes[0], tuple) else len(planes[0])
        if total is None:
            return np.zeros((slabs, self.shape[0] * self.shape[1]), _F32)
        return np.fft.irfft2(total, s=self.shape).astype(_F32).reshape(slabs, -1)


def _class_kernels(widest: float) -> list[tuple[float, np.ndarray | None]]:
    """(class width in cells, normalised blur kernel or None) per class.

    Splatting to the nearest cell blurs by a box (variance 1/12 cell^2) and reading bilinearly
    by a tent (1/6), so the kernel's variance is the class width squared less 1/4.
    """
    out: list[tuple[float, np.ndarray | None]] = []
    for c in range(CLASSES):
        width = widest / 2**c
        var = width * width - 1 / 4
        if var < 0.09:
            out.append((width, None))
            continue
        k = math.sqrt(var)
        taps = np.arange(-math.ceil(CUT * k), math.ceil(CUT * k) + 1)
        kernel = np.exp(-0.5 * (taps / k) ** 2)
        out.append((width, (kernel / kernel.sum()).astype(_F32)))
    return out


def _fast_size(n: int) -> int:
    """The smallest 2^a 3^b 5^c >= n: FFTs of such sizes are fast (a prime size was 10x slower)."""
    best = 1 << max(0, (n - 1).bit_length())
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            size = p35
            while size < n:
                size *= 2
            best = min(best, size)
            p35 *= 3
        p5 *= 5
    return best


def _spectrum(kernel: np.ndarray | None, shape: tuple[int, int]) -> np.ndarray:
    """The 2D FFT of the separable kernel ``kernel`` x ``kernel``, centred on cell (0, 0)."""
    image = np.zeros(shape)
    if kernel is None:
        image[0, 0] = 1.0
    else:
        reach = len(kernel) // 2
        taps = np.arange(-reach, reach + 1)
        image[np.ix_(taps % shape[0], taps % shape[1])] = np.outer(kernel, kernel)
    return np.fft.rfft2(image)


def _bilinear(values: np.ndarray, flat: np.ndarray, fx: np.ndarray, fy: np.ndarray, w: int) -> np.ndarray:
    """Interpolate as lerps, so a constant map reads back exactly (full sun is exactly 1). The
    neighbours are read through shifted views of ``values``: no index arrays to add up."""
    low, b = np.take(values, flat), np.take(values[1:], flat)
    high, d = np.take(values[w:], flat), np.take(values[w + 1:], flat)
    b -= low
    b *= fy
    low += b
    d -= high
    d *= fy
    high += d
    high -= low
    high *= fx
    low += high
    return low
