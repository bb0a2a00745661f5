"""The fitted fish drawn as a photo shows it, and scored against the photographed silhouette.

A species' side view is drawn as a mask in the fit's working frame (:class:`Placement`): whole
(:func:`draw`), body alone (:func:`body_mask`), or layer by layer (:class:`Drawer`, so that a
move of one fin redraws only that fin). :func:`shape_score` is the overlap the command reports.
Everything here draws what the species says; nothing is measured on the photo.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from fishgen.authoring.photo.sideview import circle_sines
from fishgen.species.model import Species


@dataclass(frozen=True)
class Placement:
    """Thesis units -> frame pixels: the nose at (x0, y0), the axis along row y0, ``s`` px per unit."""
    x0: float
    y0: float
    s: float

    def to_frame(self, xy: np.ndarray) -> np.ndarray:
        xy = np.asarray(xy, float)
        return np.stack([self.x0 + xy[:, 0] * self.s, self.y0 - xy[:, 1] * self.s], axis=1)


#: The fin records of a species, each drawn as its own layer.
FIN_RECORDS = ("caudal", "dorsal", "adipose", "anal", "pectoral", "pelvic")


def with_fin(sp: Species, record: str, fin: Any) -> Species:
    """``sp`` with fin record ``record`` replaced."""
    changes: dict[str, Any] = {record: fin}
    return replace(sp, **changes)


def reach(circles: int) -> float:
    s = circle_sines(circles)
    return float(0.5 * (s.max() - s.min()))


def parts(sp: Species) -> tuple[np.ndarray, list[tuple[np.ndarray, np.ndarray]]]:
    """(body outline polygon, [(fin vertices, faces)]) of the built fish's side view, thesis units."""
    from fishgen.assembly.fins import build_fins
    from fishgen.geometry.body import ring_positions
    from fishgen.geometry.shapes import profile_for

    rings, _ = ring_positions(profile_for(sp.shape_class, sp.shape_params), sp.body_sections,
                              sp.circle_sections, sp.scale)
    xs = rings[:, 0, 0]
    outline = np.concatenate([np.stack([xs, rings[:, :, 1].max(axis=1)], 1),
                              np.stack([xs, rings[:, :, 1].min(axis=1)], 1)[::-1]])
    built = build_fins(replace(sp, texture_points=None), rings)
    fins = [(f.mesh.positions[:, :2], f.mesh.faces) for f in built]
    return outline, fins


def draw(sp: Species, place: Placement, shape: tuple[int, int]) -> np.ndarray:
    """The built fish's side view as a mask of ``shape`` (rows down) in the working frame."""
    from PIL import Image, ImageDraw

    outline, fins = parts(sp)
    img = Image.new("L", (shape[1], shape[0]), 0)
    pen = ImageDraw.Draw(img)
    pen.polygon([tuple(p) for p in place.to_frame(outline).tolist()], fill=255)
    for pts, faces in fins:
        px = place.to_frame(pts)
        for tri in faces:
            pen.polygon([tuple(p) for p in px[tri].tolist()], fill=255)
    return np.asarray(img) >= 128


def body_mask(sp: Species, place: Placement, shape: tuple[int, int]) -> np.ndarray:
    from PIL import Image, ImageDraw

    no_tail = replace(sp.caudal, top_line=0.0, bottom_line=0.0, middle_line=0.0)
    outline, _ = parts(replace(sp, caudal=no_tail))
    img = Image.new("L", (shape[1], shape[0]), 0)
    ImageDraw.Draw(img).polygon([tuple(p) for p in place.to_frame(outline).tolist()], fill=255)
    return np.asarray(img) >= 128


def surface_row(sp: Species, place: Placement, section: int, side: float) -> float:
    from fishgen.geometry.shapes import profile_for

    r = float(profile_for(sp.shape_class, sp.shape_params)(np.array([section / (sp.body_sections - 1)]))[0])
    return place.y0 - side * r * sp.scale[1] * reach(sp.circle_sections) * place.s


class Drawer:
    """Draws a species' side view part by part, so a move of one fin redraws only that fin."""

    def __init__(self, sp: Species, place: Placement, shape: tuple[int, int]):
        from fishgen.geometry.body import ring_positions
        from fishgen.geometry.shapes import profile_for

        self.place, self.shape = place, shape
        self.rings, _ = ring_positions(profile_for(sp.shape_class, sp.shape_params), sp.body_sections,
                                       sp.circle_sections, sp.scale)
        xs = self.rings[:, 0, 0]
        outline = np.concatenate([np.stack([xs, self.rings[:, :, 1].max(axis=1)], 1),
                                  np.stack([xs, self.rings[:, :, 1].min(axis=1)], 1)[::-1]])
        self.body = self._polygons([outline])
        self.layers: dict[str, np.ndarray] = {}
        self._caudals: dict[tuple, Any] = {}
        self._rests: dict[str, tuple[tuple[np.ndarray, ...], np.ndarray]] = {}
        self.sp = sp
        for name in FIN_RECORDS:
            self.layers[name] = self.fin(sp, name)

    def _polygons(self, polys: list[np.ndarray]) -> np.ndarray:
        from PIL import Image, ImageDraw

        img = Image.new("L", (self.shape[1], self.shape[0]), 0)
        pen = ImageDraw.Draw(img)
        for poly in polys:
            pen.polygon([tuple(p) for p in self.place.to_frame(poly).tolist()], fill=255)
        return np.asarray(img) >= 128

    def _triangles(self, parts: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
        from PIL import Image, ImageDraw

        img = Image.new("L", (self.shape[1], self.shape[0]), 0)
        pen = ImageDraw.Draw(img)
        for pts, faces in parts:
            px = self.place.to_frame(pts).tolist()
            for a, b, c in faces.tolist():
                pen.polygon([tuple(px[a]), tuple(px[b]), tuple(px[c])], fill=255)
        return np.asarray(img) >= 128

    def fin(self, sp: Species, name: str) -> np.ndarray:
        """One fin's layer, built as :func:`fishgen.assembly.fins.build_fins` builds it."""
        from fishgen.assembly.fins import caudal_params, pectoral_params, pelvic_params, vertical_params
        from fishgen.geometry.fins import caudal_fin, pectoral_fin, pelvic_fin, vertical_fin

        s = np.asarray(sp.scale, float)
        rings = self.rings
        built = []
        if name in ("caudal", "dorsal", "adipose", "anal"):
            # every vertical fin's layer needs the caudal fin's front; it changes only with its record
            key = (sp.caudal, tuple(sp.scale))
            if key not in self._caudals:
                self._caudals[key] = caudal_fin(caudal_params(sp.caudal), s, None,
                                                tail_x=float(rings[-1, :, 0].max()))
            caudal = self._caudals[key]
            if name == "caudal":
                built = [caudal]
            elif getattr(sp, name).present:
                # as build_fins does: a vertical fin ends on the last section in front of the caudal fin
                params = vertical_params(getattr(sp, name))
                side = -1.0 if name == "anal" else 1.0
                front = float(caudal.mesh.positions[:, 0].min()) if len(caudal.mesh.faces) else np.inf
                fin = vertical_fin(name, params, rings, s, side)
                while (fin.mesh.positions[:, 0].max() > front + 1e-9
                       and params.end_section > params.start_section + 1):
                    params = replace(params, end_section=params.end_section - 1)
                    fin = vertical_fin(name, params, rings, s, side)
                if fin.mesh.positions[:, 0].max() <= front + 1e-9:
                    built = [fin]
        elif name == "pectoral":
            built = [pectoral_fin(pectoral_params(sp.pectoral), rings, s)]
        else:
            built = [pelvic_fin(pelvic_params(sp.pelvic), rings, s)]
        return self._triangles([(f.mesh.positions[:, :2], f.mesh.faces) for f in built])

    def whole(self, replaced: dict[str, np.ndarray] | None = None) -> np.ndarray:
        """The body and every fin layer (those in ``replaced`` instead of the drawer's own)."""
        if replaced and len(replaced) == 1:
            # a fit tries one fin at a time: the rest of the fish, kept while its layers stay, and it
            (name, layer), = replaced.items()
            return self._all_but(name) | layer
        out = self.body.copy()
        for name, layer in self.layers.items():
            out |= (replaced or {}).get(name, layer)
        return out

    def _all_but(self, name: str) -> np.ndarray:
        """The body and every layer but ``name``'s, drawn once for as long as those layers are the
        same arrays (kept here, so their identities cannot be reused by others)."""
        others = tuple(layer for n, layer in self.layers.items() if n != name)
        kept = self._rests.get(name)
        if (kept is None or len(kept[0]) != len(others)
                or any(a is not b for a, b in zip(kept[0], others, strict=True))):
            out = self.body.copy()
            for layer in others:
                out |= layer
            kept = self._rests[name] = (others, out)
        return kept[1]


def redrawn(drawer: Drawer, trial: Species, record: str) -> dict[str, np.ndarray]:
    """The layers a change to fin ``record`` redraws: the caudal fin's moves the vertical fins too,
    which end in front of it."""
    changed = {record: drawer.fin(trial, record)}
    if record == "caudal":
        changed.update({n: drawer.fin(trial, n) for n in ("dorsal", "adipose", "anal")})
    return changed


def iou(a: np.ndarray, b: np.ndarray) -> float:
    union = np.count_nonzero(a | b)
    return float(np.count_nonzero(a & b) / union) if union else 0.0


def _shape_key(part: np.ndarray) -> bytes:
    """A crop's size as 16 bytes (a digest's personalisation): equal pixels at another size differ."""
    return np.array(part.shape, np.int64).tobytes()


def shape_score(target: np.ndarray):
    """The overlap the command reports (:func:`.compare.silhouette_iou`: each silhouette cropped to
    its bounding box, the drawing scaled onto the target's), for drawings against ``target``."""
    from PIL import Image

    ys, xs = np.nonzero(target)
    crop = target[ys.min():ys.max() + 1, xs.min():xs.max() + 1]
    size = (crop.shape[1], crop.shape[0])

    scores: dict[bytes, float] = {}

    def score(drawn: np.ndarray) -> float:
        rows, cols = np.flatnonzero(drawn.any(axis=1)), np.flatnonzero(drawn.any(axis=0))
        if rows.size == 0:
            return 0.0
        part = drawn[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1]
        # A fit's small steps often draw a crop it has drawn before (two in five in tests/authoring's
        # fits): each is scaled and scored once, known by a digest of its pixels and its size.
        key = hashlib.blake2b(np.packbits(part).tobytes(), digest_size=16, person=_shape_key(part)).digest()
        if key not in scores:
            img = Image.fromarray(part.astype(np.uint8) * 255).resize(size, Image.Resampling.BILINEAR)
            scores[key] = iou(crop, np.asarray(img) >= 128)
        return scores[key]

    return score
