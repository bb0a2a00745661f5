"""Species fin records -> geometry: maps a :class:`~fishgen.species.model.Species`' fins
onto :mod:`fishgen.geometry.fins`' plain parameters and builds them."""
from __future__ import annotations

from dataclasses import fields, replace
from typing import TypeVar

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

P = TypeVar("P")


def _params(record: type[P], fin: object) -> P:
    """Geometry's parameter ``record`` from the species file's ``fin``: the two name the same
    measurements alike (the file's record keeps more, such as the pectoral's test ``version``)."""
    return record(**{f.name: getattr(fin, f.name) for f in fields(record)})  # type: ignore[arg-type]  # a dataclass


def caudal_params(fin: CaudalFin) -> CaudalParams:
    return _params(CaudalParams, fin)


def vertical_params(fin: VerticalFin) -> VerticalParams:
    return _params(VerticalParams, fin)


def pectoral_params(fin: PectoralFin) -> PectoralParams:
    return _params(PectoralParams, fin)


def pelvic_params(fin: PelvicFin) -> PelvicParams:
    return _params(PelvicParams, fin)


def build_fins(species: Species, rings: np.ndarray, clear_of_caudal: bool = True) -> list[Fin]:
    """All fins in scaled thesis space; right-hand paired fins mirror the left ones.

    ``clear_of_caudal``: end vertical fins in front of the caudal fin (what a built fish gets);
    False gives every section the species file names, one vertex per texture point (authoring)."""
    s = np.asarray(species.scale, dtype=np.float64)
    tp = species.texture_points

    def uv(name: str) -> tuple[tuple[float, float], ...] | None:
        """The texture points the file gives fin ``name``, in the geometry's vertex order."""
        return getattr(tp, name) if tp is not None else None

    caudal = caudal_fin(caudal_params(species.caudal), s, uv("caudal"), tail_x=float(rings[-1, :, 0].max()))
    fins = [caudal]
    # The caudal fin and the vertical fins lie in one plane: where they overlap, renderers flicker
    # and path tracers show black. A vertical fin ends on the last section that keeps it in front
    # of the caudal fin (docs/decisions.md); the species file's own numbers are left as they are.
    tail_front = np.inf
    if clear_of_caudal and len(caudal.mesh.faces):
        tail_front = float(caudal.mesh.positions[:, 0].min())
    for name, fin, side in (("dorsal", species.dorsal, 1.0), ("adipose", species.adipose, 1.0),
                            ("anal", species.anal, -1.0)):
        if fin.present:
            params = vertical_params(fin)
            built = vertical_fin(f"{name}_fin", params, rings, s, side, uv(name))
            while (built.mesh.positions[:, 0].max() > tail_front + 1e-9
                   and params.end_section > params.start_section + 1):  # a fin needs two sections
                params = replace(params, end_section=params.end_section - 1)
                points = _shortened_points(uv(name), params)
                built = vertical_fin(f"{name}_fin", params, rings, s, side, points)
            if built.mesh.positions[:, 0].max() <= tail_front + 1e-9:
                fins.append(built)
    for left in (pectoral_fin(pectoral_params(species.pectoral), rings, s, uv("pectoral")),
                 pelvic_fin(pelvic_params(species.pelvic), rings, s, uv("pelvic"))):
        fins += [left, mirrored(left)]
    return [f for f in fins if len(f.mesh.faces)]



def _shortened_points(points: tuple[tuple[float, float], ...] | None,
                      params: VerticalParams) -> tuple[tuple[float, float], ...] | None:
    """The texture points of a vertical fin shortened to ``params``' sections: Fixel's order is
    T_0, B_0, B_n, T_n, B_1..B_{n-1}, T_1..T_{n-1} (n + 1 sections), so the new end takes the
    points of the section it now ends on."""
    if points is None:
        return None
    old = len(points) // 2
    new = params.end_section - params.start_section + 1
    base_mid = points[4:4 + old - 2]
    top_mid = points[4 + old - 2:]
    if new < 2:
        return None
    t0, b0 = points[0], points[1]
    bn, tn = base_mid[new - 2], top_mid[new - 2]
    return (t0, b0, bn, tn, *base_mid[:new - 2], *top_mid[:new - 2])
