"""Is a fitted fish whole? The checks a --fit-shape result must pass before it is written.

- **Fins attached**: no fin vertex that touches the body at rest (within 0.1 % of the body length)
  is ever farther than 1 % of the body length from the body's surface over the ``swim`` clip (the
  body-wave issue's check, ``tests/assembly/test_body_wave.py``), on the built glTF scene.
- **No fin taller than the fish**: a fin reaches no farther from the axis (on each side of it)
  than the photo's silhouette does anywhere over the fin's columns, give or take 3 % of the body
  length (in height and in place).
- **The caudal fin on the tail**: its connection point inside the body's last fifth, the fin
  reaching past the body's end and none of it in front of the connection.
- **The body never crosses itself**: valid spline control points, rings strictly in order along
  the axis, every inner ring of positive radius. A body of revolution over such rings cannot cross
  itself, and the body wave only shears it sideways (every point keeps its place along the fish),
  so it never does while swimming either.

Each failed check is one line saying what and where; an empty list means the fish is whole.
"""
from __future__ import annotations

import numpy as np

from fishgen.authoring.photo.draw import FIN_RECORDS, Drawer
from fishgen.species.model import Species

#: Fin vertices this close to the body at rest (share of the body length) count as attached.
TOUCHING = 1e-3
#: ... and must stay this close over the swim clip.
ATTACHED = 0.01
#: A fin may reach past the photo's fish by this share of the body length (drawing tolerance).
TALLER = 0.03
#: Times sampled over the swim clip.
CLIP_SAMPLES = 33
#: Body triangles searched per fin vertex (the nearest at rest; the wave moves them together).
NEAREST = 24


def fit_problems(species: Species, work: np.ndarray | None = None, placement=None) -> list[str]:
    """Every way ``species`` is broken, one line each. ``work`` and ``placement`` (the fit's
    levelled silhouette and where the species lies on it, :class:`.fit.ShapeFit`) enable the
    height check."""
    problems = body_problems(species) + caudal_problems(species)
    if problems:   # a broken body cannot be built into a scene worth checking further
        return problems
    problems += attachment_problems(species)
    if work is not None and placement is not None:
        problems += height_problems(species, work, placement)
    return problems


def body_problems(species: Species) -> list[str]:
    from fishgen.geometry.body import ring_positions
    from fishgen.geometry.shapes import profile_for
    from fishgen.shape_names import check_shape_params

    bad = check_shape_params(species.shape_class, species.shape_params)
    if bad:
        return [f"the body crosses itself: expected {bad}"]
    rings, radii = ring_positions(profile_for(species.shape_class, species.shape_params),
                                  species.body_sections, species.circle_sections, species.scale)
    x = rings[:, 0, 0]
    if not (np.all(np.isfinite(rings)) and np.all(np.diff(x) > 0)):
        return ["the body crosses itself: its rings are not in order along the axis"]
    inner = radii[1:-1]
    if inner.size and not np.all(inner > 1e-6):
        k = int(np.argmin(inner)) + 1
        return [f"the body crosses itself: it pinches to nothing at BodySection {k}"]
    return []


def caudal_problems(species: Species) -> list[str]:
    from fishgen.assembly.fins import caudal_params
    from fishgen.geometry.fins import caudal_fin
    from fishgen.geometry.shapes import profile_for

    c = species.caudal
    sx, sy, _ = species.scale
    cx, cy = c.connection[0], c.connection[1]
    radius = float(profile_for(species.shape_class, species.shape_params)(np.array([min(cx, 1.0)]))[0])
    if not (0.8 <= cx < 1.0 and abs(cy) * sy <= radius * sy + 1e-9):
        return [f"the caudal fin is off the tail: its connection ({cx:g}, {cy:g}) is not inside the "
                "body's last fifth"]
    fin = caudal_fin(caudal_params(c), np.asarray(species.scale, float))
    xs = fin.mesh.positions[:, 0]
    if xs.max() <= sx:
        return ["the caudal fin is off the tail: it does not reach past the body's end"]
    if xs.min() < cx * sx - 1e-9:
        return ["the caudal fin is off the tail: part of it points forward over the body"]
    return []


def attachment_problems(species: Species) -> list[str]:
    """The swim clip's fin gap: fins that touch the body at rest must stay on it as it swims."""
    from fishgen.assembly.fish import build_fish
    from fishgen.scene.pose import deformed, pose

    scene = build_fish(species)
    nodes = {n.name: i for i, n in enumerate(scene.nodes)}
    drawn = dict(scene.drawn())
    body_node = nodes.get("body")
    if body_node is None or body_node not in drawn:
        return ["the fish has no body"]
    rest = pose(scene)
    faces = np.asarray(drawn[body_node].indices).reshape(-1, 3)
    body_rest = deformed(scene, body_node, drawn[body_node], rest)[0]
    length = float(np.ptp(body_rest[:, 2])) or 1.0
    tri_rest = body_rest[faces]
    centroids = tri_rest.mean(axis=1)
    touching: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    for node in nodes.values():
        if node not in drawn or node == body_node:
            continue
        pts = deformed(scene, node, drawn[node], rest)[0]
        near = np.argsort(np.linalg.norm(pts[:, None, :] - centroids[None, :, :], axis=2),
                          axis=1)[:, :NEAREST]
        dist = _distance(pts, tri_rest, near)
        idx = np.flatnonzero(dist < TOUCHING * length)
        if idx.size:
            touching[node] = (idx, near[idx])
    clip = scene.clip("swim")
    if clip is None or not touching:
        return []
    worst, where = 0.0, ""
    names = {i: n for n, i in nodes.items()}
    for t in np.linspace(0.0, clip.duration, CLIP_SAMPLES):
        posed = pose(scene, float(t), clip)
        tri = deformed(scene, body_node, drawn[body_node], posed)[0][faces]
        for node, (idx, near) in touching.items():
            pts = deformed(scene, node, drawn[node], posed)[0][idx]
            gap = float(_distance(pts, tri, near).max())
            if gap > worst:
                worst, where = gap, names[node]
    if worst > ATTACHED * length:
        return [f"the {_fin_name(where)} comes off the body while swimming "
                f"({worst / length:.1%} of the body length; at most {ATTACHED:.0%})"]
    return []


def _fin_name(node: str) -> str:
    """'pelvic_fin_left' -> 'left pelvic fin'."""
    words = node.split("_")
    if words[-1] in ("left", "right"):
        words = [words[-1], *words[:-1]]
    return " ".join(words)


def _distance(points: np.ndarray, triangles: np.ndarray, candidates: np.ndarray) -> np.ndarray:
    """Distance of each point to the nearest of its candidate triangles (closest point on a
    triangle by its Voronoi regions, Ericson 2005, 5.1.5), vectorised."""
    p = points[:, None, :]
    a, b, c = (triangles[candidates][:, :, k, :] for k in range(3))
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = _dot(ab, ap), _dot(ac, ap)
    bp = p - b
    d3, d4 = _dot(ab, bp), _dot(ac, bp)
    cp = p - c
    d5, d6 = _dot(ab, cp), _dot(ac, cp)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = va + vb + vc
        v = np.where(denom != 0, vb / denom, 0.0)
        w = np.where(denom != 0, vc / denom, 0.0)
        closest = a + ab * v[..., None] + ac * w[..., None]          # inside the face
        t_ab = np.clip(np.where(d1 - d3 != 0, d1 / (d1 - d3), 0.0), 0, 1)
        t_ac = np.clip(np.where(d2 - d6 != 0, d2 / (d2 - d6), 0.0), 0, 1)
        t_bc = np.clip(np.where((d4 - d3) + (d5 - d6) != 0, (d4 - d3) / ((d4 - d3) + (d5 - d6)), 0.0), 0, 1)
    on_ab = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
    on_ac = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
    on_bc = (va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0)
    closest = np.where(on_bc[..., None], b + (c - b) * t_bc[..., None], closest)
    closest = np.where(on_ac[..., None], a + ac * t_ac[..., None], closest)
    closest = np.where(on_ab[..., None], a + ab * t_ab[..., None], closest)
    closest = np.where(((d6 >= 0) & (d5 <= d6))[..., None], c, closest)
    closest = np.where(((d3 >= 0) & (d4 <= d3))[..., None], b, closest)
    closest = np.where(((d1 <= 0) & (d2 <= 0))[..., None], a, closest)
    return np.linalg.norm(closest - p, axis=2).min(axis=1)


def _dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.einsum("...k,...k->...", u, v)


def height_problems(species: Species, work: np.ndarray, placement) -> list[str]:
    """Fins reaching farther from the axis than the photographed fish does where they stand, in the
    fit's levelled frame."""
    drawer = Drawer(species, placement, work.shape)
    rows = np.arange(work.shape[0])[:, None] + 0.5
    off_axis = np.abs(rows - placement.y0)
    length = species.scale[0] * placement.s
    out = []
    for name in FIN_RECORDS:
        layer = drawer.layers[name]
        if not layer.any():
            continue
        for above in (True, False):   # the caudal fin has a lobe each side; judge each against its own
            side = (rows < placement.y0) if above else (rows >= placement.y0)
            part = layer & side
            if not part.any():
                continue
            fin = np.where(part, off_axis, -1.0).max(axis=0)
            cols = np.flatnonzero(fin >= 0)
            # the fin's place: its columns, give or take the tolerance (a fin a few pixels off
            # sideways is not a fin too tall)
            pad = int(np.ceil(TALLER * length))
            place = slice(max(0, cols[0] - pad), cols[-1] + pad + 1)
            photo = np.where(work[:, place] & side, off_axis, 0.0).max()
            worst = float(fin[cols].max() - photo)
            if worst > TALLER * length:
                out.append(f"the {name} fin stands {worst / length:.0%} of the body length past the "
                           "photo's fish")
                break
    return out
