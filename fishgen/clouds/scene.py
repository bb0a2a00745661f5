"""A filled cloud as a scene: one POINTS primitive, or billboard quads with a Gaussian sprite.

Points carry POSITION, COLOR_0 (linear, 16-bit so the sRGB bytes of PLY and
CSV come back exactly), ``_RADIUS``, ``_DENSITY``, ``_CUBE`` (the cube each
particle was filled in; float32, as glTF allows no 32-bit integer attributes, exact
below 2^24 and the parser allows 100,000 cubes) and, when lit, ``_LIGHT`` (the sunlight
reaching it; the sun is in the scene's extras). Billboards, for engines that cannot size
points, are three crossed quads per particle (6 triangles), one across each axis, sized
by the particle radius, with vertex alpha from its density and an unlit, alpha-blended
Gaussian sprite: a disc from the front, the side and above alike.
"""
from __future__ import annotations

import os

import numpy as np

from fishgen.clouds.lighting import EXTRAS_KEY, Lighting
from fishgen.clouds.model import Cloud
from fishgen.clouds.pipeline import PREVIEW_PARTICLES
from fishgen.clouds.sprite import gaussian_sprite_png
from fishgen.numeric import srgb8_to_linear16
from fishgen.scene.model import Image, Material, Mesh, Node, Primitive, Scene

PLANES = np.array([[[1, 0, 0], [0, 1, 0]],      # facing +Z
                   [[0, 0, -1], [0, 1, 0]],     # facing +X
                   [[1, 0, 0], [0, 0, -1]]],    # facing +Y
                  np.float32)
"""A billboard particle is three crossed quads, one across each axis of its own frame (the
rows: each quad's right and up directions), so it shows about a full disc from any side.
Each particle's frame is turned (``turns``), so no view sees every quad edge-on at once."""
_R3 = np.array([0.8191725133961645, 0.6710436067037893, 0.5497004779019703])
"""Martin Roberts' R3 sequence (2018): fractional parts of k times these are evenly spread in
the unit cube, so particle k's turn needs no random generator and no seed."""
QUADS = len(PLANES)
BILLBOARD_OPACITY = 0.5
"""Each quad's opacity at its centre, times the particle's density. Half a single billboard's:
from any side one to three of a particle's quads overlap, and a quad seen almost edge-on (a
thin needle) shows half as strongly."""
TRIANGLES_PER_BILLBOARD = 2 * QUADS
BILLBOARD_BYTES = QUADS * (4 * (12 + 8 + 4 + 4) + 6 * 4)
"""glTF bytes per billboard particle: per quad 4 corners of position, UV, RGBA8 and light,
and 6 uint32 indices."""
POINT_BYTES = 12 + 8 + 4 + 4 + 4 + 4
"""glTF bytes per point particle: position, RGB16 colour (8-byte stride), radius, density, cube, light."""

_CORNERS = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], np.float32)
_UVS = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
_QUAD = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)


def cloud_scene(cloud: Cloud, *, billboards: bool = False, name: str = "cloud") -> Scene:
    scene = Scene(name=name)
    if cloud.lighting is not None:
        scene.extras[EXTRAS_KEY] = cloud.lighting.extras()
    mesh = scene.add_mesh(Mesh(name, cloud_primitives(cloud, scene, billboards=billboards)))
    scene.add_node(Node(name=name, mesh=mesh))
    return scene


def cloud_primitives(cloud: Cloud, scene: Scene, *, billboards: bool = False) -> list[Primitive]:
    """The primitives of ``cloud``: one POINTS primitive, or its billboards, whose materials and
    images are added to ``scene`` (once each: several clouds of one scene share them)."""
    return _billboards(cloud, scene) if billboards else [_points(cloud)]


def _points(cloud: Cloud) -> Primitive:
    rgb = srgb8_to_linear16()[cloud.colors]
    attributes = {"POSITION": cloud.centers, "COLOR_0": rgb, "_RADIUS": cloud.radii,
                  "_DENSITY": cloud.density, "_CUBE": cloud.cube_index.astype(np.float32)}
    if cloud.light is not None:
        attributes["_LIGHT"] = cloud.light
    return Primitive(attributes, mode="POINTS")


def _billboards(cloud: Cloud, scene: Scene) -> list[Primitive]:
    """One primitive per texture: a texture cloud's billboards carry their cube's PNG, the
    others fishgen's Gaussian sprite."""
    if not cloud.textures:
        return [_billboard_primitive(cloud, np.arange(len(cloud)), _sprite_material(scene))]
    out = []
    for texture in dict.fromkeys(cloud.textures):     # in cube order, each once
        cubes = [k for k, t in enumerate(cloud.textures) if t == texture]
        members = np.flatnonzero(np.isin(cloud.cube_index, cubes))
        if not len(members):
            continue
        material = _sprite_material(scene) if texture is None else _texture_material(scene, texture)
        out.append(_billboard_primitive(cloud, members, material))
    return out


def _sprite_material(scene: Scene) -> int:
    for k, m in enumerate(scene.materials):
        if m.name == "cloud particle":
            return k
    texture = scene.add_image(Image("gaussian sprite", gaussian_sprite_png()))
    return scene.add_material(Material("cloud particle", texture=texture, alpha_mode="BLEND",
                                       double_sided=True, unlit=True, roughness=1.0))


def _texture_material(scene: Scene, path: str) -> int:
    """An unlit, alpha-blended material showing the picture at ``path``."""
    from pathlib import Path

    name = Path(path).name
    image = texture_image(Path(path))
    for k, m in enumerate(scene.materials):  # another cloud of the scene carries it already
        if m.name == f"cloud texture {name}" and m.texture is not None \
                and scene.images[m.texture].encoded() == image.encoded():
            return k
    texture = scene.add_image(image)
    return scene.add_material(Material(f"cloud texture {name}", texture=texture, alpha_mode="BLEND",
                                       double_sided=True, unlit=True, roughness=1.0))


def texture_image(path) -> Image:
    """A texture cloud's picture as glTF takes it: a PNG or JPEG as it is (by its bytes, whatever
    its name: a JPEG named .png was declared image/png, which glTF validators refuse), anything
    else the cube file allows (a GIF, a BMP) decoded and written as PNG."""
    data = path.read_bytes()
    if data.startswith(b"\x89PNG\r\n\x1a\n"):
        return Image(path.name, data)
    if data.startswith(b"\xff\xd8\xff"):
        return Image(path.name, data, "image/jpeg")
    return Image(path.name, b"", pixels=Image(path.name, data).rgba())


def _billboard_primitive(cloud: Cloud, members: np.ndarray, material: int) -> Primitive:
    """Three crossed quads per particle (``PLANES``), half width = radius, vertex alpha = density."""
    n = len(members)
    offsets = np.einsum("ck,qkd->qcd", _CORNERS, PLANES)                 # (quads, 4 corners, 3)
    turned = np.einsum("qcd,nde->nqce", offsets, turns(len(cloud))[members])   # (n, quads, 4, 3)
    corners = cloud.centers[members, None, None, :] + turned * cloud.radii[members, None, None, None]
    rgba = np.empty((n, 4), np.uint8)
    lin16 = srgb8_to_linear16()[cloud.colors[members]]
    rgba[:, :3] = (lin16.astype(np.uint32) * 255 + 32767) // 65535   # linear, 8 bits
    rgba[:, 3] = np.round(cloud.density[members] * (255 * BILLBOARD_OPACITY))  # thin parts fade more
    per = 4 * QUADS                                                       # vertices per particle
    quad_starts = np.arange(n * QUADS, dtype=np.uint32)[:, None, None] * 4
    indices = (quad_starts + _QUAD[None]).reshape(-1, 3)
    attributes = {"POSITION": corners.reshape(-1, 3).astype(np.float32),
                  "TEXCOORD_0": np.broadcast_to(_UVS, (n * QUADS, 4, 2)).reshape(-1, 2),
                  "COLOR_0": np.repeat(rgba, per, axis=0)}
    if cloud.light is not None:
        attributes["_LIGHT"] = np.repeat(cloud.light[members], per)
    return Primitive(attributes, indices, material)


def turns(n: int) -> np.ndarray:
    """(n, 3, 3) float32 rotations (row vectors: ``v @ R``), evenly spread: Shoemake's uniform
    random rotation of the R3 sequence's points k = 1..n."""
    u = np.modf(np.arange(1, n + 1, dtype=np.float64)[:, None] * _R3[None, :] + 0.5)[0]
    a, b = np.sqrt(1 - u[:, 0]), np.sqrt(u[:, 0])
    t1, t2 = 2 * np.pi * u[:, 1], 2 * np.pi * u[:, 2]
    x, y, z, w = a * np.sin(t1), a * np.cos(t1), b * np.sin(t2), b * np.cos(t2)
    rot = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),
                    2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                    2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y)], axis=1)
    return rot.reshape(n, 3, 3).astype(np.float32)


def cube_file_scene(path: str | os.PathLike, *, seed: int = 0, most: int = PREVIEW_PARTICLES,
                    lighting: Lighting | None = None, textures_dir: str | os.PathLike | None = None) -> Scene:
    """A cube file (.awn) or texture cloud file (.awa) filled and lit as `fishgen clouds` does it,
    as points or textured billboards (what the preview and the viewer draw).

    A file of more than ``most`` particles is filled with every cube's count scaled
    down alike (its shape and density pattern kept), and the scene's ``note`` says so.
    """
    from pathlib import Path

    from fishgen.clouds.pipeline import cube_clouds, read_cube_files

    made = cube_clouds(read_cube_files([path], textures_dir=textures_dir), seed=seed, most=most,
                       lighting=lighting)
    # a texture cloud is its textured billboards; a particle cloud is points, drawn as soft discs
    scene = cloud_scene(made.cloud, name=Path(path).stem, billboards=made.textured)
    if made.note:
        scene.note = f"{path}: {made.note}"
    return scene
