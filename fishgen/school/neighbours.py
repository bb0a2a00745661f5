"""Who each fish perceives: its k nearest school-mates (same species), its few nearest fish of any
species (keep-away, contact and separation), and its nearest fish of another species, from
scipy's k-d tree.

The lists are rebuilt every frame below NEIGHBOUR_REFRESH_FISH fish, else at most
NEIGHBOUR_REFRESH_SECONDS of simulated time apart (the k nearest change slowly), while every
distance is measured from the current positions each frame. Every list is logged (NeighbourLog),
so the measures reuse them instead of searching again.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree  # type: ignore[import-untyped]

from fishgen.school.model import NeighbourLog
from fishgen.school.state import SchoolState, norm

HARD_SEPARATION = 0.6      # mean body lengths: centres never closer (metrics flag < 0.5)
CONTACT_DISTANCE = 0.8     # mean body lengths: bodies push apart inside this, whatever the brain
NEAR = 4                   # fish of any species each fish keeps clear of
NEIGHBOUR_REFRESH_FISH = 300
NEIGHBOUR_REFRESH_SECONDS = 0.5
PARALLEL_QUERY_FISH = 5000
LOGGED = 8                 # school-mates per fish kept in the log (the measures' links)


class Neighbours:
    """The current lists as (k, N) arrays, and per step the offsets to the nearest fish."""

    def __init__(self, state: SchoolState, k: int, log: NeighbourLog | None = None) -> None:
        n = state.n
        self.state = state
        self.log = log
        self.k = max(1, min(int(k), n - 1)) if n > 1 else 0
        self.refresh_every = 1
        if n >= NEIGHBOUR_REFRESH_FISH:
            self.refresh_every = max(1, int(NEIGHBOUR_REFRESH_SECONDS * state.config.fps))
        # Threads pay off only for big trees: below that the locks cost more than the queries.
        self.workers = -1 if n >= PARALLEL_QUERY_FISH else 1
        self.version = 0           # counts rebuilds: models cache per-list constants by it
        self.other: np.ndarray | None = None
        self.near_to: np.ndarray | None = None
        self.near_dist: np.ndarray | None = None

    def due(self, frame: int) -> bool:
        return frame % self.refresh_every == 0

    def refresh(self, frame: int) -> None:
        """Rebuild the lists from the current positions, and the per-pair constants read with them."""
        state = self.state
        nb, nb_ok, near, near_ok, logged, logged_ok = self._find()
        self.nb, self.nb_ok = np.ascontiguousarray(nb.T), np.ascontiguousarray(nb_ok.T)
        self.near, self.near_ok = np.ascontiguousarray(near.T), np.ascontiguousarray(near_ok.T)
        length = state.length
        self.near_need = HARD_SEPARATION * 0.5 * (length + length[self.near])
        self.inv_near_reach = 1.0 / np.maximum(self.near_need * (CONTACT_DISTANCE / HARD_SEPARATION), 1e-12)
        # `near` is then the first rows of `nb`, and a model that gathers `nb` has its offsets
        self.near_is_nb = state.n_groups == 1 and self.k >= self.near.shape[0] and not self.everyone
        self.version += 1
        if self.log is not None:
            if logged is None:
                logged, logged_ok = self.nb[:LOGGED], self.nb_ok[:LOGGED]
            else:
                logged, logged_ok = logged.T, logged_ok.T
            self.log.append(frame, logged, logged_ok, self.near, self.near_ok)

    @property
    def everyone(self) -> bool:
        """Whether `nb` holds every school-mate, in no order: when a model perceives more fish than
        the log keeps and the largest species has no more, its lists are built once (Couzin's
        zones over a school of a hundred need no tree)."""
        if self.k <= LOGGED:
            return False
        counts = np.bincount(self.state.group, minlength=self.state.n_groups)
        return bool(self.k >= counts.max() - 1)

    def _find(self):
        """(nb, nb_ok, near, near_ok) as (N, k) from k-d trees, and the nearest school-mates to log
        when `nb` does not start with them (else None, None); sets `other`."""
        state = self.state
        n = state.n
        pos = state.pos.T
        nb = np.zeros((n, max(self.k, 1)), dtype=np.int64)
        nb_ok = np.zeros((n, max(self.k, 1)), dtype=bool)
        self.other = None
        logged = logged_ok = None
        if n < 2:
            empty = np.zeros((n, 1), dtype=np.int64)
            return nb, nb_ok, empty, empty.astype(bool), logged, logged_ok
        everyone = self.everyone
        if everyone:
            nb, nb_ok = self._everyone()
            logged = np.zeros((n, min(LOGGED, self.k)), dtype=np.int64)
            logged_ok = np.zeros(logged.shape, dtype=bool)
        m = min(NEAR, n - 1)
        tree = cKDTree(pos)
        if everyone:
            k_all = m if state.n_groups > 1 else max(m, logged.shape[1])  # type: ignore[union-attr]
        else:
            k_all = max(self.k, m) if state.n_groups == 1 else m
        _, idx = tree.query(pos, k=k_all + 1, workers=self.workers)
        idx = idx[:, 1:]  # drop self (nearest; coincident fish are separated beforehand)
        near = idx[:, :m]
        near_ok = near != np.arange(n)[:, None]
        if state.n_groups == 1:
            if everyone:
                got = min(idx.shape[1], logged.shape[1])  # type: ignore[union-attr]
                logged[:, :got] = idx[:, :got]  # type: ignore[index]
                logged_ok[:, :got] = idx[:, :got] != np.arange(n)[:, None]  # type: ignore[index]
                return nb, nb_ok, near, near_ok, logged, logged_ok
            nb = idx[:, : self.k]
            return nb, nb != np.arange(n)[:, None], near, near_ok, logged, logged_ok
        other = np.full(n, -1, dtype=np.int64)
        other_d = np.full(n, np.inf)
        for g in range(state.n_groups):
            members = np.flatnonzero(state.group == g)
            if members.size == 0:
                continue
            t = cKDTree(pos[members])
            kk = min((logged.shape[1] if everyone else self.k) + 1, members.size)  # type: ignore[union-attr]
            _, li = t.query(pos[members], k=kk, workers=self.workers)
            li = li.reshape(members.size, kk)[:, 1:]
            got = li.shape[1]
            into, into_ok = (logged, logged_ok) if everyone else (nb, nb_ok)
            into[members, :got] = members[li]  # type: ignore[index]
            into_ok[members, :got] = members[li] != members[:, None]  # type: ignore[index]
            outsiders = np.flatnonzero(state.group != g)
            if outsiders.size:
                dd, oi = t.query(pos[outsiders], k=1, workers=self.workers)
                better = dd < other_d[outsiders]
                other[outsiders[better]] = members[oi[better]]
                other_d[outsiders[better]] = dd[better]
        self.other = other
        return nb, nb_ok, near, near_ok, logged, logged_ok

    def _everyone(self) -> tuple[np.ndarray, np.ndarray]:
        """Every school-mate of each fish (N, k), padded with the fish itself (not ok); built once."""
        if getattr(self, "_all", None) is None:
            state = self.state
            n = state.n
            nb = np.tile(np.arange(n)[:, None], (1, self.k))
            ok = np.zeros((n, self.k), dtype=bool)
            for g in range(state.n_groups):
                members = np.flatnonzero(state.group == g)
                if members.size < 2:
                    continue
                others = np.tile(members, (members.size, 1))[~np.eye(members.size, dtype=bool)]
                others = others.reshape(members.size, members.size - 1)
                nb[members, : members.size - 1] = others
                ok[members, : members.size - 1] = True
            self._all = (nb, ok)
        return self._all

    # ----------------------------------------------------------------- per step
    def begin_step(self) -> None:
        self.near_to = self.near_dist = None

    def set_near_offsets(self, near_to: np.ndarray, near_dist: np.ndarray) -> None:
        """Offsets a model measured anyway (`near` being the first rows of its school-mates)."""
        self.near_to, self.near_dist = near_to, near_dist

    def near_offsets(self) -> tuple[np.ndarray, np.ndarray]:
        """From each of the few nearest fish (any species) to me (3, m, N), and how far (m, N), at
        this step's start; measured once a step, shared by the urges and the separation."""
        if self.near_to is None or self.near_dist is None:
            pos = self.state.pos
            self.near_to = np.take(pos, self.near, axis=1) - pos[:, None, :]
            self.near_dist = norm(self.near_to)
        return self.near_to, self.near_dist

    def contact_strength(self) -> np.ndarray:
        """Per nearest fish: 1 at contact falling to 0 at the contact distance, over the distance."""
        _, dist = self.near_offsets()
        reach = np.maximum(1.0 - dist * self.inv_near_reach, 0.0) * self.near_ok
        return reach / np.maximum(dist, 1e-12)

    def push(self, strength: np.ndarray) -> np.ndarray:
        """Sum over the nearest fish of strength x offset away from them."""
        near_to, _ = self.near_offsets()
        return -np.einsum("kn,ckn->cn", strength, near_to)
