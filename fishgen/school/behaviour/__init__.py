"""Behaviour models: each computes, per step, the velocity every fish wants, how far it may turn
and its speed limits. Everything else (neighbours, soft bounds, other species, the predator, the
turn limit, the hard separation) is shared and lives outside them.

A model is a class in its own module, named in BEHAVIOURS, with:

- ``neighbours``: how many school-mates (nearest first) it needs in ``Neighbours.nb``;
- ``__init__(config, state)``: per-fish constants; it may set the start velocities;
- ``want(state, nbrs, target) -> Want``.

Adding a model is one module and one line here (and its name in ``model.MODELS``).
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    import numpy as np

    from fishgen.school.model import SchoolConfig
    from fishgen.school.neighbours import Neighbours
    from fishgen.school.state import SchoolState

BEHAVIOURS = {
    "boids": "fishgen.school.behaviour.boids:Boids",
    "pso": "fishgen.school.behaviour.pso:Pso",
    "couzin": "fishgen.school.behaviour.couzin:Couzin",
}


@dataclass
class Want:
    """What a model asks of each fish this step."""

    velocity: np.ndarray              # (3, N) metres per second, before the shared urges
    max_turn: np.ndarray | float      # radians per second, per fish or for all
    v_min: np.ndarray | float         # metres per second
    v_max: np.ndarray | float


class Behaviour(Protocol):
    neighbours: int

    def want(self, state: SchoolState, nbrs: Neighbours, target: np.ndarray | None) -> Want: ...


def behaviour(config: SchoolConfig, state: SchoolState) -> Behaviour:
    """The model ``config.model`` names, set up for ``state``."""
    try:
        where = BEHAVIOURS[config.model]
    except KeyError:
        raise ValueError(f"unknown model {config.model!r}; expected one of {', '.join(BEHAVIOURS)}") from None
    module, name = where.split(":")
    return getattr(importlib.import_module(module), name)(config, state)
