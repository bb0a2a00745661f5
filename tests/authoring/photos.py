"""Synthetic "photos" of the shipped species and where their texture points truly are.

A photo is an orthographic left-side render on a transparent background; the
truth is every ring and fin vertex projected by the same camera. The photo
kinds of the robustness checks (noise, JPEG, gradient background, mirrored,
rotated) are made from it, with the truth carried through the same change.
"""
from __future__ import annotations

import io
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from PIL import Image

from fishgen.assembly.fins import build_fins
from fishgen.assembly.fish import METRES_PER_WORLD_UNIT, THESIS_TO_GLTF, build_fish
from fishgen.authoring.photo.sideview import FIN_PARTS
from fishgen.geometry.body import ring_positions
from fishgen.geometry.shapes import profile_for
from fishgen.preview.pipeline import frame_scene
from fishgen.species.model import Species

SIZE = (1024, 512)
PARAMS_DIR = Path(__file__).resolve().parents[2] / "params"


@dataclass(frozen=True)
class Photo:
    rgba: np.ndarray                 # (H, W, 4) uint8
    body: np.ndarray                 # (B*C, 2) true texture points, pixels
    fins: dict[str, np.ndarray]      # fin name -> (N, 2) true points, pixels

    @property
    def size(self) -> np.ndarray:
        return np.array([self.rgba.shape[1], self.rgba.shape[0]], float)

    def save(self, path, fmt: str = "PNG", **kw) -> None:
        img = Image.fromarray(self.rgba, "RGBA")
        if fmt != "PNG":
            img = img.convert("RGB")
        img.save(path, fmt, **kw)


def truth_points(species: Species, project) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    rings, _ = ring_positions(profile_for(species.shape_class, species.shape_params), species.body_sections,
                              species.circle_sections, species.scale)
    fins = {f.name: f for f in build_fins(replace(species, texture_points=None), rings,
                                          clear_of_caudal=False)}
    return project(rings.reshape(-1, 3)), {n: project(fins[p].mesh.positions) for n, p in FIN_PARTS.items()
                                           if p in fins}


def render_photo(species: Species, size=SIZE) -> Photo:
    """Side view, orthographic, transparent background, and the camera's own projection."""
    from fishgen.preview.render import Renderer

    w, h = size
    scene = build_fish(species)
    cam = frame_scene(scene, "side", w / h, ortho=True)
    renderer = Renderer(w, h)
    try:
        rgba = renderer.render(scene, cam, None, (0.0, 0.0, 0.0, 0.0))
    finally:
        renderer.release()
    vp = cam.projection() @ cam.view()
    metres = species.world_scale * METRES_PER_WORLD_UNIT
    centre = np.array([0.5 * species.scale[0], 0.0, 0.0])

    def project(p3: np.ndarray) -> np.ndarray:
        g = (np.asarray(p3, float) - centre) @ THESIS_TO_GLTF.T * metres
        c = np.c_[g, np.ones(len(g))] @ vp.T
        ndc = c[:, :2] / c[:, 3:4]
        return np.stack([(ndc[:, 0] + 1) / 2 * w, (1 - ndc[:, 1]) / 2 * h], 1)

    body, fins = truth_points(species, project)
    return Photo(rgba, body, fins)


def _map(photo: Photo, rgba: np.ndarray, f) -> Photo:
    return Photo(rgba, f(photo.body), {n: f(p) for n, p in photo.fins.items()})


def on_background(photo: Photo, top=(200, 215, 230), bottom=(150, 175, 200), noise: float = 0.0,
                  seed: int = 0) -> Photo:
    """Composite onto a vertical gradient (equal colours: a plain backdrop), plus sensor noise."""
    h, w = photo.rgba.shape[:2]
    t = np.linspace(0, 1, h)[:, None, None]
    bg = (1 - t) * np.array(top, float) + t * np.array(bottom, float)
    a = photo.rgba[:, :, 3:4] / 255.0
    rgb = photo.rgba[:, :, :3] * a + bg * (1 - a)
    if noise:
        rgb = rgb + np.random.default_rng(seed).normal(0, noise, rgb.shape)
    out = np.dstack([np.clip(rgb, 0, 255).astype(np.uint8), np.full((h, w), 255, np.uint8)])
    return _map(photo, out, lambda p: p)


def jpeg(photo: Photo, quality: int = 60) -> Photo:
    buf = io.BytesIO()
    Image.fromarray(photo.rgba).convert("RGB").save(buf, "JPEG", quality=quality)
    rgb = np.asarray(Image.open(io.BytesIO(buf.getvalue())).convert("RGB"))
    return _map(photo, np.dstack([rgb, np.full(rgb.shape[:2], 255, np.uint8)]), lambda p: p)


def mirrored(photo: Photo) -> Photo:
    w = photo.rgba.shape[1]
    return _map(photo, np.ascontiguousarray(photo.rgba[:, ::-1]),
                lambda p: np.stack([w - p[:, 0], p[:, 1]], 1))


def rotated(photo: Photo, degrees: float) -> Photo:
    """Turned ``degrees`` counter-clockwise on screen (PIL's sense) on a grown canvas."""
    img = Image.fromarray(photo.rgba, "RGBA")
    out = img.rotate(degrees, resample=Image.Resampling.BICUBIC, expand=True)
    w, h = img.size
    w2, h2 = out.size
    a = np.radians(degrees)

    def f(p: np.ndarray) -> np.ndarray:
        x, y = p[:, 0] - w / 2, p[:, 1] - h / 2
        return np.stack([w2 / 2 + x * np.cos(a) + y * np.sin(a), h2 / 2 - x * np.sin(a) + y * np.cos(a)], 1)

    return _map(photo, np.asarray(out), f)


def errors(species: Species, photo: Photo) -> tuple[np.ndarray, dict[str, float]]:
    """(per body point error, per fin max point error) as fractions of the texture's size."""
    from fishgen.species.model import TexturePoints

    tp: TexturePoints | None = species.texture_points
    assert tp is not None
    size = photo.size
    body = np.linalg.norm(np.asarray(tp.body) - photo.body / size, axis=1)
    fins = {n: float(np.linalg.norm(np.asarray(getattr(tp, n)) - p / size, axis=1).max())
            for n, p in photo.fins.items()}
    return body, fins


def rendered_mask(species: Species) -> np.ndarray:
    """The rebuilt species' own silhouette, rendered as the photo was."""
    return render_photo(species).rgba[:, :, 3] >= 64


#: What may happen to a photo between the camera and `fishgen texture`: each a Photo -> Photo.
KINDS = {
    "transparent": lambda p: p,
    "plain": lambda p: on_background(p, (190, 205, 220), (190, 205, 220)),
    "gradient+noise": lambda p: on_background(p, noise=6.0),
    "jpeg": lambda p: jpeg(on_background(p, (200, 200, 200), (170, 180, 190)), 60),
    "mirrored": mirrored,
    "rotated+10": lambda p: rotated(p, 10.0),
    "rotated-10": lambda p: rotated(p, -10.0),
}
