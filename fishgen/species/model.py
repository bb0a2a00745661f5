"""Typed model of a VRFish species parameter file (thesis Appendix A).

Values are kept as the file gives them (thesis units: the body spans x = 0..1
before scaling); geometry code interprets them.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

#: One VRFish world unit in metres (docs/decisions.md): BonyBream's world scale
#: 25.5 x scaleX 0.26 then gives a 0.33 m body, a typical adult bony bream.
METRES_PER_WORLD_UNIT = 0.05

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class CaudalFin:
    top_line: float
    middle_line: float
    top_angle: float          # degrees between top and middle line
    top_triangles: int
    connection: Vec3          # unit body space
    rotation_angle: float     # degrees, tilts the whole fin about the z-axis
    bottom_line: float
    bottom_angle: float       # degrees between bottom and middle line
    bottom_triangles: int
    movement_angle: float     # degrees, swing amplitude
    step_size: float          # degrees per frame

    @property
    def texture_point_count(self) -> int:
        return 1 + (self.top_triangles + 1) + (self.bottom_triangles + 1)


@dataclass(frozen=True)
class VerticalFin:
    """Dorsal, adipose or anal fin: spans BodySections start..end on the top/bottom line."""
    start_section: int
    end_section: int
    start_length: float
    end_length: float
    start_angle: float        # degrees from the horizontal
    proportion: float

    @property
    def texture_point_count(self) -> int:
        return 2 * (self.end_section - self.start_section + 1)

    @property
    def present(self) -> bool:
        return self.start_length > 0 or self.end_length > 0


@dataclass(frozen=True)
class PelvicFin:
    start_circle: int
    start_section: int
    end_section: int
    start_length: float
    end_length: float
    end_angle: float          # degrees from the horizontal
    movement_angle: float
    step_size: float

    @property
    def texture_point_count(self) -> int:
        return 2 * (self.end_section - self.start_section + 1)


@dataclass(frozen=True)
class PectoralFin:
    start_section: int
    start_circle: int
    triangles: int
    start_length: float
    start_angle: float
    proportion: float
    version: float            # the thesis' test value, kept for round-tripping
    movement_angle: float
    step_size: float

    @property
    def texture_point_count(self) -> int:
        return 2 * self.triangles + 1


@dataclass(frozen=True)
class TexturePoints:
    """Texture coordinates exactly as Fixel wrote them (u right, v down from the image top)."""
    body: tuple[Vec2, ...]    # BodySections x CircleSections, row-major by section
    caudal: tuple[Vec2, ...]
    dorsal: tuple[Vec2, ...]
    adipose: tuple[Vec2, ...]
    anal: tuple[Vec2, ...]
    pectoral: tuple[Vec2, ...]
    pelvic: tuple[Vec2, ...]


@dataclass(frozen=True)
class Behaviour:
    """Schooling parameters (chapter 7.2); parsed and kept for the school simulator."""
    initial_velocity: Vec3
    random: float
    center: float
    keepaway: float
    repel_distance: float
    speed: float
    change_rate: float
    direction: float
    flee: Vec2


@dataclass(frozen=True)
class Species:
    name: str
    world_scale: float
    urge_factor: float
    start_position: Vec3
    cube_size: float
    colour: Vec3
    shape_class: str
    shape_params: tuple[float, ...]
    body_sections: int
    circle_sections: int
    textured: bool
    masked: bool
    turn_test: bool
    catchfish_test: bool
    scale: Vec3
    caudal: CaudalFin
    adipose: VerticalFin
    dorsal: VerticalFin
    pelvic: PelvicFin
    anal: VerticalFin
    pectoral: PectoralFin
    transparency: float = 1.0
    colour_texture: Path | None = None   # resolved, checked path
    mask_texture: Path | None = None
    texture_points: TexturePoints | None = None
    behaviour: Behaviour | None = None
    source: Path | None = field(default=None, compare=False)
    #: line number of each record ("shape", "caudal", "pelvic", "pectoral", "texture")
    record_lines: dict[str, int] = field(default_factory=dict, compare=False, repr=False)

    def line_of(self, record: str) -> int | None:
        return self.record_lines.get(record)

    @property
    def side_files(self) -> tuple[Path, ...]:
        """The textures the file names (what a build reads besides the file itself)."""
        return tuple(t for t in (self.colour_texture, self.mask_texture) if t is not None)
