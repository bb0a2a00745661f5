"""VRFish's brain (Lobb 2002, ch. 7.2): Reynolds' rules weighted by the species file's urges.

Each urge is an acceleration in body lengths, its gain a base gain x the file's weight / the
Appendix A weight (docs/decisions.md, Schools): keep own speed, follow the wander spline, move
towards the centre of the perceived school-mates and match their heading, keep away from the
nearest fish inside the repel distance; bodies that nearly touch push apart whatever the weights.
"""
from __future__ import annotations

import numpy as np

from fishgen.school.behaviour import Want
from fishgen.school.model import SchoolConfig
from fishgen.school.neighbours import Neighbours
from fishgen.school.state import SchoolState, norm

# Base gains (1/s) that make the Appendix A brain school (tuned by the tests' measures).
GAIN_RANDOM = 0.5
GAIN_CENTER = 1.0
GAIN_KEEPAWAY = 8.0
GAIN_SPEED = 1.0
GAIN_DIRECTION = 6.0
GAIN_CONTACT = 10.0
MIN_SPEED = 0.3            # x cruise
SCHOOL_HEADING = 0.2       # share of the whole school's mean heading in the alignment target
MAX_SPEED = 2.0            # x cruise


class Boids:
    def __init__(self, config: SchoolConfig, state: SchoolState) -> None:
        self.neighbours = int(config.neighbours)
        self.max_turn = float(config.max_turn)
        w, cruise = state.weights, state.cruise
        self.g_center = GAIN_CENTER * w["center"] * cruise
        self.g_direction = GAIN_DIRECTION * w["direction"] * cruise
        self.g_keepaway = GAIN_KEEPAWAY * w["keepaway"] * cruise
        self.g_contact = GAIN_CONTACT * cruise
        self.g_speed = GAIN_SPEED * w["speed"]
        self.g_random = GAIN_RANDOM * w["random"] * cruise
        self.perception = config.perception * state.length
        self.inv_length = 1.0 / state.length
        self.inv_repel = 1.0 / np.maximum(state.repel, 1e-12)
        self.ones = np.ones((1, state.n))
        self._version = -1
        self.group, self.n_groups = state.group, state.n_groups
        others = np.bincount(state.group, minlength=state.n_groups)[state.group] - 1
        self.inv_others = np.where(others > 0, 1.0 / np.maximum(others, 1), 0.0)

    def _school_heading(self, d: np.ndarray) -> np.ndarray:
        """Each fish's mean heading of the rest of its species (3, N): VRFish's "average direction
        of the school" (7.2), over every fish of the species but itself."""
        if self.n_groups == 1:
            total = d.sum(axis=1, keepdims=True)
        else:
            total = np.stack([np.bincount(self.group, d[c], minlength=self.n_groups) for c in range(3)])
            total = total[:, self.group]
        return (total - d) * self.inv_others

    def want(self, state: SchoolState, nbrs: Neighbours, target: np.ndarray | None) -> Want:
        pos, d, v = state.pos, state.dir, state.vel
        cruise = state.cruise
        # keep own velocity (relax towards cruising speed along the heading) and the wander spline
        acc = self.g_speed * (d * cruise - v) + self.g_random * (state.wander.point() - d)
        if state.n > 1:
            if self._version != nbrs.version:
                self.nb_perception = np.where(nbrs.nb_ok, self.perception, -1.0)  # no mate: never seen
                self._version = nbrs.version
            # one gather of the school-mates' positions, headings and a 1 (their count): (7, k, N)
            mates = np.take(np.concatenate([pos, d, self.ones]), nbrs.nb, axis=1)
            off = mates[:3] - pos[:, None, :]  # me to them
            dist = norm(off)
            seen = (dist < self.nb_perception).astype(np.float64)
            sums = np.einsum("kn,ckn->cn", seen, mates)
            cnt = sums[6]
            has = cnt > 0
            mean = has / np.maximum(cnt, 1.0)
            # cohesion: towards the centre of the perceived school-mates, in body lengths, capped
            coh = (sums[:3] - cnt * pos) * (mean * self.inv_length)
            acc += self.g_center / np.maximum(norm(coh), 1.0) * coh
            # alignment: towards their mean heading, and the whole school's (the thesis' cue)
            heading = (1.0 - SCHOOL_HEADING) * (sums[3:6] * mean) + SCHOOL_HEADING * self._school_heading(d)
            acc += self.g_direction * (heading - d * has)
            if nbrs.near_is_nb:
                m = nbrs.near.shape[0]
                nbrs.set_near_offsets(off[:, :m], dist[:m])
            # keepaway inside the repel distance (any species), and bodies that nearly touch push
            # apart whatever the brain (the swim-through fix): one weighted sum over the nearest
            _, dist = nbrs.near_offsets()
            strength = np.maximum(1.0 - dist * nbrs.inv_near_reach, 0.0) * self.g_contact
            strength += np.maximum(1.0 - dist * self.inv_repel, 0.0) * self.g_keepaway
            strength *= nbrs.near_ok / np.maximum(dist, 1e-12)
            acc += nbrs.push(strength)
        return Want(v + acc * state.dt, self.max_turn, MIN_SPEED * cruise, cruise * MAX_SPEED)
