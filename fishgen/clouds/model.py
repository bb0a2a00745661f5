"""Typed model of a RekAwan cube file (.awn) and of the particle cloud filled from it."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # numpy stays out of the import path of the parser and the CLI help
    import numpy as np

    from fishgen.clouds.lighting import Lighting

DEFAULT_MAX_PARTICLES = 50_000_000
"""Refuse larger clouds before allocating (about 31 bytes per particle in memory)."""
DEFAULT_VOXEL_SIZE = 0.2
"""A volume's voxel side, in cube-file units: Table 4.4 (about 18 x 13 x 9 with its particles'
reach) becomes about 90 x 65 x 45 voxels, 2 to 6 voxels across the sigma of most particles."""
MAX_VOXELS = 1 << 25
"""Most voxels in a volume's bounding box (about 320^3): the splat holds two float32 grids of that
box, 256 MB at the cap; refused before filling."""
METHODS = ("paper", "uniform")
"""How cubes are filled: the report's sine phase shifts with rejection, or plain uniform."""


@dataclass(frozen=True)
class Cube:
    """One editor cube: particles (or billboards) to place, x/y/z extents (y up), centre and
    maximum radius; in a texture cloud (.awa), the texture its billboards carry."""

    particles: int
    size: tuple[float, float, float]
    centre: tuple[float, float, float]
    max_radius: float
    line: int = 0  # source line, for messages
    texture: str | None = None  # .awa: the PNG file, resolved (an absolute path)


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
    A filled cloud is unlit: white, ``light`` and ``lighting`` None. ``light_cloud``
    (fishgen.clouds.light) sets the sunlight reaching each particle and the colours it gives.
    """

    centers: np.ndarray      # (N, 3) float32, world units, y up
    radii: np.ndarray        # (N,) float32, in (0, max radius of its cube]
    density: np.ndarray      # (N,) float32, Gaussian fall-off weight in (0, 1]
    colors: np.ndarray       # (N, 3) uint8 sRGB
    cube_index: np.ndarray   # (N,) int32
    cube_bounds: np.ndarray  # (K, 2, 3) float64
    light: np.ndarray | None = None       # (N,) float32 in [0, 1]: sunlight reaching each centre
    lighting: Lighting | None = None      # the light it was lit with
    textures: tuple[str | None, ...] = ()  # per cube: its billboards' PNG (a texture cloud), else ()

    def __post_init__(self) -> None:
        n = len(self.centers)
        shapes = {"centers": (n, 3), "radii": (n,), "density": (n,), "colors": (n, 3),
                  "cube_index": (n,), "light": (n,)}
        for name, shape in shapes.items():
            value = getattr(self, name)
            if value is not None and value.shape != shape:
                raise ValueError(f"Cloud.{name} has shape {value.shape}, expected {shape}")
        if (self.light is None) != (self.lighting is None):
            raise ValueError("Cloud.light and Cloud.lighting go together")
        if self.textures and len(self.textures) != len(self.cube_bounds):
            raise ValueError(f"Cloud.textures has {len(self.textures)} entries, expected one per cube "
                             f"({len(self.cube_bounds)})")

    def __len__(self) -> int:
        return len(self.centers)
