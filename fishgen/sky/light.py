"""One sun for a whole sky: every cloud lit, clouds shadowing clouds.

Two ways, both Harris's first pass (:func:`fishgen.clouds.light.incident_light`):

* ``"sky"``: every particle of the sky at once (``merge_clouds`` then ``light_cloud``). One deep
  shadow map spans the whole sky across the sun's rays, so its cells are the sky's width / 96:
  a cloud far smaller than the sky is resolved by a few cells and loses its own shading.
* ``"cloud"`` (the default): each cloud on its own map, with the particles of the other clouds
  that lie between it and the sun (those whose place across the rays falls on its footprint and
  that are nearer the sun than its farthest particle) as occluders. Each map spans one cloud and
  its shadow column, so each cloud is shaded as finely as `fishgen clouds` shades it alone, and
  the shadows other clouds cast still count.

Cost and difference, measured: ``docs/fly.md`` ("Lighting a sky").
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np

from fishgen.clouds.lighting import Lighting
from fishgen.clouds.sprite import SIGMA
from fishgen.sky.compose import SkyCloud

METHODS = ("cloud", "sky")
CUT = 3.0
"""A particle's shadow reaches CUT x its sprite's width across the rays (fishgen.clouds.light.CUT)."""


def light_sky(clouds: Sequence[SkyCloud], lighting: Lighting | None = None, method: str = "cloud",
              slabs: int | None = 16, grid: int | None = None,
              advance: Callable[[int], None] | None = None) -> list[SkyCloud]:
    """Each cloud lit by one sun, the others casting their shadows on it; ``advance(1)`` as each
    cloud's light is done (all at once with ``method="sky"``)."""
    from fishgen.clouds.light import incident_light, lit_colors

    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, not {method!r}")
    lighting = lighting or Lighting()
    if not clouds:
        return []
    world = [c.world_centers() for c in clouds]
    sizes = [len(c.cloud) for c in clouds]
    centers = np.concatenate(world)
    radii = np.concatenate([c.cloud.radii for c in clouds])
    density = np.concatenate([c.cloud.density for c in clouds])
    starts = np.concatenate([[0], np.cumsum(sizes)])
    if method == "sky":
        light = incident_light(centers.astype(np.float32), radii, density, lighting, grid_cells=grid)
        parts = [light[a:b] for a, b in zip(starts[:-1], starts[1:], strict=True)]
        if advance is not None:
            advance(len(parts))
    else:
        parts = _each_cloud(centers, radii, density, starts, lighting, slabs, advance)
    return [replace(c, cloud=replace(c.cloud, light=part, lighting=lighting,
                                     colors=lit_colors(part, lighting)))
            for c, part in zip(clouds, parts, strict=True)]


SKY_GRID = 96
"""Most cells along a side of one sky cloud's light grid (a cube file's own cap is 256: issue 32)."""


def _each_cloud(centers: np.ndarray, radii: np.ndarray, density: np.ndarray, starts: np.ndarray,
                lighting: Lighting, slabs: int | None,
                advance: Callable[[int], None] | None = None) -> list[np.ndarray]:
    from fishgen.clouds.light import depth_share, incident_light

    sun = np.array(lighting.sun_unit, np.float64)
    helper = np.zeros(3)
    helper[int(np.argmin(np.abs(sun)))] = 1.0
    a = np.cross(sun, helper)
    a /= np.linalg.norm(a)
    b = np.cross(sun, a)
    toward = centers @ sun                         # larger: nearer the sun
    across = np.stack([centers @ a, centers @ b], axis=1)
    reach = (CUT * SIGMA) * radii.astype(np.float64)
    count = len(starts) - 1
    # each cloud's footprint across the rays (its particles' shadows included) and its depth range
    spans = list(zip(starts[:-1], starts[1:], strict=True))
    lo = np.array([(across[s:e] - reach[s:e, None]).min(axis=0) for s, e in spans])
    hi = np.array([(across[s:e] + reach[s:e, None]).max(axis=0) for s, e in spans])
    far = np.array([toward[s:e].min() for s, e in spans])
    near = np.array([toward[s:e].max() for s, e in spans])

    def one(k: int) -> np.ndarray:
        s, e = int(starts[k]), int(starts[k + 1])
        # clouds whose footprint meets this one's and that reach nearer the sun than its far side
        meets = np.flatnonzero((lo[:, 0] <= hi[k, 0]) & (hi[:, 0] >= lo[k, 0]) & (lo[:, 1] <= hi[k, 1])
                               & (hi[:, 1] >= lo[k, 1]) & (near > far[k]))
        pieces = [np.arange(s, e)]
        for j in meets.tolist():
            if j == k:
                continue
            js, je = int(starts[j]), int(starts[j + 1])
            sel = np.arange(js, je)
            keep = ((toward[sel] > far[k]) & (across[sel, 0] + reach[sel] >= lo[k, 0])
                    & (across[sel, 0] - reach[sel] <= hi[k, 0]) & (across[sel, 1] + reach[sel] >= lo[k, 1])
                    & (across[sel, 1] - reach[sel] <= hi[k, 1]))
            pieces.append(sel[keep])
        index = np.concatenate(pieces)
        # A sky's cloud is one compact model (and its shadowing neighbours): 96 cells a side give it
        # the same light as 256 to within 0.02 RMS, at 45-60 % less time for the whole sky.
        # the cloud's own crowding sets the share of its optical depth each particle casts (its
        # occluders' too: they only shade it), so a cloud is lit alike with or without neighbours
        share = depth_share(centers[s:e], radii[s:e], density[s:e], lighting)
        light = incident_light(centers[index].astype(np.float32), radii[index], density[index], lighting,
                               slabs=slabs, grid_cells=SKY_GRID, share=share)
        return light[:e - s]

    import os
    from concurrent.futures import ThreadPoolExecutor

    parts = []
    with ThreadPoolExecutor(min(count, os.cpu_count() or 1)) as pool:
        for part in pool.map(one, range(count)):    # in order, each as soon as it and those before are
            parts.append(part)
            if advance is not None:
                advance(1)
    return parts
