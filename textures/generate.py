"""Generate the shipped species files and their colour + mask textures.

    python textures/generate.py        # rewrites params/*.txt (but BonyBream) and textures/*.png

BonyBream's texture points come from the thesis (Appendix A); the other three
species are designed here and get Fixel-style texture points from
``fishgen.authoring.texture_points``. Every texture is painted from its species' texture
points, so fins and body land where the geometry expects them. As VRFish did,
the files are stored upside down (chapter 6); fishgen flips them on load.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFilter, ImageOps

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fishgen.authoring.texture_points import project_texture_points  # noqa: E402
from fishgen.species.model import Behaviour, CaudalFin, PectoralFin, PelvicFin, Species, VerticalFin  # noqa: E402
from fishgen.species.parser import parse_species  # noqa: E402
from fishgen.species.writer import format_species  # noqa: E402

SIZE = (512, 256)


# ---------------------------------------------------------------- species designs
def _behaviour(speed: float) -> Behaviour:
    return Behaviour((0.000009, 0.0000075, 0.0000071), 0.04, 0.35, 0.01, 0.15, speed, 50.0, 0.0015,
                     (0.04, 10.0))


DESIGNS = {
    # Monocentris japonica: short, rotund, armoured; the thesis' low level of detail (8 x 6).
    "pineapplefish": dict(
        sp=Species(
            name="pineapplefish", world_scale=16.0, urge_factor=0.008, start_position=(2.0, 3.0, -8.0),
            cube_size=10.0, colour=(1.0, 0.78, 0.2), shape_class="FishShapeSpline",
            shape_params=(0.08, 0.36, 0.3, 0.5, 0.6, 0.44, 0.82, 0.24, 0.93, 0.12),
            body_sections=8, circle_sections=6, textured=True, masked=True, turn_test=False,
            catchfish_test=False, scale=(0.19, 0.13, 0.09),
            caudal=CaudalFin(0.42, 0.36, 40.0, 2, (0.92, 0.0, 0.0), 0.0, 0.42, 40.0, 2, 12.0, 1.5),
            adipose=VerticalFin(5, 6, 0.0, 0.0, 0.0, 0.5),
            dorsal=VerticalFin(2, 6, 0.45, 0.08, 80.0, 0.85),
            pelvic=PelvicFin(5, 2, 3, 0.5, 0.3, 60.0, 5.0, 1.25),
            anal=VerticalFin(4, 6, 0.3, 0.06, -70.0, 0.9),
            pectoral=PectoralFin(2, 1, 2, 0.45, 10.0, 0.7, 0.0, 8.0, 2.0),
            transparency=1.0, behaviour=_behaviour(0.5)),
        palette=dict(back=(150, 95, 20), belly=(255, 226, 120), fin=(240, 190, 70), pattern="scales",
                     accent=(60, 30, 10))),
    # Centroberyx affinis (redfish): deep perch-like body, big eye, blended fins, 32 x 24.
    "centroberyx": dict(
        sp=Species(
            name="centroberyx", world_scale=20.0, urge_factor=0.009, start_position=(-3.0, 5.0, -6.0),
            cube_size=10.0, colour=(0.85, 0.2, 0.15), shape_class="FishShapeSpline",
            shape_params=(0.06, 0.3, 0.25, 0.5, 0.5, 0.47, 0.78, 0.24, 0.92, 0.12),
            body_sections=32, circle_sections=24, textured=True, masked=False, turn_test=False,
            catchfish_test=False, scale=(0.4, 0.16, 0.07),
            caudal=CaudalFin(0.62, 0.3, 32.0, 4, (0.93, 0.0, 0.0), 0.0, 0.62, 32.0, 4, 9.0, 0.75),
            adipose=VerticalFin(20, 22, 0.0, 0.0, 0.0, 0.5),
            dorsal=VerticalFin(9, 24, 0.55, 0.12, 75.0, 0.93),
            pelvic=PelvicFin(19, 9, 12, 0.35, 0.45, 55.0, 6.0, 1.0),
            anal=VerticalFin(19, 26, 0.45, 0.1, -70.0, 0.88),
            pectoral=PectoralFin(8, 1, 4, 0.55, 12.0, 0.7, 0.0, 6.0, 1.5),
            transparency=0.6, behaviour=_behaviour(0.7)),
        palette=dict(back=(150, 20, 25), belly=(250, 150, 130), fin=(235, 70, 60), pattern="bands",
                     accent=(110, 10, 15))),
    # Threadfin goldie (an anthias): slender, orange, lyre tail and a threadlike dorsal, 24 x 16.
    "threadfingoldie": dict(
        sp=Species(
            name="threadfingoldie", world_scale=17.0, urge_factor=0.01, start_position=(0.0, 2.0, -4.0),
            cube_size=8.0, colour=(1.0, 0.55, 0.1), shape_class="FishShapeHawk", shape_params=(),
            body_sections=24, circle_sections=16, textured=True, masked=True, turn_test=False,
            catchfish_test=False, scale=(0.12, 0.05, 0.025),
            caudal=CaudalFin(1.3, 0.35, 28.0, 4, (0.94, 0.0, 0.0), 0.0, 1.3, 28.0, 4, 15.0, 2.5),
            adipose=VerticalFin(19, 20, 0.0, 0.0, 0.0, 0.5),
            dorsal=VerticalFin(5, 19, 1.3, 0.15, 62.0, 0.7),
            pelvic=PelvicFin(14, 6, 8, 0.3, 1.1, 70.0, 8.0, 2.0),
            anal=VerticalFin(14, 19, 0.6, 0.1, -60.0, 0.85),
            pectoral=PectoralFin(6, 2, 3, 0.8, 8.0, 0.72, 0.0, 10.0, 2.5),
            transparency=1.0, behaviour=_behaviour(0.9)),
        palette=dict(back=(220, 90, 10), belly=(255, 200, 120), fin=(255, 140, 40), pattern="stripe",
                     accent=(200, 40, 140))),
}
BONYBREAM_PALETTE = dict(back=(70, 90, 70), belly=(225, 225, 205), fin=(180, 170, 120), pattern="spot",
                         accent=(30, 40, 60))


# ---------------------------------------------------------------- painting
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


def paint(sp: Species, palette: dict, seed: int) -> tuple[Image.Image, Image.Image]:
    """Upright colour and mask pictures painted from the species' texture points."""
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
    fin_rgb = np.array(palette["fin"])
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
    rows = (np.array(palette["back"])[None, :] * (1 - t[:, None])
            + np.array(palette["belly"])[None, :] * t[:, None])
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
    accent = tuple(palette["accent"])
    layer = Image.new("RGBA", SIZE, (0, 0, 0, 0))
    ld = ImageDraw.Draw(layer)
    pattern = palette["pattern"]
    if pattern == "scales":
        for y in range(0, h, 12):
            for x in range(int(u0), int(u1), 12):
                off = 6 if (y // 12) % 2 else 0
                ld.arc([x + off - 7, y - 7, x + off + 7, y + 7], 20, 160, fill=(*accent, 200), width=2)
    elif pattern == "bands":
        for k in range(5):
            x = u0 + (u1 - u0) * (0.25 + 0.13 * k)
            ld.rectangle([x, 0, x + 9, h], fill=(*accent, 90))
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


def save_pair(sp: Species, palette: dict, seed: int, colour_name: str, mask_name: str) -> None:
    colour, mask = paint(sp, palette, seed)
    # VRFish's convention: the texture file holds the picture upside down (thesis ch. 6).
    ImageOps.flip(colour).save(ROOT / "textures" / colour_name, optimize=True)
    ImageOps.flip(mask).save(ROOT / "textures" / mask_name, optimize=True)


def main() -> None:
    bony = parse_species((ROOT / "params" / "bonybream.txt").read_text(), "params/bonybream.txt")
    save_pair(bony, BONYBREAM_PALETTE, 1, "bonybream.png", "bonybream_mask.png")
    for seed, (name, design) in enumerate(DESIGNS.items(), start=2):
        sp = project_texture_points(design["sp"], aspect=SIZE[0] / SIZE[1])
        (ROOT / "params" / f"{name}.txt").write_text(
            format_species(sp, f"{name}.png", f"{name}_mask.png"))
        save_pair(sp, design["palette"], seed, f"{name}.png", f"{name}_mask.png")
        print(f"params/{name}.txt, textures/{name}.png, textures/{name}_mask.png")
    print("textures/bonybream.png, textures/bonybream_mask.png")


if __name__ == "__main__":
    main()
