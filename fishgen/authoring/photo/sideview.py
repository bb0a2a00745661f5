"""A species seen from its left side in thesis units (x nose->tail, y up), as an orthographic
photo shows it: the body's outline per BodySection and every fin's vertices.

This wraps the geometry modules so the photo code depends on one small surface
(:func:`side_view`) rather than on how fins are built.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from fishgen.species.model import Species

#: Fin names in the species model, with the geometry part that carries them.
FIN_PARTS = {"caudal": "caudal_fin", "dorsal": "dorsal_fin", "adipose": "adipose_fin",
             "anal": "anal_fin", "pectoral": "pectoral_fin_left", "pelvic": "pelvic_fin_left"}


@dataclass(frozen=True)
class SideView:
    rings: np.ndarray            # (B, C, 2) ring vertices' (x, y), scaled thesis units
    top: np.ndarray              # (B,) highest y of each ring: the silhouette's top outline
    bottom: np.ndarray           # (B,) lowest y (negative)
    length: float                # body length, scaleX
    fins: dict[str, np.ndarray]  # species fin name -> (N, 2) vertices in Fixel's order
    fin_faces: dict[str, np.ndarray]
    # The fins as a built fish shows them (vertical fins end in front of the caudal fin): what a
    # photo of this species holds. ``fins`` has every section the file names, one per texture point.
    shown_fins: dict[str, np.ndarray]
    shown_faces: dict[str, np.ndarray]

    @property
    def sections(self) -> int:
        return self.rings.shape[0]

    def section_x(self) -> np.ndarray:
        return self.rings[:, 0, 0]

    def outline_at(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(top, bottom) of the body's silhouette at thesis x: straight between sections."""
        xs = self.section_x()
        return np.interp(x, xs, self.top), np.interp(x, xs, self.bottom)

    def extent(self) -> tuple[np.ndarray, np.ndarray]:
        """(min, max) corner of everything a photo of the built fish shows."""
        pts = np.concatenate([self.rings.reshape(-1, 2), *self.shown_fins.values()])
        return pts.min(axis=0), pts.max(axis=0)


def circle_sines(circles: int) -> np.ndarray:
    """sin of each CircleSection's angle: how high ring point i stands, as a share of the radius."""
    from fishgen.geometry.body import ring_angles

    return np.sin(ring_angles(circles))


def side_view(species: Species) -> SideView:
    from fishgen.assembly.fins import build_fins
    from fishgen.geometry.body import ring_positions
    from fishgen.geometry.shapes import profile_for

    rings, _ = ring_positions(profile_for(species.shape_class, species.shape_params),
                              species.body_sections, species.circle_sections, species.scale)
    bare = replace(species, texture_points=None)

    def parts(clear_of_caudal: bool) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        built = {f.name: f for f in build_fins(bare, rings, clear_of_caudal=clear_of_caudal)}
        return ({name: built[part].mesh.positions[:, :2].copy() for name, part in FIN_PARTS.items()
                 if part in built},
                {name: built[part].mesh.faces.copy() for name, part in FIN_PARTS.items() if part in built})

    # every section the file names: its texture points are one per vertex of these fins
    fins, faces = parts(clear_of_caudal=False)
    # ...but the photo's fish is measured against the fish as built: BonyBream's anal and adipose
    # fins, drawn whole, reach over its peduncle, and its tail base calibrated 0.4 % of the length
    # too far back and too low put every texture point 1-2 px off (its round trips fell to 0.958)
    shown, shown_faces = parts(clear_of_caudal=True)
    xy = rings[:, :, :2]
    return SideView(xy, xy[:, :, 1].max(axis=1), xy[:, :, 1].min(axis=1), float(species.scale[0]),
                    fins, faces, shown, shown_faces)


def rasterize(view: SideView, pixels_per_unit: float, margin: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """The side view's silhouette as a mask (image rows down), and the pixel position of thesis (0, 0)."""
    from PIL import Image, ImageDraw

    lo, hi = view.extent()
    origin = np.array([margin - lo[0] * pixels_per_unit, margin + hi[1] * pixels_per_unit])
    size = np.ceil((hi - lo) * pixels_per_unit).astype(int) + 2 * margin

    def px(points: np.ndarray) -> list[tuple[float, float]]:
        return [(float(x), float(y)) for x, y in origin + points * np.array([1.0, -1.0]) * pixels_per_unit]

    img = Image.new("L", (int(size[0]), int(size[1])), 0)
    draw = ImageDraw.Draw(img)
    xs = view.section_x()
    body = np.concatenate([np.stack([xs, view.top], 1), np.stack([xs, view.bottom], 1)[::-1]])
    draw.polygon(px(body), fill=255)
    for name, pts in view.shown_fins.items():
        for tri in view.shown_faces[name]:   # a fin has tens of triangles, not pixels
            draw.polygon(px(pts[tri]), fill=255)
    return np.asarray(img) >= 128, origin


def with_counts(base: Species, sections: int | None, circles: int | None) -> Species:
    """``base`` at another level of detail, as a level of detail maps it
    (:func:`fishgen.assembly.levels.at_level`): fin sections, circle points and the fins' per-step
    proportions move with the body, so a fin keeps its shape (`--body-sections 96` had shrunk
    ThreadfinGoldie's dorsal and anal fins to spikes: a fin's proportion is per section)."""
    from fishgen.assembly.levels import at_level

    b, c = sections or base.body_sections, circles or base.circle_sections
    return replace(at_level(base, b, c), texture_points=None)
