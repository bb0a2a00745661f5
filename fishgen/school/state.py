"""A school's state between frames, and how it starts: where each fish is, where it heads, how
fast, its size and its brain's weights (VRSchool's per-fish jitter), and its wander spline.

Kept component-major: positions, headings and velocities are (3, N), so that every numpy pass runs
along the fish (a trailing axis of 3 makes numpy's inner loops three elements long, several times
slower at 1,000 fish). Every random draw a school's start needs happens here, in one fixed order,
whatever the behaviour model: the same seed gives the same start to every model.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fishgen.school.model import Brain, SchoolConfig

# VRFish Appendix A `urge_weightings` (random center keepaway - speed - direction) and flee weight.
# The thesis' weights multiply vectors of unrelated magnitudes in its own scene units, so fishgen
# reads each weight relative to these values: gain = BASE_GAIN * weight / APPENDIX_WEIGHT.
APPENDIX = Brain()
APPENDIX_WEIGHTS = dict(random=0.04, center=0.35, keepaway=0.01, speed=0.7, direction=0.0015,
                        flee=0.04)
JITTERED = ("random", "center", "keepaway", "speed", "direction", "flee")
WANDER_VERTICAL = 0.3      # wander points are flattened: fish wander mostly horizontally
WANDER_POOL = 4096         # random wander points drawn at a time
LAYOUT_SPACING = 1.5       # body lengths between start positions
BOUNDS_MARGIN = 3.0        # body lengths inside the walls where they start to steer fish back
RING_LEAST = 2.0           # x the layout spacing: the least radius of a ring layout


@dataclass(eq=False)
class SchoolState:
    """Per-fish constants and the (3, N) state the steps move on."""

    config: SchoolConfig
    dt: float
    rng: np.random.Generator
    group: np.ndarray          # (N,) species index
    n_groups: int
    scale: np.ndarray          # (N,) size factor
    length: np.ndarray         # (N,) body length, metres
    cruise: np.ndarray         # (N,) cruising speed, metres per second
    weights: dict[str, np.ndarray]  # per-fish urge weights relative to Appendix A, jittered
    repel: np.ndarray          # (N,) the brain's keep-away distance, metres
    flee_dist: np.ndarray      # (N,) metres
    lo: np.ndarray             # (3, 1) bounds
    hi: np.ndarray
    inner_lo: np.ndarray       # (3, N) where the soft walls start
    inner_hi: np.ndarray
    inv_margin: np.ndarray
    pos: np.ndarray            # (3, N) metres
    dir: np.ndarray            # (3, N) unit heading
    vel: np.ndarray            # (3, N) metres per second, always along dir
    wander: Wander
    fallback: np.ndarray       # (3, N) push-apart direction for coincident fish

    @property
    def n(self) -> int:
        return int(self.group.size)

    @classmethod
    def start(cls, config: SchoolConfig) -> SchoolState:
        """The school at frame 0, before any separation (the simulation separates it)."""
        rng = np.random.default_rng(config.seed)
        groups = config.groups
        counts = np.array([g.count for g in groups], dtype=np.int64)
        group = np.repeat(np.arange(len(groups)), counts)
        n = int(counts.sum())
        s = float(config.size_jitter)
        scale = np.clip(1.0 + s * rng.standard_normal(n), 1.0 - 3 * s, 1.0 + 3 * s)
        length = np.array([g.body_length for g in groups], dtype=np.float64)[group] * scale
        cruise = np.array([g.cruise_speed for g in groups])[group] * length
        j = float(config.jitter)
        weights = {}
        for name in JITTERED:
            if name == "flee":
                raw = np.array([g.brain.flee[0] for g in groups])
            else:
                raw = np.array([getattr(g.brain, name) for g in groups])
            factor = np.clip(1.0 + j * rng.standard_normal(n), 0.0, None)
            weights[name] = raw[group] / APPENDIX_WEIGHTS[name] * factor
        repel = np.array([g.brain.repel_distance for g in groups])[group] * length
        flee_dist = np.array([g.brain.flee[1] for g in groups])[group] * length
        cr = np.array([g.brain.change_rate for g in groups])[group]
        change_rate = np.maximum(1.0, cr * np.clip(1.0 + j * rng.standard_normal(n), 0.5, 1.5))
        lo = np.asarray(config.bounds[0], dtype=np.float64)[:, None]
        hi = np.asarray(config.bounds[1], dtype=np.float64)[:, None]
        pos = layout(config, group, rng)
        d = random_units(rng, n, vertical=WANDER_VERTICAL)
        if config.layout == "ring":
            d = ring_headings(config, group, pos, d)
        wander = Wander.start(rng, d, change_rate)
        fallback = random_units(rng, n, vertical=1.0)
        margin = np.minimum(BOUNDS_MARGIN * length, 0.25 * (hi - lo))   # (3, N)
        return cls(config=config, dt=1.0 / config.fps, rng=rng, group=group, n_groups=len(groups),
                   scale=scale, length=length, cruise=cruise, weights=weights, repel=repel,
                   flee_dist=flee_dist, lo=lo, hi=hi, inner_lo=lo + margin, inner_hi=hi - margin,
                   inv_margin=1.0 / margin, pos=pos, dir=d, vel=d * cruise, wander=wander,
                   fallback=fallback)


@dataclass(eq=False)
class Wander:
    """VRFish's random path (7.2): each fish steers towards a point of a spline through random
    directions, a new one every `change_rate` frames, blended in with smoothstep."""

    rng: np.random.Generator
    prev: np.ndarray           # (3, N) the last random point, as a direction
    next: np.ndarray           # (3, N) the next one
    phase: np.ndarray          # (N,) frames since the last point
    change_rate: np.ndarray    # (N,) frames between points
    pool: np.ndarray
    used: int = 0

    @classmethod
    def start(cls, rng: np.random.Generator, d: np.ndarray, change_rate: np.ndarray) -> Wander:
        n = d.shape[1]
        nxt = random_units(rng, n, vertical=WANDER_VERTICAL)
        phase = rng.uniform(0.0, 1.0, n) * change_rate
        return cls(rng, d.copy(), nxt, phase, change_rate, np.empty((3, 0)))

    def point(self) -> np.ndarray:
        """Advance one frame: a point on each fish's wander spline, as a unit direction (3, N)."""
        self.phase += 1.0
        due = self.phase >= self.change_rate
        if due.any():
            idx = np.flatnonzero(due)
            self.phase[idx] -= self.change_rate[idx]
            self.prev[:, idx] = self.next[:, idx]
            self.next[:, idx] = self._points(idx.size)
        h = np.minimum(np.maximum(self.phase / self.change_rate, 0.0), 1.0)
        h = h * h * (3.0 - 2.0 * h)
        u = self.prev + h * (self.next - self.prev)
        return u / np.maximum(norm(u), 1e-9)

    def _points(self, count: int) -> np.ndarray:
        """The next `count` random wander points, drawn many at a time: a few fish need one each
        frame, and one draw per frame cost more than the rest of the wander spline."""
        if self.pool.shape[1] - self.used < count:
            self.pool = random_units(self.rng, max(WANDER_POOL, count), vertical=WANDER_VERTICAL)
            self.used = 0
        self.used += count
        return self.pool[:, self.used - count:self.used]


def layout(config: SchoolConfig, group: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Start positions (3, N): each species a sphere, a box or a line; several species side by side."""
    n_groups = len(config.groups)
    lo, hi = np.asarray(config.bounds[0], np.float64), np.asarray(config.bounds[1], np.float64)
    extent = hi - lo
    centre = (lo + hi) / 2
    pos = np.empty((group.size, 3))
    for g, spec in enumerate(config.groups):
        sel = group == g
        m = int(sel.sum())
        if m == 0:
            continue
        spacing = LAYOUT_SPACING * spec.body_length
        gc = centre.copy()
        if n_groups > 1:  # each species starts in its own place along X
            gc[0] = lo[0] + (g + 0.5) * extent[0] / n_groups
        room = extent / (2 * max(1, n_groups) if config.layout != "box" else 2)
        if config.layout == "sphere":
            r = spacing * np.cbrt(3.0 * m / (4.0 * np.pi))
            r = min(r, 0.45 * float(np.min(extent)), 0.9 * float(room[0]))
            u = random_units(rng, m, vertical=1.0).T
            pos[sel] = gc + u * (r * np.cbrt(rng.uniform(0.0, 1.0, m)))[:, None]
        elif config.layout == "box":
            inset = np.minimum(spec.body_length, 0.25 * extent)
            sub_lo, sub_hi = lo + inset, hi - inset
            if n_groups > 1:
                sub_lo = sub_lo.copy()
                sub_hi = sub_hi.copy()
                sub_lo[0] = lo[0] + g * extent[0] / n_groups + inset[0]
                sub_hi[0] = lo[0] + (g + 1) * extent[0] / n_groups - inset[0]
            pos[sel] = rng.uniform(sub_lo, sub_hi, (m, 3))
        elif config.layout == "ring":  # a horizontal ring (torus) of about the layout's density
            ring = spacing * max(RING_LEAST, float(np.cbrt(9.0 * m / (2.0 * np.pi ** 2))))
            ring = min(ring, 0.35 * float(min(extent[0], extent[2])), 0.9 * float(room[0]))
            angle, depth, around = rng.uniform(0.0, 1.0, (3, m))
            angle, around = 2.0 * np.pi * angle, 2.0 * np.pi * around
            tube = ring / 3.0 * np.sqrt(depth)
            radius = ring + tube * np.cos(around)
            ring_pos = np.stack([radius * np.cos(angle), tube * np.sin(around), radius * np.sin(angle)], 1)
            pos[sel] = gc + ring_pos
        else:  # line along X (or along Z per species when there are several)
            axis = 0 if n_groups == 1 else 2
            width = min(m * spacing, 0.9 * float(extent[axis]))
            p = np.tile(gc, (m, 1))
            p[:, axis] += np.linspace(-width / 2, width / 2, m)
            p += rng.normal(0.0, 0.05 * spacing, (m, 3))
            pos[sel] = p
    return np.ascontiguousarray(np.clip(pos, lo, hi).T)


def ring_headings(config: SchoolConfig, group: np.ndarray, pos: np.ndarray, noise: np.ndarray) -> np.ndarray:
    """Headings round each species' ring (turning about -Y: clockwise seen from above, as +X turns
    to +Z), a little off (noise x 0.2)."""
    d = np.empty_like(pos)
    for g in range(len(config.groups)):
        sel = group == g
        if sel.any():
            centre = pos[:, sel].mean(axis=1, keepdims=True)
            out = pos[:, sel] - centre
            d[:, sel] = np.stack([-out[2], np.zeros_like(out[0]), out[0]])
    d /= np.maximum(norm(d), 1e-12)
    d = d + 0.2 * noise
    return d / np.maximum(norm(d), 1e-12)


def norm(v: np.ndarray) -> np.ndarray:
    """Lengths of component-major vectors: (3, ...) -> (...)."""
    return np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


def random_units(rng: np.random.Generator, n: int, vertical: float) -> np.ndarray:
    """n random unit directions as (3, n), flattened vertically by `vertical`."""
    u = rng.standard_normal((n, 3)).T.copy()
    u[1] *= vertical
    return u / np.maximum(norm(u), 1e-12)
