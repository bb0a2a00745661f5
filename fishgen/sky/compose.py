"""A sky of many clouds: where each goes, how big it is, and its particles (pure functions).

:func:`plan_sky` decides, from a seed: which cloud model each cloud is, its scale (uniform, with
its depth stretched: the editor's clouds are flat cards), its turn about +Y, its place in the
area and altitude band, and its share of the particles. :func:`fill_sky` fills each cloud in its
own frame (the model's box centred on the origin) as `fishgen clouds` fills a file, adds the
noise, and keeps where it goes; the
lighting (:mod:`fishgen.sky.light`) and the scene (:mod:`fishgen.sky.scene`) follow.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from fishgen.clouds.model import DEFAULT_MAX_PARTICLES, Cloud, Cube, CubeFile
from fishgen.sky.modes import SkyMode

PLACE_TRIES = 48
"""Random places tried per cloud; the one overlapping its neighbours least is kept."""
OVERLAP = 0.75
"""Two clouds may come this close, as a share of the sum of their bounding radii."""


@dataclass(frozen=True)
class Placement:
    """One cloud of a sky, before filling: which model, how turned, scaled and placed."""

    name: str                                  # its node's name, "cloud_007"
    source: int                                # index of its model in the sources
    scale: tuple[float, float, float]          # x, y, z scale of the model
    yaw: float                                 # turn about +Y, radians
    position: tuple[float, float, float]       # world position of its frame's origin (the box centre)
    particles: int                             # its share of the sky's particles
    seed: int                                  # its fill and noise seed

    @property
    def rotation(self) -> tuple[float, float, float, float]:
        """The turn as a glTF quaternion (x, y, z, w)."""
        return (0.0, math.sin(self.yaw / 2), 0.0, math.cos(self.yaw / 2))


@dataclass(frozen=True)
class SkyPlan:
    mode: SkyMode
    seed: int
    area: tuple[float, float]
    altitude: tuple[float, float]
    placements: tuple[Placement, ...]

    @property
    def particles(self) -> int:
        return sum(p.particles for p in self.placements)


@dataclass(frozen=True)
class SkyCloud:
    """A filled cloud: its particles in its own frame, and the placement that puts it in the sky."""

    placement: Placement
    cloud: Cloud                 # particles relative to placement.position, before the turn

    def world_centers(self) -> np.ndarray:
        """(N, 3) float64: the particles where the sky puts them."""
        return to_world(self.cloud.centers, self.placement)


def to_world(local: np.ndarray, placement: Placement) -> np.ndarray:
    c, s = math.cos(placement.yaw), math.sin(placement.yaw)
    # a turn by yaw about +Y (right-handed): x' = c x + s z, z' = -s x + c z
    rot = np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]], np.float64)   # row vectors: v @ rot
    return np.asarray(local, np.float64) @ rot + np.asarray(placement.position, np.float64)


def model_box(model: CubeFile) -> tuple[np.ndarray, np.ndarray]:
    """The min and max corners of a model's cubes, widened by its largest particle radius."""
    centre = np.array([c.centre for c in model.cubes], np.float64).reshape(-1, 3)
    half = np.array([c.size for c in model.cubes], np.float64).reshape(-1, 3) / 2
    reach = max(c.max_radius for c in model.cubes)
    return (centre - half).min(axis=0) - reach, (centre + half).max(axis=0) + reach


def plan_sky(mode: SkyMode, sources: Sequence[CubeFile], *, seed: int, area: tuple[float, float],
             altitude: tuple[float, float], particles: int | None = None) -> SkyPlan:
    """Where ``mode.clouds`` clouds go, drawn from ``sources`` with the seed; ``particles`` (default
    the mode's) are shared out in proportion to each cloud's volume, each cube getting its model's
    share of them."""
    if not sources:
        raise ValueError("a sky needs at least one cloud model")
    total = mode.particles if particles is None else int(particles)
    rng = np.random.default_rng([int(seed), 0x736B79])     # "sky"
    n = mode.clouds
    which = rng.integers(0, len(sources), n)
    uniform = rng.uniform(*mode.scale, n)
    stretch = rng.uniform(*mode.depth, n)
    yaw = rng.uniform(0, 2 * math.pi, n)
    seeds = rng.integers(0, 2**62, n)
    boxes = [model_box(m) for m in sources]
    sizes = np.array([(boxes[k][1] - boxes[k][0]) * (u, u, u * d)
                      for k, u, d in zip(which, uniform, stretch, strict=True)])
    volume = np.array([_volume(sources[k]) for k in which]) * uniform**3 * stretch
    shares = _apportion(total, volume, minimum=np.array([_occupied(sources[k]) for k in which]))
    # biggest first: they are the hardest to fit
    order = np.argsort(-sizes[:, 0] * sizes[:, 2], kind="stable")
    centres = _place(rng, sizes[order], area, altitude)
    placed = np.empty_like(centres)
    placed[order] = centres
    placements = tuple(Placement(name=f"cloud_{i:03d}", source=int(which[i]),
                                 scale=(float(uniform[i]), float(uniform[i]), float(uniform[i] * stretch[i])),
                                 yaw=float(yaw[i]), position=tuple(float(v) for v in placed[i]),  # type: ignore[arg-type]
                                 particles=int(shares[i]), seed=int(seeds[i]))
                       for i in range(n))
    return SkyPlan(mode, int(seed), area, altitude, placements)


def _volume(model: CubeFile) -> float:
    return float(sum(c.size[0] * c.size[1] * c.size[2] for c in model.cubes if c.particles))


def _occupied(model: CubeFile) -> int:
    return sum(1 for c in model.cubes if c.particles)


def _apportion(total: int, weights: np.ndarray, minimum: np.ndarray | None = None) -> np.ndarray:
    """Whole numbers summing to ``total`` in proportion to ``weights`` (largest remainders, ties by
    position), each at least its ``minimum`` when the total allows."""
    weights = np.asarray(weights, np.float64)
    floor_ = np.zeros(len(weights), np.int64) if minimum is None else np.asarray(minimum, np.int64)
    if floor_.sum() > total:
        floor_ = np.zeros(len(weights), np.int64)
    rest = total - int(floor_.sum())
    if weights.sum() <= 0:
        weights = np.ones(len(weights))
    exact = weights / weights.sum() * rest
    out = np.floor(exact).astype(np.int64)
    short = rest - int(out.sum())
    if short:
        out[np.argsort(-(exact - out), kind="stable")[:short]] += 1
    return out + floor_


def _place(rng: np.random.Generator, sizes: np.ndarray, area: tuple[float, float],
           altitude: tuple[float, float]) -> np.ndarray:
    """Box centres for clouds of ``sizes`` (in placing order): each the least crowded of
    PLACE_TRIES random places inside the area, its base within the altitude band."""
    reach = np.linalg.norm(sizes, axis=1) / 2                       # bounding radius
    width, depth = area
    low, high = altitude
    out = np.zeros((len(sizes), 3))
    for k, size in enumerate(sizes):
        half_x, half_z = min(size[0] / 2, width / 2), min(size[2] / 2, depth / 2)
        tries = np.stack([rng.uniform(-width / 2 + half_x, width / 2 - half_x, PLACE_TRIES),
                          rng.uniform(low, high, PLACE_TRIES) + size[1] / 2,
                          rng.uniform(-depth / 2 + half_z, depth / 2 - half_z, PLACE_TRIES)], axis=1)
        if k == 0:
            out[0] = tries[0]
            continue
        gap = np.linalg.norm(tries[:, None, :] - out[None, :k, :], axis=2)   # (tries, placed)
        crowding = np.clip(OVERLAP * (reach[k] + reach[None, :k]) - gap, 0, None).sum(axis=1)
        out[k] = tries[int(np.argmin(crowding))]       # the first of the least crowded
    return out


def scaled_model(model: CubeFile, placement: Placement, puff: float) -> CubeFile:
    """The model as the placement wants it, centred on its box: cubes scaled, each cube's share of
    the particles (its model's share), radii grown with the scale and made finer as the particles
    grow denser than the model's (so the cloud keeps its model's look), times ``puff``."""
    lo, hi = model_box(model)
    middle = (lo + hi) / 2
    sx, sy, sz = placement.scale
    counts = _apportion(placement.particles, np.array([c.particles for c in model.cubes], np.float64))
    source = max(model.total, 1)
    finer = (sx * sy * sz * source / max(placement.particles, 1)) ** (1 / 3)
    cubes = tuple(Cube(particles=int(k), size=(c.size[0] * sx, c.size[1] * sy, c.size[2] * sz),
                       centre=((c.centre[0] - middle[0]) * sx, (c.centre[1] - middle[1]) * sy,
                               (c.centre[2] - middle[2]) * sz),
                       max_radius=c.max_radius * finer * puff, line=c.line, texture=c.texture)
                  for c, k in zip(model.cubes, counts, strict=True))
    return replace(model, cubes=cubes, declared_total=int(counts.sum()))


def fill_sky(plan: SkyPlan, sources: Sequence[CubeFile], *, noise: float = 0.0,
             max_particles: int = DEFAULT_MAX_PARTICLES,
             advance: Callable[[int], None] | None = None) -> list[SkyCloud]:
    """Every cloud of the plan filled in its own frame through the one cloud pipeline
    (:func:`fishgen.clouds.pipeline.cube_clouds`, its placement's seed), with ``noise`` (0 to 0.9)
    of seeded 3D noise on its radii and densities; the sky lights them (:mod:`fishgen.sky.light`).
    ``advance(1)`` after each cloud (a progress bar's)."""
    from fishgen.clouds.noise import roughen
    from fishgen.clouds.pipeline import cube_clouds

    out = []
    for p in plan.placements:
        model = scaled_model(sources[p.source], p, plan.mode.puff)
        cloud, = cube_clouds([model], seed=p.seed, light=False, max_particles=max_particles).clouds
        if noise > 0:
            lo, hi = model_box(model)
            # features about a third of the cloud's height: bumps on its top, holes in its base
            cloud = roughen(cloud, noise, seed=p.seed, scale=float(hi[1] - lo[1]) / 3)
        out.append(SkyCloud(p, cloud))
        if advance is not None:
            advance(1)
    return out
