"""Procedural skin: a species' colour texture and fin mask painted from its own texture points.

Fins get a membrane with rays, the body a back-to-belly gradient, a pattern,
a lateral line, a gill cover and an eye, all placed by the texture points so
they land where the geometry expects them. Used for the shipped species
(textures/generate.py) and for `fishgen species --random`.
"""
from __future__ import annotations

import io
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from PIL import Image, ImageDraw, ImageFilter, ImageOps

from fishgen.species.model import Species

SIZE = (512, 256)
PATTERNS = ("scales", "bands", "stripe", "spot")
RGB = tuple[int, int, int]


@dataclass(frozen=True)
class Palette:
    back: RGB
    belly: RGB
    fin: RGB
    pattern: str
    accent: RGB


def _px(points) -> list[tuple[float, float]]:
    return [(u * SIZE[0], v * SIZE[1]) for u, v in points]


def _rows(points, order: str):
    """Split Fixel-ordered fin points into (base row, outer row)."""
    p = list(points)
    if order == "vertical":      # T0, B0, Bn, Tn, B1.., T1..
        n = len(p) // 2
        base = [p[1]] + p[4:4 + n - 2] + [p[2]]
        top = [p[0]] + p[4 + n - 2:] + [p[3]]
        return base, top
    if order == "pectoral":      # T0, B0, Bn, B1.., T1..
        n = (len(p) - 1) // 2
        base = [p[1]] + p[3:3 + n - 1] + [p[2]]
        top = [p[0]] + p[3 + n - 1:] + [p[2]]
        return base, top
    n = len(p) // 2              # pelvic: B0, Bn, O0, On, B1.., O1..
    base = [p[0]] + p[4:4 + n - 2] + [p[1]]
    top = [p[2]] + p[4 + n - 2:] + [p[3]]
    return base, top


def _fin_outline(sp: Species):
    """(polygon, base row, outer row) in pixels for every fin present."""
    tp, c = sp.texture_points, sp.caudal
    assert tp is not None  # paint() checked
    n_top = c.top_triangles + 1
    origin, top_edge, bottom_edge = tp.caudal[0], tp.caudal[1:1 + n_top], tp.caudal[1 + n_top:]
    fins = [([origin] + list(top_edge) + list(reversed(bottom_edge)), [origin],
             list(top_edge) + list(reversed(bottom_edge)))]
    for name, kind in (("dorsal", "vertical"), ("adipose", "vertical"), ("anal", "vertical"),
                       ("pectoral", "pectoral"), ("pelvic", "pelvic")):
        if name in ("dorsal", "adipose", "anal") and not getattr(sp, name).present:
            continue
        base, top = _rows(getattr(tp, name), kind)
        fins.append((base + list(reversed(top)), base, top))
    return [(_px(poly), _px(base), _px(top)) for poly, base, top in fins]


def paint(sp: Species, palette: Palette | Mapping[str, Any], seed: int) -> tuple[Image.Image, Image.Image]:
    """Upright colour and mask pictures painted from the species' texture points."""
    if not isinstance(palette, Palette):
        palette = Palette(**palette)
    if sp.texture_points is None:
        raise ValueError(f"species {sp.name!r} has no texture points to paint by")
    rng = np.random.default_rng(seed)
    w, h = SIZE
    tp = sp.texture_points
    body = np.asarray(tp.body).reshape(sp.body_sections, sp.circle_sections, 2)
    top_line = [tuple(body[j][np.argmin(body[j][:, 1])]) for j in range(sp.body_sections)]
    bottom_line = [tuple(body[j][np.argmax(body[j][:, 1])]) for j in range(sp.body_sections)]
    body_poly = _px(top_line + list(reversed(bottom_line)))

    colour = Image.new("RGB", SIZE, (12, 30, 48))
    mask = Image.new("L", SIZE, 0)
    cd, md = ImageDraw.Draw(colour), ImageDraw.Draw(mask)

    # Fins first (the body overlaps their bases): membrane and rays. The mask's fin
    # outline is rounded below, so the mask technique visibly cuts the fin shape.
    fin_rgb = np.array(palette.fin)
    for poly, base, outer in _fin_outline(sp):
        cd.polygon(poly, fill=tuple(int(v) for v in fin_rgb * 0.85))
        md.polygon(poly, fill=255)
        for k, tip in enumerate(outer):
            root = base[min(int(k * len(base) / max(len(outer), 1)), len(base) - 1)]
            cd.line([root, tip], fill=tuple(int(v) for v in np.minimum(fin_rgb * 1.15, 255)), width=2)
    # Body: dorsal-to-ventral gradient, pattern, lateral line, gill cover and eye.
    grad = Image.new("RGB", SIZE)
    top_v = min(v for _, v in body_poly)
    bottom_v = max(v for _, v in body_poly)
    t = np.clip((np.arange(h) - top_v) / max(bottom_v - top_v, 1), 0, 1) ** 0.8
    rows = (np.array(palette.back)[None, :] * (1 - t[:, None])
            + np.array(palette.belly)[None, :] * t[:, None])
    grad_arr = np.repeat(rows[:, None, :], w, axis=1)
    grad_arr += rng.normal(0, 6, grad_arr.shape)           # skin noise
    grad = Image.fromarray(np.clip(grad_arr, 0, 255).astype(np.uint8))
    body_mask = Image.new("L", SIZE, 0)
    ImageDraw.Draw(body_mask).polygon(body_poly, fill=255)
    colour.paste(grad, (0, 0), body_mask)
    md.polygon(body_poly, fill=255)

    pd = ImageDraw.Draw(colour)
    u0, u1 = body_poly[0][0], body_poly[len(top_line) - 1][0]
    mid = [((a[0] + b[0]) / 2, a[1] + (b[1] - a[1]) * 0.45)
           for a, b in zip(_px(top_line), _px(bottom_line), strict=True)]
    accent = tuple(palette.accent)
    layer = Image.new("RGBA", SIZE, (0, 0, 0, 0))
    ld = ImageDraw.Draw(layer)
    pattern = palette.pattern
    if pattern == "scales":
        for y in range(0, h, 12):
            for x in range(int(u0), int(u1), 12):
                off = 6 if (y // 12) % 2 else 0
                ld.arc([x + off - 7, y - 7, x + off + 7, y + 7], 20, 160, fill=(*accent, 200), width=2)
    elif pattern == "bands":
        for k in range(5):
            bx = u0 + (u1 - u0) * (0.25 + 0.13 * k)
            ld.rectangle([bx, 0, bx + 9, h], fill=(*accent, 90))
    elif pattern == "stripe":
        ld.line(mid[1:-3], fill=(*accent, 200), width=5)
        ld.line([(p[0], p[1] - 12) for p in mid[1:-6]], fill=(255, 240, 120, 140), width=3)
    elif pattern == "spot":
        j = len(mid) // 5
        ld.ellipse([mid[j][0] - 9, mid[j][1] - 20, mid[j][0] + 9, mid[j][1] - 4], fill=(*accent, 220))
    ld.line(mid[1:-1], fill=(255, 255, 255, 70), width=1)  # lateral line
    colour.paste(layer, (0, 0), Image.composite(layer, Image.new("RGBA", SIZE), body_mask))
    head = _px(top_line)[max(1, len(top_line) // 5)]
    head_b = _px(bottom_line)[max(1, len(bottom_line) // 5)]
    pd.arc([head[0] - 30, head[1], head[0] + 8, head_b[1]], 300, 60, fill=accent, width=2)  # gill cover
    eye_u = body_poly[0][0] + (u1 - u0) * 0.07
    eye_v = mid[1][1] - (head_b[1] - head[1]) * 0.12
    r = max(3.0, (head_b[1] - head[1]) * 0.12)
    pd.ellipse([eye_u - r, eye_v - r, eye_u + r, eye_v + r], fill=(235, 235, 220))
    pd.ellipse([eye_u - r * 0.55, eye_v - r * 0.55, eye_u + r * 0.55, eye_v + r * 0.55], fill=(10, 10, 10))
    colour = colour.filter(ImageFilter.SMOOTH)
    # Round and slightly erode the fins' cut-out so its edge reads as membrane; the
    # body is pasted back whole so the body's own outline stays where the mesh is.
    mask = mask.filter(ImageFilter.GaussianBlur(3.0)).point(lambda v: 255 if v >= 150 else 0)
    mask.paste(255, (0, 0), body_mask)
    return colour, mask


def texture_files(sp: Species, palette: Palette | Mapping[str, Any], seed: int) -> tuple[bytes, bytes]:
    """(colour, mask) PNG bytes, upside down as VRFish stores textures (thesis chapter 6)."""
    out = []
    for img in paint(sp, palette, seed):
        buf = io.BytesIO()
        ImageOps.flip(img).save(buf, "PNG", optimize=True)
        out.append(buf.getvalue())
    return out[0], out[1]
