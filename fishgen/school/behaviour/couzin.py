"""Couzin, Krause, James, Ruxton & Franks (2002), "Collective memory and spatial sorting in animal
groups", J. Theor. Biol. 218, 1-11: zones of repulsion, orientation and attraction.

Each step a fish wants to head:

- away from every school-mate inside the zone of repulsion (radius rr), if there is one: d_r =
  -sum of the unit vectors towards them (this rule alone);
- otherwise along d_o, its own heading plus those of the school-mates it sees in the zone of
  orientation (rr to rr + delta ro); towards d_a, the sum of the unit vectors towards those it
  sees in the zone of attraction (to rr + delta ro + delta ra); or half of each (both made unit
  first) when both zones hold fish; with nobody in either, straight on.

A fish sees all round but for a cone of `blind_angle` straight behind it (the paper's field of
perception alpha = 360 - blind angle); the zone of repulsion is felt all round. The wanted
heading is turned by a random angle (s.d. `noise` per 0.1 s, the paper's time step tau, scaled by
sqrt(dt / tau) so that the heading diffuses alike at any frame rate), and the fish turns towards
it by at most `turning_rate` (the shared turn limit; faster next to the region's walls, which the
paper's open water has none of), swimming at its cruising speed. The paper's
states depend on its turning radius s / theta (4.3 zone widths at s = 3, theta = 40 degrees/s), so
a fish swimming at another speed turns, and wanders, in proportion: the paper's clock runs at
cruise / `speed` of ours.

The zones are the paper's, metric; the paper's group of 100 sees every school-mate. A school-mate
in a zone counts whether it is near or far, so in a bigger school each fish takes its
`neighbours` nearest exactly and a fresh random sample of `sampled` of the others each step,
weighted so that their sum is the whole school's on average (a Horvitz-Thompson estimate). With
as many school-mates as the two together, every one is taken exactly.
"""
from __future__ import annotations

import math

import numpy as np

from fishgen.school.behaviour import Want
from fishgen.school.model import SchoolConfig
from fishgen.school.neighbours import Neighbours
from fishgen.school.state import SchoolState, norm

PAPER_TAU = 0.1            # seconds: the paper's time step, the unit of its noise


class Couzin:
    def __init__(self, config: SchoolConfig, state: SchoolState) -> None:
        p = config.couzin
        counts = np.bincount(state.group, minlength=state.n_groups)
        self.exact = int(counts.max(initial=0)) - 1 <= p.neighbours + p.sampled
        self.neighbours = int(p.neighbours + p.sampled) if self.exact else int(p.neighbours)
        self.sampled = 0 if self.exact else int(p.sampled)
        length = state.length
        self.r_rep = p.repulsion * length
        self.r_ori = (p.repulsion + p.orientation) * length
        self.r_att = p.reach * length
        # seen when the angle from the heading is at most half the field of perception
        self.cos_seen = math.cos(math.radians(min(max(360.0 - p.blind_angle, 0.0), 360.0)) / 2)
        # the paper's clock runs at cruise / speed of ours: its turning radius and its noise per
        # distance swum hold at any speed
        clock = state.cruise / state.length / p.speed
        self.max_turn = math.radians(p.turning_rate) * clock
        self.wall_turn = float(config.max_turn)
        self.sigma = p.noise * np.sqrt(state.dt * clock / PAPER_TAU)
        self.noisy = p.noise > 0
        # each fish's species as a run of fish indices (state.group is sorted): where samples come from
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        self.first, self.count = starts[state.group], counts[state.group]
        self.far_weight = np.maximum(self.count - 1, 0) / max(self.sampled, 1)

    def want(self, state: SchoolState, nbrs: Neighbours, target: np.ndarray | None) -> Want:
        pos, d = state.pos, state.dir
        n = state.n
        wanted = d.copy()
        if n > 1:
            mates = np.take(np.concatenate([pos, d]), nbrs.nb, axis=1)   # (6, k, N)
            rep, ori, att, off, dist = self._zones(pos, d, mates, nbrs.nb_ok)
            d_r = -np.einsum("kn,ckn->cn", rep / np.maximum(dist, 1e-12), off)
            d_o = d + np.einsum("kn,ckn->cn", ori, mates[3:])
            d_a = np.einsum("kn,ckn->cn", att / np.maximum(dist, 1e-12), off)
            has_o, has_a = ori.any(axis=0), att.any(axis=0)
            if self.sampled:
                far, far_ok = self._sample(state.rng, n)
                fmates = np.take(np.concatenate([pos, d]), far, axis=1)
                # the near lists hold everyone inside their farthest member: samples there are theirs
                beyond = far_ok & (norm(fmates[:3] - pos[:, None, :]) > dist.max(axis=0))
                _, f_ori, f_att, f_off, f_dist = self._zones(pos, d, fmates, beyond)
                w = self.far_weight
                d_o += w * np.einsum("kn,ckn->cn", f_ori, fmates[3:])
                d_a += w * np.einsum("kn,ckn->cn", f_att / np.maximum(f_dist, 1e-12), f_off)
                has_o |= f_ori.any(axis=0)
                has_a |= f_att.any(axis=0)
            d_o /= np.maximum(norm(d_o), 1e-12)
            d_a /= np.maximum(norm(d_a), 1e-12)
            social = np.where(has_o & has_a, 0.5 * (d_o + d_a), np.where(has_o, d_o, d_a))
            wanted = np.where(has_o | has_a, social, wanted)
            wanted = np.where(rep.any(axis=0), d_r, wanted)
            if nbrs.near_is_nb:
                m = nbrs.near.shape[0]
                nbrs.set_near_offsets(off[:, :m], dist[:m])
            size = norm(wanted)
            wanted = np.where(size > 1e-9, wanted / np.maximum(size, 1e-12), d)
        if self.noisy:  # a random turn: a Gaussian step at right angles to the wanted heading
            kick = state.rng.standard_normal((3, n)) * self.sigma
            kick -= (kick[0] * wanted[0] + kick[1] * wanted[1] + kick[2] * wanted[2]) * wanted
            wanted = wanted + kick
            wanted /= np.maximum(norm(wanted), 1e-12)
        cruise = state.cruise
        return Want(wanted * cruise, self._turn_rate(state), cruise, cruise)

    def _turn_rate(self, state: SchoolState) -> np.ndarray:
        """The paper's turning rate; the paper's fish swim in open water, so inside the margin of
        the region's walls a fish may turn up to the other models' rate (config.max_turn) as the
        wall nears, else its turning radius would carry it into the wall."""
        pos = state.pos
        below = np.minimum(np.maximum((state.inner_lo - pos) * state.inv_margin, 0.0), 1.0)
        above = np.minimum(np.maximum((pos - state.inner_hi) * state.inv_margin, 0.0), 1.0)
        wall = np.maximum(below, above).max(axis=0)
        return np.maximum(self.max_turn, self.wall_turn * wall)

    def _zones(self, pos: np.ndarray, d: np.ndarray, mates: np.ndarray, ok: np.ndarray):
        """Which of `mates` (6, k, N: positions, headings) are in each zone, as 0/1 floats (k, N);
        and the offsets to them (3, k, N) and their distances."""
        off = mates[:3] - pos[:, None, :]                                # me to them
        dist = norm(off)
        ahead = np.einsum("ckn,cn->kn", off, d)                          # |off| cos(angle)
        seen = ok & (ahead >= self.cos_seen * dist)
        rep = (ok & (dist < self.r_rep)).astype(np.float64)
        ori = (seen & (dist >= self.r_rep) & (dist < self.r_ori)).astype(np.float64)
        att = (seen & (dist >= self.r_ori) & (dist < self.r_att)).astype(np.float64)
        return rep, ori, att, off, dist

    def _sample(self, rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
        """`sampled` random school-mates of each fish (M, N), drawn with replacement, and which are
        not the fish itself."""
        pick = self.first + (rng.random((self.sampled, n)) * self.count).astype(np.int64)
        return pick, pick != np.arange(n)
