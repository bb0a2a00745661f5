"""What the preview renderer draws: meshes and particle sets placed on nodes.

Readers (glTF, OBJ/PLY, species files, cube files) all produce a ``Scene``;
the renderer knows nothing about file formats.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fishgen.preview.animation import Animation, Node, pose


@dataclass
class Material:
    """The glTF metallic-roughness subset a preview needs; colours are linear RGBA."""

    base_color: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)
    texture: np.ndarray | None = None  # (H, W, 4) uint8, sRGB-encoded like glTF base colour
    alpha_mode: str = "OPAQUE"         # OPAQUE | MASK | BLEND
    alpha_cutoff: float = 0.5
    double_sided: bool = False
    unlit: bool = False


@dataclass
class MeshPart:
    """One triangle primitive on node ``node``; attributes are per vertex."""

    positions: np.ndarray               # (N, 3) float32
    indices: np.ndarray                 # (M, 3) uint32
    material: Material
    node: int | None = None             # None: identity transform
    normals: np.ndarray | None = None   # (N, 3) float32; computed when missing
    uvs: np.ndarray | None = None       # (N, 2) float32
    colors: np.ndarray | None = None    # (N, 4) float32 linear


@dataclass
class PointPart:
    """A particle set: each particle a soft disc of its radius, in world units."""

    positions: np.ndarray               # (N, 3) float32
    radii: np.ndarray                   # (N,) float32
    colors: np.ndarray                  # (N, 4) float32 linear RGBA
    node: int | None = None


@dataclass
class Scene:
    label: str = ""
    nodes: list[Node] = field(default_factory=list)
    meshes: list[MeshPart] = field(default_factory=list)
    points: list[PointPart] = field(default_factory=list)
    animations: list[Animation] = field(default_factory=list)

    def clip(self, name: str | None = None) -> Animation | None:
        """The named clip, else the first (fishgen fish carry one named ``swim``)."""
        for anim in self.animations:
            if name is None or anim.name == name:
                return anim
        return None

    def world_matrices(self, t: float | None, clip: str | None = None) -> list[np.ndarray]:
        """Node world matrices posed at ``t`` seconds (None: rest pose)."""
        return pose(self.nodes, None if t is None else self.clip(clip), t or 0.0)

    def counts(self) -> dict[str, int]:
        return {"vertices": sum(len(m.positions) for m in self.meshes),
                "triangles": sum(len(m.indices) for m in self.meshes),
                "particles": sum(len(p.positions) for p in self.points)}


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    """sRGB-encoded values in [0, 1] to linear light."""
    c = np.asarray(c, np.float32)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)


def vertex_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Area-weighted smooth normals, for assets that ship none."""
    tri = positions[indices]
    face = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normals = np.zeros_like(positions, dtype=np.float64)
    for k in range(3):
        np.add.at(normals, indices[:, k], face)
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    return (normals / np.where(length > 0, length, 1)).astype(np.float32)
