"""Fixel's texture points from a measured body outline (chapter 6, Appendix B).

Body: BodySections vertical lines evenly spread along the midline from the nose
to the tail point, each sized to the body's outline; CircleSections points on
each, point 0 on the midline. Fins: the base species' fin vertices carried into
the photo the way the body was, then fitted to the fin seen there; a fin the
photo does not show takes body skin near its attachment instead.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage  # type: ignore[import-untyped]

from fishgen.authoring.photo.anatomy import BodyOutline
from fishgen.authoring.photo.sideview import SideView, circle_sines
from fishgen.errors import FishgenError

SPACINGS = ("projected", "even")
#: A fin counts as seen when the photo shows fin pixels over this share of its expected area.
SEEN_SHARE = 0.2


def circle_heights(circles: int, spacing: str) -> np.ndarray:
    """Height of each CircleSection point on its vertical line, as a share of the way from the
    midline to the top (+) or bottom (-) outline.

    ``projected``: where an orthographic side view shows ring point i (sin of its angle,
    normalised by the highest point so the outline is reached). ``even``: equal steps, as
    the points in BonyBream's Appendix A listing are spaced.
    """
    if spacing == "even":
        from fishgen.geometry.body import ring_offset

        q = (4.0 * (np.arange(circles) + ring_offset(circles)) / circles) % 4.0   # quarter turns from +z
        return np.where(q <= 1, q, np.where(q <= 3, 2 - q, q - 4))
    s = circle_sines(circles)
    up, down = s.max(), -s.min()
    return np.where(s >= 0, s / (up if up > 0 else 1), s / (down if down > 0 else 1))


def body_points(outline: BodyOutline, sections: int, circles: int, spacing: str = "projected") -> np.ndarray:
    """(B, C, 2) frame points of the body's texture points."""
    x = outline.x0 + np.linspace(0.0, 1.0, sections) * outline.x_scale
    up, down = outline.half_heights(x)
    mid = outline.midline(x)
    f = circle_heights(circles, spacing)[None, :]
    y = mid[:, None] - np.where(f >= 0, f * up[:, None], f * down[:, None])
    return np.stack([np.broadcast_to(x[:, None], y.shape), y], axis=2)


def thesis_to_frame(outline: BodyOutline, view: SideView, xy: np.ndarray) -> np.ndarray:
    """Map side-view thesis points into the frame by the body's measured scale."""
    xy = np.asarray(xy, float)
    x = outline.x0 + xy[:, 0] / view.length * outline.x_scale
    return np.stack([x, outline.midline(x) - xy[:, 1] * outline.y_scale], axis=1)


@dataclass(frozen=True)
class FinResult:
    points: np.ndarray     # (N, 2) frame points in Fixel's order
    seen: bool
    stretch: float         # how much the fin's outer edge was moved to meet the photo's fin
    reach: float = 1.0     # the photo's fin reach over the base species' (what --fit-shape scales by)
    area: int = 0          # pixels the base species' fin covers in the frame


#: Fixel's order per fin kind: indices of base (attached) and outer vertices.
def _rows(name: str, count: int) -> tuple[np.ndarray, np.ndarray]:
    if name == "caudal":
        return np.array([0]), np.arange(1, count)
    if name == "pelvic":
        n = count // 2
        return np.r_[0, 4:4 + n - 2, 1], np.r_[2, 4 + n - 2:count, 3]
    if name == "pectoral":
        n = (count - 1) // 2
        return np.r_[1, 3:3 + n - 1, 2], np.r_[0, 3 + n - 1:count]
    n = count // 2
    return np.r_[1, 4:4 + n - 2, 2], np.r_[0, 4 + n - 2:count, 3]


def fin_points(name: str, fin_xy: np.ndarray, faces: np.ndarray, outline: BodyOutline, view: SideView,
               mask: np.ndarray, body: np.ndarray, search: float = 1 / 3,
               seen: np.ndarray | None = None) -> FinResult:
    """One fin's texture points; ``body`` is the body's region in the frame (bool mask). Fin
    pixels count up to ``search`` x the fin's size beyond where the base species puts it.
    ``seen``: the fin's vertices in the frame where a render in perspective shows them, when the
    photo was taken so (else they are carried in by the body's outline)."""
    pts = thesis_to_frame(outline, view, fin_xy) if seen is None else np.asarray(seen, float)
    if not np.isfinite(pts).all():  # an outline too thin to measure (a 2000 x 64 photo at 3 sections)
        raise FishgenError(f"expected a fish whose outline places its {name} fin, found an outline too "
                           "thin to measure (a taller photo, or more --body-sections)")
    if name == "pectoral":  # it lies over the flank in a side view: what is there is its texture
        return FinResult(pts, True, 1.0)
    expected = _raster(pts, faces, mask.shape)
    area = int(expected.sum())
    base_idx, outer_idx = _rows(name, len(pts))

    outside, _ = ndimage.label(mask & ~body, structure=np.ones((3, 3), bool))
    touching = np.unique(outside[expected & (outside > 0)])
    fin_pixels = np.isin(outside, touching[touching > 0]) & _grown(expected, pts, search)
    # Beside a fin (the anal fin next to the caudal) another fin may join its blob outside the
    # body: only columns over the fin's own span, a quarter of its width either way, count.
    lo, hi = pts[:, 0].min(), pts[:, 0].max()
    pad = 0.25 * (hi - lo)
    cols = np.arange(mask.shape[1]) + 0.5
    fin_pixels &= ((cols >= lo - pad) & ((cols <= hi + pad) | (name == "caudal")))[None, :]
    if area == 0 or fin_pixels.sum() < SEEN_SHARE * area:
        return FinResult(_on_skin(pts, base_idx, body, outline), False, 0.0)
    base_c = pts[base_idx].mean(axis=0)
    outward = pts[outer_idx].mean(axis=0) - base_c
    norm = np.linalg.norm(outward)
    if norm < 1e-9:
        return FinResult(pts, True, 1.0)
    d = outward / norm
    ys, xs = np.nonzero(fin_pixels)
    reach_seen = float(((np.stack([xs + 0.5, ys + 0.5], 1) - base_c) @ d).max())  # a thin tip is few pixels
    reach_model = ((pts[outer_idx] - base_c) @ d).max()
    # Only ever grow: the texture's fin must cover the fin the photo shows. A smaller fin in the
    # photo keeps its own size (the mask or blending shows it as it is); --fit-shape resizes fins.
    reach = float(reach_seen / reach_model) if reach_model > 0 else 1.0
    stretch = float(np.clip(reach, 1.0, 1.6))
    if stretch < 1.03:
        return FinResult(pts, True, 1.0, reach, area)
    moved = pts.copy()
    along = (pts[outer_idx] - base_c) @ d
    moved[outer_idx] += ((stretch - 1.0) * along)[:, None] * d[None, :]
    return FinResult(moved, True, stretch, reach, area)


def _raster(pts: np.ndarray, faces: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    from PIL import Image, ImageDraw

    img = Image.new("L", (shape[1], shape[0]), 0)
    draw = ImageDraw.Draw(img)
    for tri in faces:
        draw.polygon([(float(x), float(y)) for x, y in pts[tri]], fill=255)
    return np.asarray(img) >= 128


def _grown(expected: np.ndarray, pts: np.ndarray, search: float) -> np.ndarray:
    """The expected fin area, widened by ``search`` x its size: a real fin is rarely where the
    base species puts it to the pixel."""
    size = float(np.ptp(pts, axis=0).max())
    reach = max(2, int(size * search))
    dist = ndimage.distance_transform_edt(~expected)
    return dist <= reach


def _on_skin(pts: np.ndarray, base_idx: np.ndarray, body: np.ndarray, outline: BodyOutline) -> np.ndarray:
    """Squeeze an unseen fin onto body skin just inside its attachment line."""
    anchor = pts[base_idx].mean(axis=0)
    x = float(np.clip(anchor[0], outline.x0, outline.x0 + outline.x_scale))
    up, down = outline.half_heights(np.array([x]))
    mid = float(outline.midline(np.array([x]))[0])
    inward = np.array([x, mid - 0.5 * up[0] if anchor[1] < mid else mid + 0.5 * down[0]])
    span = max(float(up[0] + down[0]), 2.0)
    local = pts - pts.mean(axis=0)
    scale = 0.3 * span / max(float(np.abs(local).max()), 1e-9)
    return inward + local * scale
