"""A minimal indexed triangle mesh with per-vertex normals and texture coordinates."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Mesh:
    positions: np.ndarray   # (n, 3) float64
    faces: np.ndarray       # (m, 3) int64, counter-clockwise seen from the front
    uvs: np.ndarray         # (n, 2) float64, glTF convention (v down from the image top)

    @property
    def normals(self) -> np.ndarray:
        return vertex_normals(self.positions, self.faces)

    def mirrored_z(self) -> Mesh:
        """Mirror in z, reversing the winding so the front stays the front."""
        pos = self.positions * np.array([1.0, 1.0, -1.0])
        return Mesh(pos, self.faces[:, ::-1].copy(), self.uvs)


def face_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Un-normalised face normals (length = twice the triangle area)."""
    tri = positions[faces]
    return np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])


def area_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Per vertex, the sum of its faces' normals, each as long as twice the face's area."""
    acc = np.zeros(positions.shape, dtype=np.float64)
    fn = face_normals(positions, faces)
    for corner in range(3):
        np.add.at(acc, faces[:, corner], fn)
    return acc


def vertex_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted average of adjacent face normals, as the thesis does (Figure 4.4)."""
    acc = area_normals(positions, faces)
    length = np.linalg.norm(acc, axis=1, keepdims=True)
    fallback = np.array([0.0, 1.0, 0.0])
    return np.where(length > 1e-300, acc / np.maximum(length, 1e-300), fallback)


def normal_deltas(positions: np.ndarray, faces: np.ndarray, displacements: np.ndarray) -> np.ndarray:
    """NORMAL deltas of morph targets that move ``positions`` by ``displacements`` (t, n, 3).

    A client poses normals as ``normalize(n0 + sum w_i delta_i)`` with ``n0`` the unit rest normal.
    Each delta is the change of the area-weighted normal sum scaled by the rest sum's length, so
    wherever that sum is linear in the displacement (every body vertex under fishgen's targets,
    see :mod:`fishgen.geometry.bend`) any blend of targets is shaded exactly as its own recomputed
    normals, not only the targets at full weight.
    """
    rest = area_normals(positions, faces)
    length = np.linalg.norm(rest, axis=1, keepdims=True)
    scale = np.where(length > 1e-300, 1.0 / np.maximum(length, 1e-300), 0.0)
    return np.stack([(area_normals(positions + d, faces) - rest) * scale for d in displacements])


def strip_faces(bottom: np.ndarray, top: np.ndarray) -> np.ndarray:
    """Triangles joining two index rows of equal length: quads (b0, b1, t1, t0) split in two."""
    b0, b1, t0, t1 = bottom[:-1], bottom[1:], top[:-1], top[1:]
    first = np.stack([b0, b1, t1], axis=1)
    second = np.stack([b0, t1, t0], axis=1)
    return np.concatenate([first, second])
