"""Typed model of a school: what to simulate (species groups, model, bounds, target, predator),
and what the simulation yields (tracks). Plain numbers and arrays; no file formats."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

if TYPE_CHECKING:
    import numpy as np

Model = Literal["boids", "pso"]
MODELS: tuple[Model, ...] = ("boids", "pso")
Layout = Literal["sphere", "box", "line"]
PathKind = Literal["circle", "figure8", "spline", "points", "none"]


@dataclass(frozen=True)
class Brain:
    """A species' urge weightings (VRFish Appendix A `movement of fish`, chapter 7.2)."""

    random: float = 0.04        # weight of the wander spline
    center: float = 0.35        # move towards the centre of nearby school-mates
    keepaway: float = 0.01      # keep away from the nearest fish inside the repel distance
    repel_distance: float = 1.0  # in body lengths
    speed: float = 0.7          # keep its own velocity
    change_rate: float = 50.0   # frames between new random wander points
    direction: float = 0.0015   # match the heading of nearby school-mates
    flee: tuple[float, float] = (0.04, 10.0)  # (weight, distance in body lengths) away from a predator


@dataclass(frozen=True)
class Group:
    """One species' fish: how many, how long (metres), cruising speed (body lengths / s), brain."""

    name: str
    count: int
    body_length: float
    cruise_speed: float = 1.0
    brain: Brain = field(default_factory=Brain)


@dataclass(frozen=True)
class TargetPath:
    """Where the pso school's target (or the predator) goes: a built-in curve or points over time."""

    kind: PathKind = "circle"
    centre: tuple[float, float, float] = (0.0, 0.0, 0.0)
    radius: float = 2.0          # metres
    period: float = 20.0         # seconds per lap
    points: tuple[tuple[float, float, float, float], ...] = ()  # (t, x, y, z) for kind "points"
    seed: int = 0                # for kind "spline"


@dataclass(frozen=True)
class PsoParams:
    """The particle swarm of the 2017 report (eq. 2.1-2.2, Figure 2.2)."""

    inertia: float = 0.7
    attraction: float = 0.3      # towards the second-nearest neighbour (C3 of Figure 2.2)
    global_weight: float = 1.5   # towards the global best (the fish nearest the target)
    repulsion: float = 2.0       # away from the nearest neighbour inside repulsion_radius
    repulsion_radius: float = 1.0  # body lengths
    slowdown: float = 0.95
    turn_rate: float = 2.0       # radians per second per metre from the target, capped
    max_speed: float = 3.0       # body lengths per second


@dataclass(frozen=True)
class SchoolConfig:
    groups: tuple[Group, ...]
    model: Model = "boids"
    frames: int = 300
    fps: float = 30.0
    seed: int = 0
    bounds: tuple[tuple[float, float, float], tuple[float, float, float]] = ((-5, -2, -5), (5, 2, 5))
    layout: Layout = "sphere"
    neighbours: int = 7            # k nearest school-mates each fish perceives
    perception: float = 5.0        # body lengths
    max_turn: float = 3.0          # radians per second
    jitter: float = 0.05           # VRSchool's per-fish variation of size and weights
    target: TargetPath = field(default_factory=TargetPath)
    pso: PsoParams = field(default_factory=PsoParams)
    predator: TargetPath | None = None

    @property
    def count(self) -> int:
        return sum(g.count for g in self.groups)


@dataclass
class Tracks:
    """The simulation's result, one row per frame and fish."""

    times: np.ndarray        # (F,) seconds
    positions: np.ndarray    # (F, N, 3) metres, +Y up
    velocities: np.ndarray   # (F, N, 3) metres per second
    headings: np.ndarray     # (F, N, 4) unit quaternions (x, y, z, w): the fish's +Z (head) along its heading
    group: np.ndarray        # (N,) index into SchoolConfig.groups
    scale: np.ndarray        # (N,) per-fish size factor (VRSchool's jitter), 1 = the species' size
    target: np.ndarray | None = None    # (F, 3) the pso target
    predator: np.ndarray | None = None  # (F, 3)
