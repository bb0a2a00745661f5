"""Cube files fishgen did not ship, suns from anywhere, and an optical depth the lighting code
did not compute: the harness of tests/clouds/test_suns.py and benchmarks/cloud_suns.py.

The reference treats each particle as a 3D Gaussian cloud of extinction, of width 0.4 x its
radius (its billboard sprite's) and column depth through its centre Li2(1 - e^-(extinction x
density)) (SkyWorks' splat, docs/clouds.md), and integrates it exactly along the ray from a
particle's centre towards the sun: ``peak x exp(-b^2 / 2 sigma^2) x Phi(t / sigma)``, b the
distance of the other particle from the ray and t how far along the ray it lies. No grid, no
slabs, no depth order: pairs come from a KD-tree across the sun's rays.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import special
from scipy.spatial import cKDTree

SIGMA = 0.4
"""A particle's width over its radius: the billboard sprite's Gaussian."""
REACH = 4.0
"""Pairs farther apart across the rays than REACH x the wider sigma shade nothing (e^-8)."""
ISSUE_SUNS = ((1.0, 0.2, 0.0), (-1.0, 0.3, 0.2), (0.2, 0.3, 1.0))
"""Issue 32's suns: 0.58, a failure and 0.93 on its cube file."""
AXES = ((1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0),
        (0.0, -1.0, 0.0))


def random_cube_file(rng: np.random.Generator, particles: int) -> str:
    """The text of a .awn file of ``particles`` particles: 1 to 30 cubes of random sizes (0.5 to
    12 per side) and maximum radii (0.3 to 3.5), somewhere within 50 units of the origin, either
    heaped together (overlapping a lot, a little or not at all) or strung out along a random
    direction with gaps between them (a bank of separate clouds)."""
    count = int(rng.integers(1, 31))
    sizes = rng.uniform(0.5, 12.0, (count, 3))
    scale = float(np.median(sizes))
    if rng.random() < 0.5:
        spread = rng.uniform(0.0, 1.5) * scale * count ** (1 / 3)
        centres = rng.normal(0.0, spread + 1e-3, (count, 3))
    else:
        line = rng.normal(size=3)
        line /= np.linalg.norm(line)
        steps = rng.uniform(1.0, 6.0, count) * scale
        centres = np.cumsum(steps)[:, None] * line + rng.normal(0.0, 0.3 * scale, (count, 3))
    centres += rng.uniform(-50, 50, 3)
    radii = rng.uniform(0.3, 3.5, count)
    weights = rng.dirichlet(np.ones(count) * rng.uniform(0.3, 3.0))
    counts = np.maximum(1, np.floor(weights * particles)).astype(int)
    counts[int(np.argmax(counts))] += particles - int(counts.sum())
    lines = [str(int(counts.sum())), str(count)]
    lines += [", ".join([str(int(n)), *(f"{v:.6g}" for v in (*s, *c, r))])
              for n, s, c, r in zip(counts, sizes, centres, radii, strict=True)]
    return "\n".join(lines) + "\n"


def random_suns(rng: np.random.Generator, count: int) -> list[tuple[float, float, float]]:
    """``count`` directions uniform on the sphere (below the horizon as often as above)."""
    v = rng.normal(size=(count, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    return [tuple(float(x) for x in row) for row in v]


def peak_depth(density: np.ndarray, extinction: float) -> np.ndarray:
    """Column depth through a particle's centre: Li2(1 - e^-(extinction x density))."""
    return special.spence(np.exp(-np.asarray(density, np.float64) * extinction))


FACE = 1.0
"""Where a particle's light stands for, in sigmas sunward of its centre: its sunward face, the
side its billboard shows the sun (docs/decisions.md, "Dense clouds, grey")."""


def optical_depth(centers: np.ndarray, radii: np.ndarray, density: np.ndarray, sun,
                  query: np.ndarray, extinction: float = 80.0, chunk: int = 1024,
                  face: float = FACE) -> np.ndarray:
    """Optical depth towards ``sun`` through every other particle's Gaussian (float64, one per
    query index), from ``face`` x its sigma sunward of each ``query`` particle's centre."""
    s = np.asarray(sun, np.float64)
    s /= np.linalg.norm(s)
    p = centers.astype(np.float64)
    p -= p.mean(axis=0)
    helper = np.eye(3)[int(np.argmin(np.abs(s)))]
    a = np.cross(s, helper)
    a /= np.linalg.norm(a)
    b = np.cross(s, a)
    across = np.stack([p @ a, p @ b], axis=1)
    along = p @ s
    sigma = SIGMA * radii.astype(np.float64)
    peak = peak_depth(density, extinction)
    tree = cKDTree(across)
    reach = REACH * float(sigma.max())
    tau = np.zeros(len(query))
    for start in range(0, len(query), chunk):
        rows = query[start:start + chunk]
        # every pair within reach across the rays, as arrays (no per-pair Python objects)
        pairs = cKDTree(across[rows]).sparse_distance_matrix(tree, reach, output_type="ndarray")
        owner, j = pairs["i"], pairs["j"]
        keep = rows[owner] != j
        owner, j, d = owner[keep], j[keep], pairs["v"][keep]
        i = rows[owner]
        t = along[j] - (along[i] + face * sigma[i])
        sj = sigma[j]
        share = peak[j] * np.exp(-0.5 * (d * d) / (sj * sj)) * special.ndtr(t / sj)
        tau[start:start + len(rows)] = np.bincount(owner, share, len(rows))
    return tau


def sample(n: int, most: int, rng: np.random.Generator) -> np.ndarray:
    """At most ``most`` particle indices, sorted (the reference's cost grows with the queries)."""
    return np.arange(n) if n <= most else np.sort(rng.choice(n, most, replace=False))


def rank_correlation(light: np.ndarray, tau: np.ndarray) -> float:
    """Spearman's rank correlation of the baked light with -tau (1: the light falls exactly as
    the optical depth towards the sun grows); NaN-free: a constant light scores 0."""
    from scipy import stats

    if np.ptp(light) == 0 or np.ptp(tau) == 0:
        return 0.0
    value = stats.spearmanr(light, -tau).statistic
    return float(value) if math.isfinite(value) else 0.0


TUNED = range(0, 10)
"""Seeds the lighting was tuned on."""
ADDED = range(20, 100)
"""More seeds the small clouds' pair-by-pair light was designed on (their files of 100 to 2,048
particles, as the test draws them): tuned too, but left out of the test for its time."""
HELD_OUT = range(100, 120)
"""Seeds nobody looked at while tuning the grid (issue 32's first round); the pair-by-pair light
was designed knowing that 102 and 112 fell short, not on their files."""
FRESH = range(200, 220)
"""Seeds nobody looked at until the pair-by-pair light was done: the honest figure."""


def suns_for(rng: np.random.Generator) -> dict[str, tuple[float, float, float]]:
    """The issue's three suns, one of the six axis directions and two uniform on the sphere."""
    axis = AXES[int(rng.integers(len(AXES)))]
    return {"issue +x": ISSUE_SUNS[0], "issue -x": ISSUE_SUNS[1], "issue +z": ISSUE_SUNS[2],
            "axis": axis, "random 1": random_suns(rng, 1)[0], "random 2": random_suns(rng, 1)[0]}


def drawn(seed: int, folder, lowest: int = 100, highest: int = 100_000, queries: int = 300):
    """(cloud, cube count, query indices, {sun name: sun}) of the random cube file of ``seed``
    (``lowest`` to ``highest`` particles, log-uniform), written to ``folder`` and loaded and
    filled as a user's would be."""
    from pathlib import Path

    from fishgen.clouds import fill_cloud, load_cubes

    rng = np.random.default_rng(seed)
    particles = int(round(math.exp(rng.uniform(math.log(lowest), math.log(highest)))))
    path = Path(folder) / f"random_{seed}.awn"
    path.write_text(random_cube_file(rng, particles))
    cubes = load_cubes(path)
    cloud = fill_cloud(cubes, seed=seed)
    query = sample(len(cloud), queries, rng)
    return cloud, len(cubes.cubes), query, suns_for(rng)


def correlations(seed: int, folder, lowest: int = 100, highest: int = 100_000,
                 queries: int = 300) -> tuple[int, int, dict[str, float]]:
    """(particles, cubes, {sun: rank correlation}) of the light fishgen bakes on the random cube
    file of ``seed`` (``drawn``), against the reference depth of ``queries`` particles."""
    from fishgen.clouds import Lighting
    from fishgen.clouds.light import incident_light

    cloud, cubes, query, suns = drawn(seed, folder, lowest, highest, queries)
    out = {}
    for name, sun in suns.items():
        lighting = Lighting(sun=sun)
        light = incident_light(cloud.centers, cloud.radii, cloud.density, lighting)
        tau = optical_depth(cloud.centers, cloud.radii, cloud.density, sun, query, lighting.extinction)
        out[name] = rank_correlation(light[query], tau)
    return len(cloud), cubes, out
