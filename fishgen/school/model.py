"""Typed model of a school: what to simulate (species groups, behaviour model and its parameters,
bounds, target, predator), and what the simulation yields (tracks). Plain numbers and arrays; no
file formats. numpy-free at import, so the command line can read the models, presets and ranges
at ``--help`` time."""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, Any, Literal

if TYPE_CHECKING:
    import numpy as np

Model = Literal["boids", "pso", "couzin"]
MODELS: tuple[Model, ...] = ("boids", "pso", "couzin")
Layout = Literal["sphere", "box", "line", "ring"]
LAYOUTS: tuple[Layout, ...] = ("sphere", "box", "line", "ring")
PathKind = Literal["circle", "figure8", "spline", "points", "none"]
WARMUP_SECONDS = 3.0
WARMUP_SHARE = 1 / 3
"""Without a warm-up given, the school forms in the first third of the run, at most 3 s."""
PREROLL_PAPER_SECONDS = 20.0
"""Seconds on the Couzin paper's clock its groups take to reach their collective state from a
disordered start, which fishgen simulates before a couzin school's first frame by default (at 1
body length a second that clock runs 3x slower than ours: 60 s). In a 10 s run with no pre-roll
the README's "highly parallel" school read polarization 0.78 (worst 0.49); with 60 s, 0.98-1.00."""


@dataclass(frozen=True)
class Brain:
    """A species' urge weightings (VRFish Appendix A `movement of fish`, chapter 7.2)."""

    random: float = 0.04        # weight of the wander spline
    center: float = 0.35        # move towards the centre of the school
    keepaway: float = 0.01      # keep away from the nearest fish inside the repel distance
    repel_distance: float = 1.0  # in body lengths
    speed: float = 0.7          # keep its own velocity
    change_rate: float = 50.0   # frames between new random wander points
    direction: float = 0.0015   # match the heading of the school
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
class CouzinParams:
    """Couzin, Krause, James, Ruxton & Franks (2002), "Collective memory and spatial sorting in
    animal groups", J. Theor. Biol. 218, 1-11: three zones around each fish, a blind volume behind
    it and a turning-rate limit.

    Distances are in body lengths (the paper's unit is the zone of repulsion's radius, rr = 1),
    times in seconds. Each step a fish wants to move away from every school-mate inside the zone
    of repulsion if there is one (that rule alone); otherwise along its own and its visible
    school-mates' headings in the zone of orientation, towards the visible school-mates in the zone
    of attraction, or half of each when both zones hold fish. It turns towards that by at most
    `turning_rate`, after a random turn of `noise`.

    Fish swim at their species' cruising speed. The paper's states depend on its turning radius,
    s / theta (3 units/s over 40 degrees/s: 4.3 units), so `turning_rate` and `noise` hold at
    `speed`, the paper's s, and a fish swimming at another speed turns and wanders in proportion:
    the same paths, run faster or slower. A school bigger than `neighbours` + `sampled` + 1 fish
    takes each fish's `neighbours` nearest exactly and a fresh random sample of `sampled` others,
    weighted to stand for all of them (fishgen.school.behaviour.couzin).
    """

    repulsion: float = 1.0       # rr: radius of the zone of repulsion, body lengths
    orientation: float = 1.0     # delta ro: width of the zone of orientation beyond rr, body lengths
    attraction: float = 15.0     # delta ra: width of the zone of attraction beyond rr + delta ro
    blind_angle: float = 90.0    # degrees of the cone straight behind a fish it cannot see into
                                 # (the paper's field of perception alpha = 270 degrees)
    turning_rate: float = 40.0   # theta: the most a fish turns, degrees per second at `speed`
    speed: float = 3.0           # s: the paper's speed, body lengths per second (see below)
    noise: float = 0.05          # sigma: s.d. of the random turn, radians per 0.1 s (the paper's tau)
    neighbours: int = 40         # school-mates each fish takes exactly, nearest first
    sampled: int = 60            # more taken at random each step in a bigger school (see above)

    @property
    def reach(self) -> float:
        """The zone of attraction's outer radius, body lengths."""
        return self.repulsion + self.orientation + self.attraction


COUZIN_PRESETS: dict[str, CouzinParams] = {
    # The four collective states of the paper's Figure 2 (delta ra = 15, delta ro swept from 0 to 15
    # starting from a disordered group): swarm for delta ro of 0-0.5, torus 0.5-2.5, dynamic parallel
    # 2.5-6, highly parallel 6.5-15. Each preset sits inside its band; docs/decisions.md, Schools.
    "swarm": CouzinParams(orientation=0.0),
    "torus": CouzinParams(orientation=1.0),
    "dynamic parallel": CouzinParams(orientation=4.0),
    "highly parallel": CouzinParams(orientation=12.0),
}
"""The paper's four collective states, as parameter sets (scene-file `preset = "torus"`)."""

COUZIN_RANGES: dict[str, tuple[float, float]] = {
    "repulsion": (0.1, 20.0), "orientation": (0.0, 100.0), "attraction": (0.0, 100.0),
    "blind_angle": (0.0, 360.0), "turning_rate": (1.0, 3600.0), "noise": (0.0, 3.0),
    "neighbours": (1, 1000), "sampled": (0, 1000), "speed": (0.05, 20.0),
}
"""Accepted range of each CouzinParams field (the scene file and the command line check these)."""

COUZIN_HELP: dict[str, str] = {
    "repulsion": "radius of the zone of repulsion, body lengths",
    "orientation": "width of the zone of orientation beyond the zone of repulsion, body lengths",
    "attraction": "width of the zone of attraction beyond the zone of orientation, body lengths",
    "blind_angle": "degrees of the cone behind a fish that it cannot see into",
    "turning_rate": "the most a fish turns, degrees per second",
    "noise": "s.d. of each fish's random turn, radians per 0.1 s",
    "neighbours": "school-mates each fish takes exactly, nearest first",
    "sampled": "more school-mates taken at random each step in a bigger school",
    "speed": "the speed at which turning_rate and noise hold, body lengths per second",
}


def couzin_params(preset: str | None = None, **values: Any) -> CouzinParams:
    """A preset (or the defaults) with ``values`` overriding its fields; KeyError for an unknown
    preset, TypeError for an unknown field."""
    from dataclasses import replace

    base = CouzinParams() if preset is None else COUZIN_PRESETS[preset]
    names = {f.name for f in fields(CouzinParams)}
    unknown = set(values) - names
    if unknown:
        raise TypeError(f"unknown Couzin parameter {sorted(unknown)[0]!r}")
    return replace(base, **values)


@dataclass(frozen=True)
class Variety:
    """VRSchool's per-fish variety (thesis 4.2.6, 7.2): seeded, so the same seed gives the same fish.

    `size` is the s.d. of each fish's size factor (its node's scale; clipped at 3 s.d.), which the
    simulation also spaces the fish by. `tints` colour variants per species share the species'
    geometry and texture and differ only in material: variant 0 is the species' own colours, each
    other multiplies every material's base colour by its own seeded (r, g, b), each channel from
    1 - `tint` to 1. One variant (the default) writes exactly the file it always did.
    """

    size: float = 0.05
    tints: int = 1
    tint: float = 0.15


VARIETY_RANGES: dict[str, tuple[float, float]] = {"size": (0.0, 0.3), "tints": (1, 16), "tint": (0.0, 0.5)}
"""Accepted range of each Variety field."""

VARIETY_HELP: dict[str, str] = {
    "size": "s.d. of each fish's size factor (its node's scale), 0 for all alike",
    "tints": "colour variants per species, sharing its geometry; 1 for the species' own colours only",
    "tint": "how far a colour variant strays: each channel times 1 - tint to 1",
}


@dataclass(frozen=True)
class SchoolConfig:
    groups: tuple[Group, ...]
    model: Model = "boids"
    frames: int = 300
    fps: float = 30.0
    seed: int = 0
    bounds: tuple[tuple[float, float, float], tuple[float, float, float]] = ((-5, -2, -5), (5, 2, 5))
    layout: Layout = "sphere"
    neighbours: int = 7            # k nearest school-mates each fish perceives (boids, pso)
    perception: float = 5.0        # body lengths
    max_turn: float = 3.0          # radians per second (boids, pso)
    jitter: float = 0.05           # VRSchool's per-fish variation of the urge weights
    target: TargetPath = field(default_factory=TargetPath)
    pso: PsoParams = field(default_factory=PsoParams)
    predator: TargetPath | None = None
    couzin: CouzinParams = field(default_factory=CouzinParams)
    size_jitter: float = 0.05      # VRSchool's per-fish variation of size (s.d. of the size factor)
    preroll: float = 0.0           # seconds simulated before frame 0 and not recorded: the school forms

    @property
    def preroll_frames(self) -> int:
        """Steps simulated before frame 0."""
        return int(round(self.preroll * self.fps))

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
    neighbours: NeighbourLog | None = None  # the simulation's neighbour lists, for the measures
    order: dict[str, np.ndarray] | None = None  # measures the simulation took as it ran (metrics.LOGGED)


@dataclass
class NeighbourLog:
    """The neighbour lists the simulation used, each from its frame until the next one's: the
    measures reuse them instead of searching again. Lists are (k, N): row j holds each fish's j-th
    nearest at the list's frame, -1 where there is none (a species with fewer fish); int16 below
    32,767 fish, so a small school, whose lists are rebuilt every frame, logs 22 bytes a fish-frame."""

    starts: list[int] = field(default_factory=list)        # first frame of each list
    mates: list[np.ndarray] = field(default_factory=list)  # (k, N) nearest of the same species
    near: list[np.ndarray] = field(default_factory=list)   # (m, N) nearest of any species

    def index(self, frames: np.ndarray) -> np.ndarray:
        """Which list each of ``frames`` used."""
        import numpy as np

        return np.searchsorted(np.asarray(self.starts), frames, side="right") - 1

    def append(self, frame: int, mates: np.ndarray, mates_ok: np.ndarray, near: np.ndarray,
               near_ok: np.ndarray) -> None:
        """Log lists (k, N) of fish indices, `*_ok` saying which entries are fish."""
        import numpy as np

        kind = np.int16 if mates.shape[-1] < np.iinfo(np.int16).max else np.int32
        self.starts.append(int(frame))
        self.mates.append(np.where(mates_ok, mates, -1).astype(kind))
        self.near.append(np.where(near_ok, near, -1).astype(kind))
