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


def vertex_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted average of adjacent face normals, as the thesis does (Figure 4.4)."""
    acc = np.zeros_like(positions, dtype=np.float64)
    fn = face_normals(positions, faces)
    for corner in range(3):
        np.add.at(acc, faces[:, corner], fn)
    length = np.linalg.norm(acc, axis=1, keepdims=True)
    fallback = np.array([0.0, 1.0, 0.0])
    return np.where(length > 1e-300, acc / np.maximum(length, 1e-300), fallback)


def strip_faces(bottom: np.ndarray, top: np.ndarray) -> np.ndarray:
    """Triangles joining two index rows of equal length: quads (b0, b1, t1, t0) split in two."""
    b0, b1, t0, t1 = bottom[:-1], bottom[1:], top[:-1], top[1:]
    first = np.stack([b0, b1, t1], axis=1)
    second = np.stack([b0, t1, t0], axis=1)
    return np.concatenate([first, second])
