"""Species fin records -> geometry: maps a :class:`~fishgen.species.model.Species`' fins
onto :mod:`fishgen.geometry.fins`' plain parameters and builds them."""
from __future__ import annotations

import numpy as np

from fishgen.geometry.fins import (
    CaudalParams,
    Fin,
    PectoralParams,
    PelvicParams,
    VerticalParams,
    caudal_fin,
    mirrored,
    pectoral_fin,
    pelvic_fin,
    vertical_fin,
)
from fishgen.species.model import CaudalFin, PectoralFin, PelvicFin, Species, VerticalFin


def caudal_params(fin: CaudalFin) -> CaudalParams:
    return CaudalParams(top_line=fin.top_line, middle_line=fin.middle_line, top_angle=fin.top_angle,
                        top_triangles=fin.top_triangles, connection=fin.connection,
                        rotation_angle=fin.rotation_angle, bottom_line=fin.bottom_line,
                        bottom_angle=fin.bottom_angle, bottom_triangles=fin.bottom_triangles,
                        movement_angle=fin.movement_angle, step_size=fin.step_size)


def vertical_params(fin: VerticalFin) -> VerticalParams:
    return VerticalParams(start_section=fin.start_section, end_section=fin.end_section,
                          start_length=fin.start_length, end_length=fin.end_length,
                          start_angle=fin.start_angle, proportion=fin.proportion)


def pectoral_params(fin: PectoralFin) -> PectoralParams:
    # ``version`` is the thesis' test value, kept only for round-tripping the file.
    return PectoralParams(start_section=fin.start_section, start_circle=fin.start_circle,
                          triangles=fin.triangles, start_length=fin.start_length,
                          start_angle=fin.start_angle, proportion=fin.proportion,
                          movement_angle=fin.movement_angle, step_size=fin.step_size)


def pelvic_params(fin: PelvicFin) -> PelvicParams:
    return PelvicParams(start_circle=fin.start_circle, start_section=fin.start_section,
                        end_section=fin.end_section, start_length=fin.start_length,
                        end_length=fin.end_length, end_angle=fin.end_angle,
                        movement_angle=fin.movement_angle, step_size=fin.step_size)


def build_fins(species: Species, rings: np.ndarray) -> list[Fin]:
    """All fins in scaled thesis space; right-hand paired fins mirror the left ones."""
    s = np.asarray(species.scale, dtype=np.float64)
    tp = species.texture_points

    def uv(name: str) -> tuple[tuple[float, float], ...] | None:
        """The texture points the file gives fin ``name``, in the geometry's vertex order."""
        return getattr(tp, name) if tp is not None else None

    fins = [caudal_fin(caudal_params(species.caudal), s, uv("caudal"))]
    for name, fin, side in (("dorsal", species.dorsal, 1.0), ("adipose", species.adipose, 1.0),
                            ("anal", species.anal, -1.0)):
        if fin.present:
            fins.append(vertical_fin(f"{name}_fin", vertical_params(fin), rings, s, side, uv(name)))
    for left in (pectoral_fin(pectoral_params(species.pectoral), rings, s, uv("pectoral")),
                 pelvic_fin(pelvic_params(species.pelvic), rings, s, uv("pelvic"))):
        fins += [left, mirrored(left)]
    return [f for f in fins if len(f.mesh.faces)]

