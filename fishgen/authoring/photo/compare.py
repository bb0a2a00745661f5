"""Render a species side-on as the photo shows a fish, and measure how alike two silhouettes are."""
from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from fishgen.species.model import Species

DRAWN_ALPHA = 64
"""A rendered pixel is the fish's from this alpha: a quarter covered, so a thin fin's edge counts."""
HALF_ALPHA = 128
"""...and surely so from this one: half covered, as Blender's coverage counts a pixel. A fish that
matches the photo only by its quarter-covered pixels (a translucent fin's fading parts) is said to."""
SAMPLE_GRIDS = (3, 5)
"""The grids of samples a pixel :func:`half_covered` counts with (3 x 3, 5 x 5): a fin's thread
under a pixel wide is half covered at some grids and not at others, as at a renderer's own sample
positions, and where it sets the box the IoU crops to the figure turns on that chance (1206 on
ThreadfinGoldie: 0.845, 0.864, 0.845 at 3, 4 and 5; Blender 0.847). 4 x 4 said no miss the two
others did not, and its render was a third of the check's cost."""


def render_side(species: Species, width: int, height: int, distance: float | None = None,
                renderer: Any = None, coverage: bool = False) -> np.ndarray:
    """(H, W, 4) uint8 left-side render on a transparent background, head left: orthographic, or
    in the perspective of a camera ``distance`` fish lengths away. ``renderer``: one to reuse,
    with its uploads (a new one shares the thread's GL context: only its framebuffers are new).
    ``coverage``: only the (H, W) alpha, the silhouette's measure."""
    from fishgen.assembly.fish import build_fish
    from fishgen.preview.render import Renderer

    scene = build_fish(species, still=True)
    camera = side_camera(scene, width, height, distance)
    own = renderer is None
    renderer = Renderer(width, height) if own else renderer
    try:
        if coverage:
            return renderer.coverage(scene, camera)
        return renderer.render(scene, camera, None, (0.0, 0.0, 0.0, 0.0))
    finally:
        if own:
            renderer.release()


def half_covered(species: Species, width: int, height: int, distance: float | None = None,
                 grid: int = 4) -> np.ndarray:
    """(H, W) bool: the pixels :func:`render_side`'s picture of ``species`` covers at least half,
    counted from ``grid`` x ``grid`` samples a pixel, each drawn on its own, so a masked fin's
    texture is read and alpha-tested at every sample, and a blended fin's alpha averaged over them:
    as Blender's Cycles counts coverage (16 samples, box filter). :func:`render_side` multisamples
    4 times a pixel but shades, and so alpha-tests, once a pixel: a fin's thin tip the mask texture
    trims at most of a pixel's samples is drawn whole, and a thread under a pixel wide covers the
    pixel by whichever samples it crosses. Where such a tip sets the box the IoU crops to, the two
    part: 1502 on BonyBream (Blender's photo, 50 mm) 0.882 counted at half by :func:`render_side`,
    0.846 here, 0.847 in Blender, whose render of the file stops its dorsal's tip 4 px lower."""
    (covered,) = half_covered_grids(species, width, height, distance, (grid,))
    return covered


def half_covered_grids(species: Species, width: int, height: int, distance: float | None = None,
                       grids: tuple[int, ...] = SAMPLE_GRIDS) -> list[np.ndarray]:
    """:func:`half_covered` at each of ``grids``: the fish built once, and drawn by one renderer
    as large as the finest grid needs, each coarser grid's frame in its corner."""
    from fishgen.assembly.fish import build_fish
    from fishgen.preview.render import Renderer

    scene = build_fish(species, still=True)
    camera = side_camera(scene, width, height, distance)
    finest = max(grids)
    renderer = Renderer(width * finest, height * finest, samples=1)
    try:
        alphas = [renderer.coverage(scene, camera, size=(width * grid, height * grid)) for grid in grids]
    finally:
        renderer.release()
    return [alpha.reshape(height, grid, width, grid).mean(axis=(1, 3), dtype=np.float32) >= 127.5
            for alpha, grid in zip(alphas, grids, strict=True)]


def side_camera(scene: Any, width: int, height: int, distance: float | None = None) -> Any:
    """The camera :func:`render_side` draws ``scene`` (a fish) with."""
    from fishgen.preview.camera import frame
    from fishgen.preview.pipeline import subject_points

    points, _ = subject_points(scene, [None], None)   # a fish: vertices, which reach no farther
    camera = frame(points, "side", width / height, ortho=distance is None)
    return camera if distance is None else _from_afar(camera, points, distance)


def seen_fins(species: Species, width: int, height: int, distance: float,
              target: np.ndarray) -> dict[str, np.ndarray]:
    """Where :func:`render_side`'s picture of ``species`` from ``distance`` fish lengths shows each
    fin's vertices (one per texture point, as :func:`.sideview.side_view` lists them), in the
    pixels of the silhouette ``target``: the picture's box laid on the target's, as
    :func:`silhouette_iou` lays them. Fin name -> (N, 2). A fin standing out towards the camera (a
    paired fin) is seen larger and lower than side-on, and the fins are fitted as so seen: a fin's
    texture (and the mask cutting it) is then taken from where the photo shows it."""
    from fishgen.assembly.fins import build_fins
    from fishgen.assembly.fish import METRES_PER_WORLD_UNIT, THESIS_TO_GLTF, build_fish
    from fishgen.authoring.photo.sideview import FIN_PARTS
    from fishgen.geometry.body import ring_positions
    from fishgen.geometry.shapes import profile_for
    from fishgen.preview.render import Renderer

    bare = replace(species, texture_points=None, colour_texture=None, mask_texture=None)
    scene = build_fish(bare, still=True)
    camera = side_camera(scene, width, height, distance)
    renderer = Renderer(width, height)
    try:
        drawn = renderer.coverage(scene, camera) >= DRAWN_ALPHA
    finally:
        renderer.release()
    rings, _ = ring_positions(profile_for(bare.shape_class, bare.shape_params), bare.body_sections,
                              bare.circle_sections, bare.scale)
    built = {f.name: f for f in build_fins(bare, rings, clear_of_caudal=False)}
    # as fish_of places the thesis' scaled geometry: glTF axes in metres, centred on the body
    centre = np.array([0.5 * bare.scale[0], 0.0, 0.0])
    metres = bare.world_scale * METRES_PER_WORLD_UNIT
    viewproj = camera.projection() @ camera.view()
    d_rows, d_cols = np.flatnonzero(drawn.any(axis=1)), np.flatnonzero(drawn.any(axis=0))
    t_rows, t_cols = np.flatnonzero(target.any(axis=1)), np.flatnonzero(target.any(axis=0))
    if not (len(d_rows) and len(t_rows)):   # nothing to lay on: the fins stay where side-on puts them
        return {}
    kx = (t_cols[-1] + 1 - t_cols[0]) / (d_cols[-1] + 1 - d_cols[0])
    ky = (t_rows[-1] + 1 - t_rows[0]) / (d_rows[-1] + 1 - d_rows[0])
    out = {}
    for name, part in FIN_PARTS.items():
        if part not in built:
            continue
        world = (built[part].mesh.positions - centre) @ THESIS_TO_GLTF.T * metres
        clip = np.c_[world, np.ones(len(world))] @ viewproj.T
        ndc = clip[:, :2] / clip[:, 3:4]
        px = np.stack([(ndc[:, 0] + 1) / 2 * width, (1 - ndc[:, 1]) / 2 * height], axis=1)
        out[name] = np.stack([t_cols[0] + (px[:, 0] - d_cols[0]) * kx,
                              t_rows[0] + (px[:, 1] - d_rows[0]) * ky], axis=1)
    return out


def camera_distance(focal_length: float, photo_width: int, mask: np.ndarray) -> float:
    """How many fish lengths from the camera a fish ``mask`` shows was, photographed with a lens of
    ``focal_length`` mm on a 36 mm wide sensor: the focal length in pixels over the fish's length in
    pixels (its longer extent: a side photo shows a fish about level)."""
    ys, xs = np.nonzero(mask)
    length = max(float(np.ptp(xs)), float(np.ptp(ys))) + 1.0
    return focal_length / 36.0 * photo_width / length


def _from_afar(camera: Any, points: np.ndarray, distance: float) -> Any:
    """``camera``'s side view of ``points`` taken from ``distance`` times their length, its field of
    view narrowed to frame them as before."""
    back = (camera.eye - camera.target) / np.linalg.norm(camera.eye - camera.target)
    right = np.cross(-back, camera.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, -back)
    length, height = float(np.ptp(points @ right)), float(np.ptp(points @ up))
    far = distance * length
    half = max(0.5 * length / camera.aspect, 0.5 * height) / 0.8 / (far - 0.5 * float(np.ptp(points @ back)))
    return replace(camera, eye=camera.target + back * far, fov_y=2 * float(np.arctan(half)),
                   near=0.01 * far, far=10.0 * far + length, ortho=False)


def render_scale(species: Species, width: int, height: int) -> float:
    """Pixels a thesis unit spans in :func:`render_side`'s picture of ``species`` at this size:
    the camera frames the whole fish, so this follows from its extents alone (nothing is drawn)."""
    from fishgen.assembly.fish import METRES_PER_WORLD_UNIT, THESIS_TO_GLTF, build_fish
    from fishgen.preview.pipeline import frame_scene

    camera = frame_scene(build_fish(species, still=True), "side", width / height, ortho=True)
    vp = camera.projection() @ camera.view()
    # one thesis unit along the body, from the origin, in clip space (orthographic: w stays 1)
    ends = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]) @ THESIS_TO_GLTF.T
    ends *= species.world_scale * METRES_PER_WORLD_UNIT
    clip = np.c_[ends, np.ones(2)] @ vp.T
    return float(abs(clip[1, 0] - clip[0, 0]) / 2 * width)


def _crop(mask: np.ndarray) -> np.ndarray:
    ys, xs = np.nonzero(mask)
    return mask[ys.min():ys.max() + 1, xs.min():xs.max() + 1]


def silhouette_iou(a: np.ndarray, b: np.ndarray) -> float:
    """IoU of two silhouettes after each is cropped to its bounding box and ``b`` is scaled onto
    ``a``'s: a shape measure, blind to where and how large each fish sits in its frame."""
    from PIL import Image

    ca, cb = _crop(a), _crop(b)
    img = Image.fromarray(cb.astype(np.uint8) * 255).resize((ca.shape[1], ca.shape[0]),
                                                             Image.Resampling.BILINEAR)
    cb2 = np.asarray(img) >= 128
    union = (ca | cb2).sum()
    return float((ca & cb2).sum() / union) if union else 0.0


def compare_image(photo_rgba: np.ndarray, render_rgba: np.ndarray, caption: str, label: str = "photo"):
    """The photo (``label`` under it) and the rebuilt fish side by side on a light grey ground,
    with a caption."""
    from PIL import Image, ImageDraw

    h = max(photo_rgba.shape[0], render_rgba.shape[0])
    w = photo_rgba.shape[1] + render_rgba.shape[1]
    sheet = Image.new("RGBA", (w, h + 28), (236, 238, 240, 255))
    sheet.alpha_composite(Image.fromarray(photo_rgba, "RGBA"), (0, 0))
    sheet.alpha_composite(Image.fromarray(render_rgba, "RGBA"), (photo_rgba.shape[1], 0))
    draw = ImageDraw.Draw(sheet)
    draw.text((8, h + 8), label, fill=(40, 40, 40, 255))
    draw.text((photo_rgba.shape[1] + 8, h + 8), caption, fill=(40, 40, 40, 255))
    return sheet.convert("RGB")
