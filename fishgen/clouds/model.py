"""Typed model of a RekAwan cube file (.awn) and of the particle cloud filled from it."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # numpy stays out of the import path of the parser and the CLI help
    import numpy as np

DEFAULT_MAX_PARTICLES = 50_000_000
"""Refuse larger clouds before allocating (about 31 bytes per particle in memory)."""
METHODS = ("paper", "uniform")
"""How cubes are filled: the report's sine phase shifts with rejection, or plain uniform."""


@dataclass(frozen=True)
class Cube:
    """One editor cube: particles to place, x/y/z extents (y up), centre and maximum radius."""

    particles: int
    size: tuple[float, float, float]
    centre: tuple[float, float, float]
    max_radius: float
    line: int = 0  # source line, for messages


@dataclass(frozen=True)
class CubeFile:
    """A parsed .awn file. The per-cube counts win over the declared total."""

    path: str
    declared_total: int
    cubes: tuple[Cube, ...]
    warnings: tuple[str, ...] = field(default=())

    @property
    def total(self) -> int:
        return sum(cube.particles for cube in self.cubes)


@dataclass
class Cloud:
    """Filled particles, one row per particle, sorted by cube.

    ``cube_bounds[k]`` is ``(min corner, max corner)`` of cube ``k`` in world
    coordinates (offset applied); ``cube_index`` maps each particle to its cube.
    """

    centers: np.ndarray      # (N, 3) float32, world units, y up
    radii: np.ndarray        # (N,) float32, in (0, max radius of its cube]
    density: np.ndarray      # (N,) float32, Gaussian fall-off weight in (0, 1]
    colors: np.ndarray       # (N, 3) uint8 sRGB
    cube_index: np.ndarray   # (N,) int32
    cube_bounds: np.ndarray  # (K, 2, 3) float64

    def __post_init__(self) -> None:
        n = len(self.centers)
        shapes = {"centers": (n, 3), "radii": (n,), "density": (n,), "colors": (n, 3),
                  "cube_index": (n,)}
        for name, shape in shapes.items():
            if getattr(self, name).shape != shape:
                raise ValueError(f"Cloud.{name} has shape {getattr(self, name).shape}, expected {shape}")

    def __len__(self) -> int:
        return len(self.centers)
