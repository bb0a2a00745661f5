"""The one place the reference tests touch fishgen's preview internals.

Everything test_reference.py needs from the preview renderer goes through the
functions below, so a new scene model means rewriting this module only. The
interface, in terms a port must keep:

    load(path) -> scene                 a species (.txt) or cloud (.awn) file, as the preview loads it
    part_names(scene) -> [str]          names of the mesh parts (glTF node names: body, dorsal_fin, ...)
    part_coverage(scene, view, size) -> {part: (H, W) float32 in [0, 1]}
                                        how much of each pixel each part visibly covers (hidden
                                        parts and the background count 0; edges are fractional)
    beauty_render(scene, view, size, background=None) -> image
                                        the preview as `fishgen preview` draws it; (H, W, 4) uint8 RGBA,
                                        straight alpha; background None = transparent
    texture_of(scene, part) -> (image | None, uvs | None)
                                        the part's base-colour texture, (H, W, 4) uint8 sRGB, and its
                                        vertices' texture coordinates (N, 2), glTF convention (v down)
    without_part(scene, name) -> scene  a copy with that part gone (KeyError if it has none)
    upside_down(scene) -> scene         a copy turned 180 degrees about the fish's spine
    without_texture(scene) -> scene     a copy with every base-colour texture removed

``view`` is one of VIEWS; ``size`` is (width, height). Scenes are never changed in place.
"""
from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np

VIEWS = ("left", "right", "top", "front", "three-quarter")
"""left: the fish's left flank (field-guide view, head to the image's left); right: its right
flank (head to the right); top, front and three-quarter as `fishgen preview --view` names them."""


def load(path):
    from fishgen.preview.inputs import load_input

    return load_input(Path(path))


def part_names(scene) -> list[str]:
    return [_name(scene, m) for m in scene.meshes]


def _name(scene, mesh) -> str:
    return scene.nodes[mesh.node].name if mesh.node is not None else ""


def part_coverage(scene, view: str, size: tuple[int, int]) -> dict[str, np.ndarray]:
    """{part name: (H, W) float32 in [0, 1], how much of each pixel that part visibly covers}.

    Every part is drawn flat, unlit and untextured; a textured cut-out (MASK or BLEND
    fin) keeps its texture's alpha as a MASK, so a fin's outline is its drawn outline.
    Three parts at a time go to the red, green and blue channels, the rest stay black
    but still hide what is behind them, so anti-aliased edges give fractional coverage
    rather than colours to classify.
    """
    names = part_names(scene)
    groups = [names[k:k + 3] for k in range(0, len(names), 3)]
    scenes = []
    for group in groups:
        s = copy.deepcopy(scene)
        for m in s.meshes:
            name = _name(s, m)
            rgb = [0.0, 0.0, 0.0]
            if name in group:
                rgb[group.index(name)] = 1.0
            mat = m.material
            mat.base_color = (*rgb, 1.0)
            mat.unlit = True
            m.colors = None
            if mat.texture is not None and mat.alpha_mode != "OPAQUE":
                white = mat.texture.copy()  # keep only the texture's alpha: it cuts the outline
                white[..., :3] = 255
                mat.texture = white
                mat.alpha_mode = "MASK"
            else:
                mat.texture = None
                mat.alpha_mode = "OPAQUE"
        scenes.append(s)
    out = {}
    for group, image in zip(groups, _render(scenes, view, size, (0, 0, 0, 255))):
        for k, name in enumerate(group):
            out[name] = image[..., k].astype(np.float32) / 255.0
    return out


def beauty_render(scene, view: str, size: tuple[int, int], background=None) -> np.ndarray:
    """(H, W, 4) uint8 straight-alpha RGBA; ``background`` an sRGB (r, g, b) or None (transparent)."""
    return _render([scene], view, size, (0, 0, 0, 0) if background is None else (*background, 255))[0]


def texture_of(scene, part: str):
    """(texture (H, W, 4) uint8 sRGB or None, (N, 2) float texture coordinates of the part's vertices)."""
    for m in scene.meshes:
        if _name(scene, m) == part:
            return m.material.texture, m.uvs
    raise KeyError(part)


def without_part(scene, name: str):
    s = copy.deepcopy(scene)
    keep = [m for m in s.meshes if _name(s, m) != name]
    if len(keep) == len(s.meshes):
        raise KeyError(f"{scene.label} has no part {name!r}")
    s.meshes = keep
    return s


def upside_down(scene):
    from fishgen.preview.animation import Node

    s = copy.deepcopy(scene)
    roots = [i for i, n in enumerate(s.nodes) if n.parent is None]
    s.nodes.append(Node("flip", rotation=np.array([0.0, 0.0, 1.0, 0.0])))  # 180 degrees about +Z
    for i in roots:
        s.nodes[i].parent = len(s.nodes) - 1
    return s


def without_texture(scene):
    s = copy.deepcopy(scene)
    for m in s.meshes:
        m.material.texture = None
    return s


_CAMERAS = {"left": ("side", 0.0), "right": ("side", math.pi), "top": ("top", 0.0),
            "front": ("front", 0.0), "three-quarter": ("three-quarter", 0.0)}


def _render(scenes, view: str, size, background) -> list[np.ndarray]:
    """Each scene framed alone on ``view``; (H, W, 4) uint8 RGBA each, straight alpha."""
    from fishgen.preview.camera import frame
    from fishgen.preview.pipeline import subject_points
    from fishgen.preview.render import Renderer

    named, azimuth = _CAMERAS[view]
    w, h = size
    renderer = Renderer(w, h)  # its upload cache is keyed by id(scene): every scene stays alive here
    try:
        return [renderer.render(s, frame(subject_points(s, [None], None), named, w / h, azimuths=(azimuth,)),
                                None, tuple(c / 255.0 for c in background)) for s in scenes]
    finally:
        renderer.release()
