"""The rest pose of a scene's triangle meshes in world space, for formats without a node tree."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fishgen.geometry.mesh import vertex_normals
from fishgen.scene.model import Scene
from fishgen.scene.pose import deformed, pose


@dataclass
class RestMesh:
    name: str
    positions: np.ndarray   # (n, 3) float64, world space
    normals: np.ndarray     # (n, 3)
    uvs: np.ndarray | None  # (n, 2), glTF convention (v down)
    faces: np.ndarray       # (m, 3)
    material: int | None


def rest_meshes(scene: Scene) -> list[RestMesh]:
    """Every drawn triangle primitive posed at rest, named after its node."""
    posed = pose(scene)
    out = []
    for node, prim in scene.drawn():
        if prim.mode != "TRIANGLES" or prim.indices is None:
            continue
        positions, normals = deformed(scene, node, prim, posed)
        faces = np.asarray(prim.indices, np.int64)
        if normals is None:
            normals = vertex_normals(positions, faces)
        uvs = prim.attributes.get("TEXCOORD_0")
        out.append(RestMesh(scene.nodes[node].name or f"node{node}", positions, normals,
                            None if uvs is None else np.asarray(uvs, np.float64), faces, prim.material))
    return out
