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


def _parts(scene):
    """(node name, primitive) of every drawn triangle primitive."""
    return [(scene.nodes[n].name, prim) for n, prim in scene.drawn() if prim.mode == "TRIANGLES"]


def part_names(scene) -> list[str]:
    return [name for name, _ in _parts(scene)]


def part_coverage(scene, view: str, size: tuple[int, int]) -> dict[str, np.ndarray]:
    """{part name: (H, W) float32 in [0, 1], how much of each pixel that part visibly covers}.

    Every part is drawn flat, unlit and untextured; a textured cut-out (MASK or BLEND
    fin) keeps its texture's alpha as a MASK, so a fin's outline is its drawn outline.
    Three parts at a time go to the red, green and blue channels, the rest stay black
    but still hide what is behind them, so anti-aliased edges give fractional coverage
    rather than colours to classify.
    """
    from fishgen.scene.model import Image, Material

    names = part_names(scene)
    groups = [names[k:k + 3] for k in range(0, len(names), 3)]
    scenes = []
    for group in groups:
        s = copy.deepcopy(scene)
        for name, prim in _parts(s):
            rgb = [0.0, 0.0, 0.0]
            if name in group:
                rgb[group.index(name)] = 1.0
            old = s.materials[prim.material] if prim.material is not None else Material("none")
            flat = Material(f"id {name}", (*rgb, 1.0), unlit=True, double_sided=old.double_sided)
            prim.attributes.pop("COLOR_0", None)
            if old.texture is not None and old.alpha_mode != "OPAQUE":
                # keep only the texture's alpha: it cuts the outline
                white = s.images[old.texture].rgba().copy()
                white[..., :3] = 255
                flat.texture = s.add_image(Image("alpha only", b"", pixels=white))
                flat.alpha_mode = "MASK"
                flat.alpha_cutoff = old.alpha_cutoff
            prim.material = s.add_material(flat)
        scenes.append(s)
    out = {}
    for group, image in zip(groups, _render(scenes, view, size, (0, 0, 0, 255)), strict=True):
        for k, name in enumerate(group):
            out[name] = image[..., k].astype(np.float32) / 255.0
    return out


def beauty_render(scene, view: str, size: tuple[int, int], background=None) -> np.ndarray:
    """(H, W, 4) uint8 straight-alpha RGBA; ``background`` an sRGB (r, g, b) or None (transparent)."""
    return _render([scene], view, size, (0, 0, 0, 0) if background is None else (*background, 255))[0]


def texture_of(scene, part: str):
    """(texture (H, W, 4) uint8 sRGB or None, (N, 2) float texture coordinates of the part's vertices)."""
    for name, prim in _parts(scene):
        if name == part:
            mat = scene.materials[prim.material] if prim.material is not None else None
            image = scene.images[mat.texture].rgba() if mat is not None and mat.texture is not None else None
            return image, prim.attributes.get("TEXCOORD_0")
    raise KeyError(part)


def without_part(scene, name: str):
    s = copy.deepcopy(scene)
    found = [i for i, node in enumerate(s.nodes) if node.name == name and node.mesh is not None]
    if not found:
        raise KeyError(f"{scene.name} has no part {name!r}")
    for node in s.nodes:
        node.children = [c for c in node.children if c not in found]
    s.roots = [r for r in s.roots if r not in found]
    return s


def upside_down(scene):
    from fishgen.scene.model import Node

    s = copy.deepcopy(scene)
    # 180 degrees about +Z
    s.nodes.append(Node("flip", rotation=(0.0, 0.0, 1.0, 0.0), children=list(s.roots)))
    s.roots = [len(s.nodes) - 1]
    return s


def without_texture(scene):
    s = copy.deepcopy(scene)
    for m in s.materials:
        m.texture = None
    return s


_CAMERAS = {"left": ("side", 0.0), "right": ("side", math.pi), "top": ("top", 0.0),
            "front": ("front", 0.0), "three-quarter": ("three-quarter", 0.0)}


def _render(scenes, view: str, size, background) -> list[np.ndarray]:
    """Each scene framed alone on ``view``; (H, W, 4) uint8 RGBA each, straight alpha."""
    from fishgen.preview.pipeline import frame_scene
    from fishgen.preview.render import Renderer

    named, azimuth = _CAMERAS[view]
    w, h = size
    renderer = Renderer(w, h)  # its upload cache is keyed by id(scene): every scene stays alive here
    try:
        return [renderer.render(s, frame_scene(s, named, w / h, azimuths=(azimuth,)),
                                None, tuple(c / 255.0 for c in background)) for s in scenes]
    finally:
        renderer.release()
