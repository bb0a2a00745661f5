"""Automatic texture points, as the thesis' Fixel tool would place them (chapter 6).

The side view of the body and the vertical and caudal fins is projected into
the left part of the texture; pectoral and pelvic fins get boxes of their own
on the right, so a painted texture can give every fin its own picture.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from fishgen.species.model import Species, TexturePoints

SIDE_VIEW = (0.02, 0.04, 0.76, 0.96)     # u0, v0, u1, v1 of the side-view area
PECTORAL_BOX = (0.79, 0.04, 0.98, 0.46)
PELVIC_BOX = (0.79, 0.54, 0.98, 0.96)


def _fit(points_xy: np.ndarray, box, aspect: float, keep=None) -> np.ndarray:
    """Map thesis (x, y) into texture ``box`` keeping proportions; v grows downwards."""
    ref = points_xy if keep is None else keep
    lo, hi = ref.min(axis=0), ref.max(axis=0)
    u0, v0, u1, v1 = box
    span = np.maximum(hi - lo, 1e-12)
    k = min((u1 - u0) / span[0], (v1 - v0) / (aspect * span[1]))
    cu = (u0 + u1) / 2 - k * (lo[0] + hi[0]) / 2
    cv = (v0 + v1) / 2 + k * aspect * (lo[1] + hi[1]) / 2
    return np.stack([cu + k * points_xy[:, 0], cv - k * aspect * points_xy[:, 1]], axis=1)


def project_texture_points(species: Species, aspect: float = 2.0) -> Species:
    """Return ``species`` with texture points for a texture ``aspect`` times wider than tall."""
    from fishgen.assembly.fins import build_fins
    from fishgen.geometry.body import ring_positions
    from fishgen.geometry.shapes import profile_for

    rings, _ = ring_positions(profile_for(species.shape_class, species.shape_params),
                              species.body_sections, species.circle_sections, species.scale)
    # every section the file names: one texture point per vertex of these fins
    whole = build_fins(replace(species, texture_points=None), rings, clear_of_caudal=False)
    fins = {f.name: f for f in whole}
    side = [rings.reshape(-1, 3)[:, :2]] + [f.mesh.positions[:, :2] for n, f in fins.items()
                                            if n in ("caudal_fin", "dorsal_fin", "adipose_fin", "anal_fin")]
    keep = np.concatenate(side)
    body = _fit(rings.reshape(-1, 3)[:, :2], SIDE_VIEW, aspect, keep)

    def side_fin(name: str, count: int):
        if name in fins:
            return _fit(fins[name].mesh.positions[:, :2], SIDE_VIEW, aspect, keep)
        return np.tile(body[0], (count, 1))  # an absent fin still needs its points

    def boxed(name: str, box):
        return _fit(fins[name].mesh.positions[:, :2], box, aspect)

    pts = TexturePoints(
        body=_tuples(body),
        caudal=_tuples(side_fin("caudal_fin", species.caudal.texture_point_count)),
        dorsal=_tuples(side_fin("dorsal_fin", species.dorsal.texture_point_count)),
        adipose=_tuples(side_fin("adipose_fin", species.adipose.texture_point_count)),
        anal=_tuples(side_fin("anal_fin", species.anal.texture_point_count)),
        pectoral=_tuples(boxed("pectoral_fin_left", PECTORAL_BOX)),
        pelvic=_tuples(boxed("pelvic_fin_left", PELVIC_BOX)),
    )
    return replace(species, textured=True, texture_points=pts)


def _tuples(a: np.ndarray) -> tuple[tuple[float, float], ...]:
    # Fixel wrote texel positions; round to 1/4096 so files stay readable.
    q = np.round(np.clip(a, 0.0, 1.0) * 4096) / 4096
    return tuple((float(u), float(v)) for u, v in q)
