"""Simulate a school: VRFish's boids "brain" (Lobb 2002, ch. 7.2) or the 2017 particle swarm.

`simulate(config, progress=None) -> Tracks`. Vectorised numpy over all fish; neighbours from
scipy's cKDTree, refreshed every few frames (the k nearest change slowly) while all distances are
recomputed from the current positions every frame, so cost grows about linearly with fish count.

Common kinematics for both models: each model proposes a new velocity; the fish's heading turns
towards it by at most `config.max_turn * dt` radians, the speed is clamped, the fish moves, a hard
separation pushes apart any pair closer than `HARD_SEPARATION` mean body lengths (VRFish's fish swim
through each other, ch. 7.3; ours do not), and positions are kept inside `config.bounds`. The
velocity always points along the heading, so a fish faces where it swims.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.spatial import cKDTree  # type: ignore[import-untyped]

from fishgen.school.model import Brain, SchoolConfig, Tracks
from fishgen.school.paths import path_positions

Progress = Callable[[int], None]

# VRFish Appendix A `urge_weightings` (random center keepaway - speed - direction) and flee weight.
# The thesis' weights multiply vectors of unrelated magnitudes in its own scene units, so fishgen
# reads each weight relative to these values: gain = BASE_GAIN * weight / APPENDIX_WEIGHT.
APPENDIX = Brain()
APPENDIX_WEIGHTS = dict(random=0.04, center=0.35, keepaway=0.01, speed=0.7, direction=0.0015,
                        flee=0.04)
# Base gains (1/s) that make the Appendix A brain school (tuned by the tests' measures).
GAIN_RANDOM = 0.5
GAIN_CENTER = 1.0
GAIN_KEEPAWAY = 8.0
GAIN_SPEED = 1.0
GAIN_DIRECTION = 6.0
GAIN_FLEE = 8.0
GAIN_BOUNDS = 6.0
GAIN_OTHER_SPECIES = 6.0

HARD_SEPARATION = 0.6      # mean body lengths: centres never closer (metrics flag < 0.5)
CONTACT_DISTANCE = 0.8     # mean body lengths: bodies push apart inside this, whatever the brain
GAIN_CONTACT = 10.0
OTHER_SPECIES_DISTANCE = 4.0  # body lengths: keep away from other species inside this
FLEE_SPEEDUP = 1.5         # speed up to (1 + this) x cruise next to a predator
MIN_SPEED = 0.3            # x cruise (boids) / x max_speed (pso)
WANDER_VERTICAL = 0.3      # wander points are flattened: fish wander mostly horizontally
LAYOUT_SPACING = 1.5       # body lengths between start positions
BOUNDS_MARGIN = 3.0        # body lengths inside the walls where they start to steer fish back
PSO_REFERENCE_DT = 0.05    # Figure 2.2's time step; inertia is re-timed from it
PSO_MIN_TURN = 0.25        # x max_turn: the least turn rate a pso fish has next to the target
SEPARATION_PASSES = 1
WANDER_POOL = 4096         # random wander points drawn at a time
# k-nearest lists are rebuilt every frame below this many fish, else at most this many seconds
# of simulated time apart (all distances are still measured every frame from current positions)
NEIGHBOUR_REFRESH_FISH = 300
NEIGHBOUR_REFRESH_SECONDS = 0.5
PARALLEL_QUERY_FISH = 5000
HEADING_CHUNK_ELEMENTS = 4096  # fish x frames per vectorised heading pass
JITTERED = ("random", "center", "keepaway", "speed", "direction", "flee")


def simulate(config: SchoolConfig, progress: Progress | None = None) -> Tracks:
    """Run `config.frames` frames at `config.fps`; frame 0 is the start layout.

    `progress(frames_done)` is called after each frame when given (frames_done = 1 .. frames).
    """
    sim = _Simulation(config)
    frames = int(config.frames)
    n = sim.n
    positions = np.empty((frames, n, 3))
    velocities = np.empty((frames, n, 3))
    headings = np.empty((frames, n, 4))
    times = np.arange(frames, dtype=np.float64) / config.fps
    target = path_positions(config.target, times) if config.model == "pso" else None
    predator = path_positions(config.predator, times) if config.predator is not None else None
    for f in range(frames):
        if f > 0:
            sim.step(f, None if target is None else target[f],
                     None if predator is None else predator[f])
        positions[f] = sim.pos.T
        velocities[f] = sim.vel.T
        if progress is not None:
            progress(f + 1)
    # headings for all frames, a few frames at a time: small chunks keep numpy's temporaries in the
    # CPU cache (at 1,000 fish, 64-frame chunks ran 2.5x slower than 4-frame ones). Each chunk's
    # sign follows the previous chunk's last frame (q and -q are one rotation, but a sign flip
    # breaks linear key interpolation).
    chunk = max(1, HEADING_CHUNK_ELEMENTS // max(n, 1))
    for start in range(0, frames, chunk):
        q = headings_from_velocities(velocities[start:start + chunk])
        if start > 0:
            q *= np.where(np.einsum("nk,nk->n", q[0], headings[start - 1]) < 0, -1.0, 1.0)[:, None]
        headings[start:start + chunk] = q
    return Tracks(times=times, positions=positions, velocities=velocities,
                  headings=headings, group=sim.group.copy(),
                  scale=sim.scale.copy(), target=target, predator=predator)


def headings_from_velocities(velocities: np.ndarray) -> np.ndarray:
    """Quaternions (x, y, z, w) turning +Z to each velocity with no roll (+Y stays as up as it can).

    q = yaw about +Y then pitch about +X; signs are made continuous frame to frame (q and -q are
    one rotation, but a sign flip breaks linear key interpolation).
    """
    v = np.asarray(velocities, dtype=np.float64)
    vx, vy, vz = v[..., 0], v[..., 1], v[..., 2]
    # the half angles depend only on the direction: scaled so that squares neither overflow nor
    # vanish (component by component: a reduction over a trailing axis of 3 is slow in numpy)
    big = np.maximum(np.maximum(np.abs(vx), np.abs(vy)), np.abs(vz))
    inv = 1.0 / np.where(big > 0, big, 1.0)
    vx, vy, vz = vx * inv, vy * inv, vz * inv
    horiz = np.sqrt(vx * vx + vz * vz)
    # half-angle (cos, sin) pairs straight from the vector, no trigonometry: for the yaw,
    # (cos, sin)(yaw / 2) ~ (horiz + vz, vx), with horiz + vz = vx^2 / (horiz - vz) where vz < 0
    # so that a fish swimming almost straight back loses no precision; a vertical or zero velocity
    # has no yaw (atan2(0, 0) = 0) and a fish swimming straight back has yaw pi
    with np.errstate(invalid="ignore", divide="ignore"):
        cos_yaw = np.where(vz >= 0, horiz + vz, vx * vx / (horiz - vz))
    length = np.sqrt(cos_yaw * cos_yaw + vx * vx)
    turned = length > 0
    safe = np.where(turned, length, 1.0)
    b = np.where(turned, cos_yaw / safe, horiz == 0)     # cos(yaw / 2)
    a = np.where(turned, vx / safe, horiz > 0)           # sin(yaw / 2)
    # pitch: (cos, sin)(pitch / 2) ~ (|v| + horiz, -vy), never both 0 but for v = 0 (no pitch)
    cos_pitch = np.sqrt(horiz * horiz + vy * vy) + horiz
    length = np.sqrt(cos_pitch * cos_pitch + vy * vy)
    safe = np.where(length > 0, length, 1.0)
    e = np.where(length > 0, cos_pitch / safe, 1.0)      # cos(pitch / 2)
    c = -vy / safe                                       # sin(pitch / 2)
    q = np.stack([b * c, e * a, -a * c, b * e], axis=-1)
    if q.ndim == 3 and q.shape[0] > 1:
        dots = np.einsum("fnk,fnk->fn", q[1:], q[:-1])
        flips = np.cumprod(np.where(dots < 0, -1.0, 1.0), axis=0)
        q[1:] *= flips[..., None]
    return q


class _Simulation:
    """The school's state between frames, kept component-major: positions, headings and velocities
    are (3, N) and neighbour lists (k, N), so that every numpy pass runs along the fish (a trailing
    axis of 3 makes numpy's inner loops three elements long, several times slower at 1,000 fish)."""

    def __init__(self, config: SchoolConfig) -> None:
        _check(config)
        self.cfg = config
        self.dt = 1.0 / config.fps
        rng = self.rng = np.random.default_rng(config.seed)
        groups = config.groups
        counts = np.array([g.count for g in groups], dtype=np.int64)
        self.group = np.repeat(np.arange(len(groups)), counts)
        self.n = n = int(counts.sum())
        self.n_groups = len(groups)
        j = float(config.jitter)
        self.scale = np.clip(1.0 + j * rng.standard_normal(n), 1.0 - 3 * j, 1.0 + 3 * j)
        base_len = np.array([g.body_length for g in groups], dtype=np.float64)
        self.length = base_len[self.group] * self.scale
        self.cruise = np.array([g.cruise_speed for g in groups])[self.group] * self.length
        # per-fish brain: weights relative to Appendix A, each jittered
        w = {}
        for name in JITTERED:
            if name == "flee":
                raw = np.array([g.brain.flee[0] for g in groups])
            else:
                raw = np.array([getattr(g.brain, name) for g in groups])
            factor = np.clip(1.0 + j * rng.standard_normal(n), 0.0, None)
            w[name] = raw[self.group] / APPENDIX_WEIGHTS[name] * factor
        self.w = w
        self.repel = np.array([g.brain.repel_distance for g in groups])[self.group] * self.length
        self.flee_dist = np.array([g.brain.flee[1] for g in groups])[self.group] * self.length
        cr = np.array([g.brain.change_rate for g in groups])[self.group]
        self.change_rate = np.maximum(1.0, cr * np.clip(1.0 + j * rng.standard_normal(n), 0.5, 1.5))
        self.lo = np.asarray(config.bounds[0], dtype=np.float64)[:, None]
        self.hi = np.asarray(config.bounds[1], dtype=np.float64)[:, None]
        self.pos = self._layout(rng)
        d = _random_units(rng, n, vertical=WANDER_VERTICAL)
        if config.model == "pso":
            speed = 0.1 * config.pso.max_speed * self.length   # Figure 2.2: InitialSpeed 0.1 of 0-1
        else:
            speed = self.cruise.copy()
        self.dir = d
        self.vel = d * speed
        # wander spline state: previous and next random point (as directions), phase in frames
        self.w_prev = d.copy()
        self.w_next = _random_units(rng, n, vertical=WANDER_VERTICAL)
        self.w_phase = rng.uniform(0.0, 1.0, n) * self.change_rate
        self.w_pool, self.w_used = np.empty((3, 0)), 0
        self.fallback = _random_units(rng, n, vertical=1.0)  # push-apart direction for coincident fish
        self.refresh = 1
        if n >= NEIGHBOUR_REFRESH_FISH:
            self.refresh = max(1, int(NEIGHBOUR_REFRESH_SECONDS * config.fps))
        # Threads pay off only for big trees: below that the locks cost more than the queries.
        self.workers = -1 if n >= PARALLEL_QUERY_FISH else 1
        self.k = max(1, min(int(config.neighbours), n - 1)) if n > 1 else 0
        # per-fish constants of the urges (hot path: no per-step recomputation)
        cruise = self.cruise
        self.g_center = GAIN_CENTER * w["center"] * cruise
        self.g_direction = GAIN_DIRECTION * w["direction"] * cruise
        self.g_keepaway = GAIN_KEEPAWAY * w["keepaway"] * cruise
        self.g_contact = GAIN_CONTACT * cruise
        self.g_speed = GAIN_SPEED * w["speed"]
        self.g_random = GAIN_RANDOM * w["random"] * cruise
        self.g_bounds = 2.0 * GAIN_BOUNDS * cruise
        self.perception = config.perception * self.length
        self.inv_length = 1.0 / self.length
        self.inv_repel = 1.0 / np.maximum(self.repel, 1e-12)
        self.ones = np.ones((1, n))
        margin = np.minimum(BOUNDS_MARGIN * self.length, 0.25 * (self.hi - self.lo))   # (3, N)
        self.inner_lo, self.inner_hi, self.inv_margin = self.lo + margin, self.hi - margin, 1.0 / margin
        self._neighbours()
        for _ in range(4):
            self._separate()
        self._clamp()

    # ----------------------------------------------------------------- start layout
    def _layout(self, rng: np.random.Generator) -> np.ndarray:
        cfg, n = self.cfg, self.n
        lo, hi = self.lo[:, 0], self.hi[:, 0]
        extent = hi - lo
        centre = (lo + hi) / 2
        pos = np.empty((n, 3))
        for g, group in enumerate(cfg.groups):
            sel = self.group == g
            m = int(sel.sum())
            if m == 0:
                continue
            spacing = LAYOUT_SPACING * group.body_length
            gc = centre.copy()
            if self.n_groups > 1:  # each species starts in its own place along X
                gc[0] = lo[0] + (g + 0.5) * extent[0] / self.n_groups
            room = extent / (2 * max(1, self.n_groups) if cfg.layout != "box" else 2)
            if cfg.layout == "sphere":
                r = spacing * np.cbrt(3.0 * m / (4.0 * np.pi))
                r = min(r, 0.45 * float(np.min(extent)), 0.9 * float(room[0]))
                u = _random_units(rng, m, vertical=1.0).T
                pos[sel] = gc + u * (r * np.cbrt(rng.uniform(0.0, 1.0, m)))[:, None]
            elif cfg.layout == "box":
                inset = np.minimum(group.body_length, 0.25 * extent)
                sub_lo, sub_hi = lo + inset, hi - inset
                if self.n_groups > 1:
                    sub_lo = sub_lo.copy()
                    sub_hi = sub_hi.copy()
                    sub_lo[0] = lo[0] + g * extent[0] / self.n_groups + inset[0]
                    sub_hi[0] = lo[0] + (g + 1) * extent[0] / self.n_groups - inset[0]
                pos[sel] = rng.uniform(sub_lo, sub_hi, (m, 3))
            else:  # line along X (or along Z per species when there are several)
                axis = 0 if self.n_groups == 1 else 2
                width = min(m * spacing, 0.9 * float(extent[axis]))
                p = np.tile(gc, (m, 1))
                p[:, axis] += np.linspace(-width / 2, width / 2, m)
                p += rng.normal(0.0, 0.05 * spacing, (m, 3))
                pos[sel] = p
        return np.ascontiguousarray(np.clip(pos, lo, hi).T)

    # ----------------------------------------------------------------- neighbours
    def _neighbours(self) -> None:
        """k nearest same-species (`nb`), 4 nearest of any species (`near`), nearest other species,
        each as (k, N), and the per-pair constants the step reads with them."""
        nb, nb_ok, near, near_ok = self._find_neighbours()
        self.nb, self.nb_ok = np.ascontiguousarray(nb.T), np.ascontiguousarray(nb_ok.T)
        self.near, self.near_ok = np.ascontiguousarray(near.T), np.ascontiguousarray(near_ok.T)
        self.near_need = HARD_SEPARATION * 0.5 * (self.length + self.length[self.near])
        self.inv_near_reach = 1.0 / np.maximum(self.near_need * (CONTACT_DISTANCE / HARD_SEPARATION), 1e-12)
        self.nb_perception = np.where(self.nb_ok, self.perception, -1.0)  # no mate: never seen
        self.near_is_nb = self.n_groups == 1 and self.k >= self.near.shape[0]  # `near` = first of `nb`

    def _find_neighbours(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(nb, nb_ok, near, near_ok) as (N, k) from k-d trees; sets `other`."""
        n = self.n
        pos = self.pos.T
        nb = np.zeros((n, max(self.k, 1)), dtype=np.int64)
        nb_ok = np.zeros((n, max(self.k, 1)), dtype=bool)
        self.other: np.ndarray | None = None
        if n < 2:
            return nb, nb_ok, np.zeros((n, 1), dtype=np.int64), np.zeros((n, 1), dtype=bool)
        m = min(4, n - 1)
        tree = cKDTree(pos)
        k_all = max(self.k, m) if self.n_groups == 1 else m
        _, idx = tree.query(pos, k=k_all + 1, workers=self.workers)
        idx = idx[:, 1:]  # drop self (nearest; coincident fish are separated beforehand)
        near = idx[:, :m]
        near_ok = near != np.arange(n)[:, None]
        if self.n_groups == 1:
            nb = idx[:, : self.k]
            return nb, nb != np.arange(n)[:, None], near, near_ok
        other = np.full(n, -1, dtype=np.int64)
        other_d = np.full(n, np.inf)
        for g in range(self.n_groups):
            members = np.flatnonzero(self.group == g)
            if members.size == 0:
                continue
            t = cKDTree(pos[members])
            kk = min(self.k + 1, members.size)
            _, li = t.query(pos[members], k=kk, workers=self.workers)
            li = li.reshape(members.size, kk)[:, 1:]
            got = li.shape[1]
            nb[members, :got] = members[li]
            nb_ok[members, :got] = members[li] != members[:, None]
            outsiders = np.flatnonzero(self.group != g)
            if outsiders.size:
                dd, oi = t.query(pos[outsiders], k=1, workers=self.workers)
                better = dd < other_d[outsiders]
                other[outsiders[better]] = members[oi[better]]
                other_d[outsiders[better]] = dd[better]
        self.other = other
        return nb, nb_ok, near, near_ok

    # ----------------------------------------------------------------- one step
    def step(self, frame: int, target: np.ndarray | None, predator: np.ndarray | None) -> None:
        if self.n == 0:
            return
        if frame % self.refresh == 0:
            self._neighbours()
        boids = self.cfg.model != "pso"
        if not (boids and self.near_is_nb):
            # from each of the few nearest fish (any species) to me, and how far: shared by the urges
            self.near_to = np.take(self.pos, self.near, axis=1) - self.pos[:, None, :]
            self.near_dist = _norm(self.near_to)
        max_turn: np.ndarray | float
        if boids:
            new_vel, max_turn, v_min, v_max = self._boids()
        else:
            new_vel, max_turn, v_min, v_max = self._pso(target)
            if self.n > 1:
                new_vel += self._push(self._contact_strength()) * self.dt
        acc = self._bounds_accel()
        if self.other is not None:
            acc += self._other_species_accel()
        flee_boost = np.zeros(self.n)
        if predator is not None:
            fa, flee_boost = self._flee_accel(predator)
            acc += fa
        new_vel += acc * self.dt
        v_max = v_max * (1.0 + FLEE_SPEEDUP * flee_boost)
        self.dir = _turn_towards(self.dir, new_vel, max_turn * self.dt)
        speed = np.minimum(np.maximum(_norm(new_vel), v_min), v_max)
        if predator is not None:  # fleeing fish speed up
            fast = np.minimum(v_max, self.cruise * (1.0 + FLEE_SPEEDUP * flee_boost))
            speed = np.where(flee_boost > 0, np.maximum(speed, fast), speed)
        self.vel = self.dir * speed
        self.pos = self.pos + self.vel * self.dt
        if self.n > 1:
            # only fish that were within one step's closing distance of a too-near neighbour can be
            # too near now (pairs close by at most both speeds x dt; the pushes add a little more)
            closing = 2.5 * float(np.max(v_max)) * self.dt
            rows = np.flatnonzero(np.any(self.near_dist < self.near_need + closing, axis=0))
            for _ in range(SEPARATION_PASSES):
                self._separate(rows)
        self._clamp()

    def _boids(self) -> tuple[np.ndarray, np.ndarray | float, np.ndarray, np.ndarray]:
        pos, d, v = self.pos, self.dir, self.vel
        cruise = self.cruise
        # keep own velocity (relax towards cruising speed along the heading) and the wander spline
        acc = self.g_speed * (d * cruise - v) + self.g_random * (self._wander() - d)
        if self.n > 1:
            # one gather of the school-mates' positions, headings and a 1 (their count): (7, k, N)
            mates = np.take(np.concatenate([pos, d, self.ones]), self.nb, axis=1)
            off = mates[:3] - pos[:, None, :]  # me to them
            dist = _norm(off)
            seen = (dist < self.nb_perception).astype(np.float64)
            sums = np.einsum("kn,ckn->cn", seen, mates)
            cnt = sums[6]
            has = cnt > 0
            mean = has / np.maximum(cnt, 1.0)
            # cohesion: towards the centre of the perceived school-mates, in body lengths, capped
            coh = (sums[:3] - cnt * pos) * (mean * self.inv_length)
            acc += self.g_center / np.maximum(_norm(coh), 1.0) * coh
            # alignment: towards their mean heading
            acc += self.g_direction * (sums[3:6] * mean - d * has)
            if self.near_is_nb:
                m = self.near.shape[0]
                self.near_to = off[:, :m]
                self.near_dist = dist[:m]
            # keepaway inside the repel distance (any species), and bodies that nearly touch push
            # apart whatever the brain (the swim-through fix): one weighted sum over the nearest
            dist = self.near_dist
            strength = np.maximum(1.0 - dist * self.inv_near_reach, 0.0) * self.g_contact
            strength += np.maximum(1.0 - dist * self.inv_repel, 0.0) * self.g_keepaway
            strength *= self.near_ok / np.maximum(dist, 1e-12)
            acc += self._push(strength)
        new_vel = v + acc * self.dt
        return new_vel, self.cfg.max_turn, MIN_SPEED * cruise, cruise * 2.0

    def _contact_strength(self) -> np.ndarray:
        """Per nearest fish: 1 at contact falling to 0 at the contact distance, over the distance."""
        dist = self.near_dist
        reach = np.maximum(1.0 - dist * self.inv_near_reach, 0.0) * self.near_ok
        return reach / np.maximum(dist, 1e-12)

    def _push(self, strength: np.ndarray) -> np.ndarray:
        """Sum over the nearest fish of strength x offset away from them."""
        return -np.einsum("kn,ckn->cn", strength, self.near_to)

    def _wander(self) -> np.ndarray:
        """A point on each fish's wander spline (as a direction); new random point every change_rate."""
        self.w_phase += 1.0
        due = self.w_phase >= self.change_rate
        if due.any():
            idx = np.flatnonzero(due)
            self.w_phase[idx] -= self.change_rate[idx]
            self.w_prev[:, idx] = self.w_next[:, idx]
            self.w_next[:, idx] = self._wander_points(idx.size)
        h = np.minimum(np.maximum(self.w_phase / self.change_rate, 0.0), 1.0)
        h = h * h * (3.0 - 2.0 * h)
        u = self.w_prev + h * (self.w_next - self.w_prev)
        return u / np.maximum(_norm(u), 1e-9)

    def _wander_points(self, count: int) -> np.ndarray:
        """The next `count` random wander points, drawn many at a time: a few fish need one each
        frame, and one draw per frame cost more than the rest of the wander spline."""
        if self.w_pool.shape[1] - self.w_used < count:
            self.w_pool = _random_units(self.rng, max(WANDER_POOL, count), vertical=WANDER_VERTICAL)
            self.w_used = 0
        self.w_used += count
        return self.w_pool[:, self.w_used - count:self.w_used]

    def _pso(self, target: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        p = self.cfg.pso
        pos, v, L, rng = self.pos, self.vel, self.length, self.rng
        n = self.n
        assert target is not None
        dist_t = _norm(pos - target[:, None])
        # global best per species: the fish nearest the target; the leader itself seeks the target
        best = np.empty((3, n))
        for g in range(self.n_groups):
            members = np.flatnonzero(self.group == g)
            if members.size == 0:
                continue
            lead = members[np.argmin(dist_t[members])]
            best[:, members] = pos[:, lead, None]
            best[:, lead] = target
        r = rng.uniform(0.0, 1.0, (n, 3))
        force = np.zeros((3, n))
        if n > 1:
            away = -self.near_to[:, 0]
            d1 = self.near_dist[0]
            inside = (d1 < p.repulsion_radius * L) & self.near_ok[0]
            slow = np.where(inside, p.slowdown, 1.0)
            force += (inside * p.repulsion * r[:, 1] * L / np.maximum(d1, 1e-12)) * away
            second, ok2 = (self.nb[1], self.nb_ok[1]) if self.nb.shape[0] > 1 else (self.nb[0], self.nb_ok[0])
            force += (slow * p.attraction * r[:, 2] * ok2) * (pos[:, second] - pos)
        else:
            slow = np.ones(n)
        force += (slow * p.global_weight * r[:, 0]) * (best - pos)
        w_eff = p.inertia ** (self.dt / PSO_REFERENCE_DT)
        gain = (1.0 - w_eff) / (1.0 - p.inertia) if p.inertia < 1.0 else self.dt / PSO_REFERENCE_DT
        new_vel = w_eff * v + gain * force
        max_turn = np.clip(p.turn_rate * dist_t, PSO_MIN_TURN * self.cfg.max_turn, self.cfg.max_turn)
        v_max = p.max_speed * L
        return new_vel, max_turn, MIN_SPEED * 0.5 * v_max, v_max

    # ----------------------------------------------------------------- shared urges
    def _bounds_accel(self) -> np.ndarray:
        pos = self.pos
        below = np.minimum(np.maximum((self.inner_lo - pos) * self.inv_margin, 0.0), 1.0)
        above = np.minimum(np.maximum((pos - self.inner_hi) * self.inv_margin, 0.0), 1.0)
        return self.g_bounds * (below - above)

    def _other_species_accel(self) -> np.ndarray:
        if self.other is None:
            return np.zeros_like(self.pos)
        ok = self.other >= 0
        off = self.pos - self.pos[:, np.where(ok, self.other, 0)]
        dist = _norm(off)
        radius = OTHER_SPECIES_DISTANCE * self.length
        strength = np.clip(1.0 - dist / radius, 0.0, None) * ok * self.w["keepaway"]
        return (GAIN_OTHER_SPECIES * self.cruise * strength / np.maximum(dist, 1e-12)) * off

    def _flee_accel(self, predator: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        off = self.pos - predator[:, None]
        dist = _norm(off)
        near = np.clip(1.0 - dist / np.maximum(self.flee_dist, 1e-12), 0.0, 1.0)
        near = near * (self.w["flee"] > 0)
        acc = (GAIN_FLEE * self.w["flee"] * self.cruise * near / np.maximum(dist, 1e-12)) * off
        return acc, np.sqrt(near)

    # ----------------------------------------------------------------- constraints
    def _separate(self, rows: np.ndarray | None = None) -> None:
        """Push apart pairs closer than HARD_SEPARATION mean body lengths (each side moves half).

        `rows`: only these fish (the others are known to be clear of their nearest this step)."""
        if self.n < 2:
            return
        pos = self.pos
        near, need, ok = self.near, self.near_need, self.near_ok
        if rows is not None:
            if rows.size == 0:
                return
            near, need, ok = near[:, rows], need[:, rows], ok[:, rows]
        mine = pos if rows is None else pos[:, rows]
        off = mine[:, None, :] - np.take(pos, near, axis=1)     # from neighbour to me: (3, m, rows)
        dist = _norm(off)
        short = np.maximum(need - dist, 0.0) * ok
        if not short.any():
            return
        tiny = dist < 1e-9
        push = np.einsum("kn,ckn->cn", short / np.maximum(dist, 1e-12), off)
        if tiny.any():  # coincident fish: each goes its own fixed random way
            fallback = self.fallback if rows is None else self.fallback[:, rows]
            push += (short * tiny).sum(axis=0) * fallback
        if rows is None:
            self.pos = pos + 0.5 * push
        else:
            self.pos[:, rows] += 0.5 * push

    def _clamp(self) -> None:
        np.clip(self.pos, self.lo, self.hi, out=self.pos)


def _norm(v: np.ndarray) -> np.ndarray:
    """Lengths of component-major vectors: (3, ...) -> (...)."""
    return np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


def _turn_towards(d: np.ndarray, want: np.ndarray, max_angle: np.ndarray | float) -> np.ndarray:
    """Unit directions `d` (3, N) rotated towards `want` by at most `max_angle` radians.

    A fish that wants to turn by less than that simply takes the wanted direction; only the others
    (few, once a school has formed) pay for the rotation's trigonometry."""
    wn = _norm(want)
    t = np.where(wn > 1e-12, want / np.maximum(wn, 1e-12), d)
    c = np.minimum(np.maximum(d[0] * t[0] + d[1] * t[1] + d[2] * t[2], -1.0), 1.0)
    limit = np.cos(np.minimum(max_angle, np.pi))
    rows = np.flatnonzero(c < limit)
    if rows.size == 0:
        return t
    d_r, c_r = d[:, rows], c[rows]
    perp = t[:, rows] - c_r * d_r
    pn = _norm(perp)
    flat = pn < 1e-9
    if flat.any():  # exactly behind: turn about the vertical, or about X if vertical
        alt = np.cross(d_r[:, flat].T, np.array([0.0, 1.0, 0.0]))
        bad = np.linalg.norm(alt, axis=1) < 1e-6
        alt[bad] = np.cross(d_r[:, flat][:, bad].T, np.array([1.0, 0.0, 0.0]))
        perp[:, flat] = alt.T
        pn[flat] = np.linalg.norm(alt, axis=1)
    a = np.minimum(np.arccos(c_r), max_angle if np.ndim(max_angle) == 0 else np.asarray(max_angle)[rows])
    out = np.cos(a) * d_r + (np.sin(a) / pn) * perp
    t[:, rows] = out / _norm(out)
    return t


def _random_units(rng: np.random.Generator, n: int, vertical: float) -> np.ndarray:
    """n random unit directions as (3, n), flattened vertically by `vertical`."""
    u = rng.standard_normal((n, 3)).T.copy()
    u[1] *= vertical
    return u / np.maximum(_norm(u), 1e-12)


def _check(config: SchoolConfig) -> None:
    if not config.fps > 0 or not np.isfinite(config.fps):
        raise ValueError(f"fps must be > 0, found {config.fps}")
    if config.frames < 1:
        raise ValueError(f"frames must be >= 1, found {config.frames}")
    lo, hi = np.asarray(config.bounds[0], float), np.asarray(config.bounds[1], float)
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(hi > lo)):
        raise ValueError(f"bounds must be finite with min < max, found {config.bounds}")
    for g in config.groups:
        if g.count < 0 or not g.body_length > 0:
            raise ValueError(f"group {g.name!r}: count >= 0 and body_length > 0 needed")
