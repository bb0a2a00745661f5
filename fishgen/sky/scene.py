"""A lit sky as a scene: one node per cloud, with its bounds and its lower level of detail.

Each cloud is a root node ``cloud_007`` carrying the cloud's place and turn (translation, rotation
about +Y) and, in its extras, its bounds in its own frame (``fishgen_cloud``: the box and the
bounding sphere of its particles, radii included), so an engine culls it as one object. Its
particles are the child node ``cloud_007_LOD0``. It also has lower levels, ``cloud_007_LOD1`` and
``_LOD2`` (``coarsen``: one particle in 8, in 64, larger; each only if it keeps at least
``LOD_MIN_PARTICLES``), tied to LOD0 by the ``MSFT_lod`` node extension, with the switches in
``extras.MSFT_screencoverage`` (``LOD_LEVELS``):

* a client that knows ``MSFT_lod`` (Babylon.js, UnityGLTF: a ``LODGroup``) shows level k when the
  cloud spans less than its coverage of the view's height, and nothing below 0;
* a client that does not (three.js's stock loader, Blender) shows LOD0 only: the lower levels'
  nodes stand in the second glTF scene, as a fish's do (``LEVELS_IN_A_SCENE``), so nothing is
  drawn twice;
* the names follow Unity's ``_LOD0``/``_LOD1``/``_LOD2`` convention, for pipelines that key on names.

The scene's extras hold the lighting (``fishgen_light``, as `fishgen clouds` writes it) and the
sky's plan (``fishgen_sky``).
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from fishgen.clouds.lighting import EXTRAS_KEY
from fishgen.clouds.model import Cloud
from fishgen.scene.model import Mesh, Node, Scene
from fishgen.sky.compose import SkyCloud, SkyPlan
from fishgen.sky.modes import LOD_LEVELS, LOD_MIN_PARTICLES

CLOUD_KEY = "fishgen_cloud"
LEVELS_IN_A_SCENE = True
"""Whether a cloud's lower levels stand in the second glTF scene, as a fish's do, rather than in no
scene (orphans: the validator's ``UNUSED_OBJECT`` info). A client must not look nodes up in
three.js's ``parser.associations``, which GLTFLoader (0.187) empties of nodes when a file has a
second scene: fishgen fly's page asks ``parser.getDependency`` (its ``addAsset``)."""
SKY_KEY = "fishgen_sky"


def bounds(cloud: Cloud) -> tuple[list[float], list[float], list[float]]:
    """The box (min, max corners) and bounding sphere (x, y, z, radius) of a cloud's particles,
    each particle's radius included, in the cloud's own frame."""
    c = np.asarray(cloud.centers, np.float64)
    r = np.asarray(cloud.radii, np.float64)[:, None]
    lo, hi = (c - r).min(axis=0), (c + r).max(axis=0)
    middle = (lo + hi) / 2
    reach = float(np.max(np.linalg.norm(c - middle, axis=1) + r[:, 0]))
    return [float(v) for v in lo], [float(v) for v in hi], [*(float(v) for v in middle), reach]


def levels(cloud: Cloud) -> list[Cloud]:
    """The cloud's lower levels of detail (``LOD_LEVELS``), each merged from the one before (fewer
    particles to sort); a level that would keep fewer than ``LOD_MIN_PARTICLES`` is not made."""
    from fishgen.clouds.lod import coarsen

    out, low, done = [], cloud, 1.0
    for ratio, _ in LOD_LEVELS:
        if len(cloud) / ratio < LOD_MIN_PARTICLES:
            break
        low = coarsen(low, ratio / done)
        done = ratio
        out.append(low)
    return out


def sky_scene(plan: SkyPlan | None, clouds: Sequence[SkyCloud], sources: Sequence[str], *,
              billboards: bool = False, lod: bool = True,
              advance: Callable[[int], None] | None = None) -> tuple[Scene, list[dict[str, Any]]]:
    """The scene, and per cloud what it holds (name, source, particles at each level); ``advance(1)``
    after each cloud's levels.

    ``plan``: the sky's, recorded in the scene's extras (None: clouds placed otherwise, no record).
    ``billboards``: particle clouds as crossed-quad billboards (a texture cloud always is).
    ``lod``: lower levels for clouds of at least LOD_MIN_PARTICLES.
    """
    from fishgen.clouds.scene import cloud_primitives

    scene = Scene(name="sky")
    lit = [c.cloud.lighting for c in clouds if c.cloud.lighting is not None]
    if lit:
        scene.extras[EXTRAS_KEY] = lit[0].extras()
    facts: list[dict[str, Any]] = []
    for sky_cloud in clouds:
        p, cloud = sky_cloud.placement, sky_cloud.cloud
        quads = billboards or bool(cloud.textures)
        lo, hi, sphere = bounds(cloud)
        fact: dict[str, Any] = {"name": p.name, "source": sources[p.source], "particles": len(cloud),
                                **{f"lod{k}": 0 for k in range(1, len(LOD_LEVELS) + 1)}, "billboards": quads}
        place = {"source": sources[p.source], "particles": len(cloud), "scale": list(p.scale),
                 "bounds": {"min": lo, "max": hi}, "sphere": sphere}
        root = scene.add_node(Node(name=p.name, translation=p.position, rotation=p.rotation,
                                   extras={CLOUD_KEY: place}))
        detail = scene.add_mesh(Mesh(f"{p.name}_LOD0", cloud_primitives(cloud, scene, billboards=quads)))
        lod0 = scene.add_node(Node(name=f"{p.name}_LOD0", mesh=detail), parent=root)
        if lod:
            ids, coverage = [], []
            for k, ((_, cover), low) in enumerate(zip(LOD_LEVELS, levels(cloud), strict=False), start=1):
                prims = cloud_primitives(low, scene, billboards=quads)
                mesh = scene.add_mesh(Mesh(f"{p.name}_LOD{k}", prims))
                ids.append(scene.add_node(Node(name=f"{p.name}_LOD{k}", mesh=mesh), root=False))
                coverage.append(cover)
                fact[f"lod{k}"] = len(low)
            scene.add_levels(lod0, ids, [*coverage, 0.0], hidden=LEVELS_IN_A_SCENE)
        facts.append(fact)
        if advance is not None:
            advance(1)
    if plan is None:
        return scene, facts
    scene.extras[SKY_KEY] = {"mode": plan.mode.name, "seed": plan.seed, "area": list(plan.area),
                             "altitude": list(plan.altitude), "clouds": len(clouds),
                             "particles": sum(len(c.cloud) for c in clouds),
                             "lod": [{"ratio": r, "coverage": c} for r, c in LOD_LEVELS] if lod else None}
    return scene, facts
