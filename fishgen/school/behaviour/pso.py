"""The 2017 report's particle swarm (eq. 2.1-2.2, Figure 2.2), following a target.

Each fish is pulled towards the global best (the fish of its species nearest the target; that
fish towards the target itself) and its second-nearest neighbour, and pushed from its nearest
inside the repulsion radius, each term with its own uniform random number; inertia re-timed from
the report's dt = 0.05. The turn rate grows with the distance to the target.
"""
from __future__ import annotations

import numpy as np

from fishgen.school.behaviour import Want
from fishgen.school.model import SchoolConfig
from fishgen.school.neighbours import Neighbours
from fishgen.school.state import SchoolState, norm

PSO_REFERENCE_DT = 0.05    # Figure 2.2's time step; inertia is re-timed from it
PSO_MIN_TURN = 0.25        # x max_turn: the least turn rate a pso fish has next to the target
MIN_SPEED = 0.15           # x max_speed
START_SPEED = 0.1          # x max_speed: Figure 2.2's InitialSpeed 0.1 of 0-1


class Pso:
    def __init__(self, config: SchoolConfig, state: SchoolState) -> None:
        self.neighbours = int(config.neighbours)
        self.p = config.pso
        self.max_turn = float(config.max_turn)
        state.vel = state.dir * (START_SPEED * config.pso.max_speed * state.length)

    def want(self, state: SchoolState, nbrs: Neighbours, target: np.ndarray | None) -> Want:
        p = self.p
        pos, v, L, rng = state.pos, state.vel, state.length, state.rng
        n = state.n
        assert target is not None
        dist_t = norm(pos - target[:, None])
        # global best per species: the fish nearest the target; the leader itself seeks the target
        best = np.empty((3, n))
        for g in range(state.n_groups):
            members = np.flatnonzero(state.group == g)
            if members.size == 0:
                continue
            lead = members[np.argmin(dist_t[members])]
            best[:, members] = pos[:, lead, None]
            best[:, lead] = target
        r = rng.uniform(0.0, 1.0, (n, 3))
        force = np.zeros((3, n))
        if n > 1:
            near_to, near_dist = nbrs.near_offsets()
            away = -near_to[:, 0]
            d1 = near_dist[0]
            inside = (d1 < p.repulsion_radius * L) & nbrs.near_ok[0]
            slow = np.where(inside, p.slowdown, 1.0)
            force += (inside * p.repulsion * r[:, 1] * L / np.maximum(d1, 1e-12)) * away
            nb, nb_ok = nbrs.nb, nbrs.nb_ok
            second, ok2 = (nb[1], nb_ok[1]) if nb.shape[0] > 1 else (nb[0], nb_ok[0])
            force += (slow * p.attraction * r[:, 2] * ok2) * (pos[:, second] - pos)
        else:
            slow = np.ones(n)
        force += (slow * p.global_weight * r[:, 0]) * (best - pos)
        w_eff = p.inertia ** (state.dt / PSO_REFERENCE_DT)
        gain = (1.0 - w_eff) / (1.0 - p.inertia) if p.inertia < 1.0 else state.dt / PSO_REFERENCE_DT
        new_vel = w_eff * v + gain * force
        if n > 1:  # bodies that nearly touch push apart (the shared contact push)
            new_vel += nbrs.push(nbrs.contact_strength()) * state.dt
        max_turn = np.clip(p.turn_rate * dist_t, PSO_MIN_TURN * self.max_turn, self.max_turn)
        v_max = p.max_speed * L
        return Want(new_vel, max_turn, MIN_SPEED * v_max, v_max)
