"""A filled cloud as a scene: one POINTS primitive, or billboard quads with a Gaussian sprite.

Points carry POSITION, COLOR_0 (linear, 16-bit so the sRGB bytes of PLY and
CSV come back exactly), ``_RADIUS``, ``_DENSITY`` and ``_CUBE`` (the cube each
particle was filled in; float32, as glTF allows no 32-bit integer attributes, exact
below 2^24 and the parser allows 100,000 cubes). Billboards are one quad per particle in the XY plane,
facing +Z (the glTF front), sized by the particle radius, with vertex alpha
from its density and an unlit, alpha-blended Gaussian sprite, for engines that
cannot size points.
"""
from __future__ import annotations

import os

import numpy as np

from fishgen.clouds.model import Cloud
from fishgen.clouds.sprite import gaussian_sprite_png
from fishgen.numeric import srgb8_to_linear16
from fishgen.scene.model import Image, Material, Mesh, Node, Primitive, Scene

BILLBOARD_BYTES = 4 * (12 + 8 + 4) + 6 * 4
"""glTF bytes per billboard particle: 4 corners of position, UV and RGBA8, 6 uint32 indices."""
POINT_BYTES = 12 + 8 + 4 + 4 + 4
"""glTF bytes per point particle: position, RGB16 colour (8-byte stride), radius, density, cube."""

_CORNERS = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], np.float32)
_UVS = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
_QUAD = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)


def cloud_scene(cloud: Cloud, *, billboards: bool = False, name: str = "cloud") -> Scene:
    scene = Scene(name=name)
    prim = _billboards(cloud, scene) if billboards else _points(cloud)
    mesh = scene.add_mesh(Mesh(name, [prim]))
    scene.add_node(Node(name=name, mesh=mesh))
    return scene


def _points(cloud: Cloud) -> Primitive:
    rgb = srgb8_to_linear16()[cloud.colors]
    return Primitive({"POSITION": cloud.centers, "COLOR_0": rgb, "_RADIUS": cloud.radii,
                      "_DENSITY": cloud.density, "_CUBE": cloud.cube_index.astype(np.float32)},
                     mode="POINTS")


def _billboards(cloud: Cloud, scene: Scene) -> Primitive:
    n = len(cloud)
    corners = np.repeat(cloud.centers[:, None, :], 4, axis=1)
    corners[:, :, :2] += _CORNERS[None] * cloud.radii[:, None, None]
    rgba = np.empty((n, 4), np.uint8)
    lin16 = srgb8_to_linear16()[cloud.colors]
    rgba[:, :3] = (lin16.astype(np.uint32) * 255 + 32767) // 65535   # linear, 8 bits
    rgba[:, 3] = np.round(cloud.density * 255)   # thin parts of the cloud fade more
    texture = scene.add_image(Image("gaussian sprite", gaussian_sprite_png()))
    material = scene.add_material(Material("cloud particle", texture=texture, alpha_mode="BLEND",
                                           double_sided=True, unlit=True, roughness=1.0))
    indices = (np.arange(n, dtype=np.uint32)[:, None, None] * 4 + _QUAD[None]).reshape(-1, 3)
    return Primitive({"POSITION": corners.reshape(-1, 3),
                      "TEXCOORD_0": np.broadcast_to(_UVS, (n, 4, 2)).reshape(-1, 2),
                      "COLOR_0": np.repeat(rgba, 4, axis=0)}, indices, material)


PREVIEW_PARTICLES = 100_000
"""Most particles a preview fills: a picture shows no more, a CPU rasterizer draws 10^5 soft discs in
about 2.5 s, and a 46-byte file of 2x10^7 particles took 6.6 GB and 42 s before this cap."""


def cube_file_scene(path: str | os.PathLike, *, seed: int = 0, most: int = PREVIEW_PARTICLES) -> Scene:
    """A cube file filled as `fishgen clouds` fills it, as points (what the preview draws).

    A file of more than ``most`` particles is filled with every cube's count
    scaled down alike (its shape and density pattern kept), and the scene's
    ``note`` says so.
    """
    from dataclasses import replace
    from pathlib import Path

    from fishgen.clouds import fill_cloud, load_cubes

    cubes = load_cubes(path)
    note = None
    if cubes.total > most:
        whole = cubes.total
        ratio = most / whole
        cubes = replace(cubes, cubes=tuple(replace(c, particles=max(1, int(c.particles * ratio)))
                                           for c in cubes.cubes))
        note = f"{path}: previewing {cubes.total:,} of its {whole:,} particles"
    scene = cloud_scene(fill_cloud(cubes, seed=seed), name=Path(path).stem)
    if note:
        scene.note = note
    return scene
