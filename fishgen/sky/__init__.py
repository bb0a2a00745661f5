"""Skies of many clouds (Pakawan's thin, medium and thick modes; report section 6.4 a-c).

    sky = build_sky("thick", seed=7)                 # the shipped cloud models, varied
    export(sky.scene, "sky.glb")                      # fishgen.exchange.export
    sky.particles, sky.distant_particles, sky.clouds  # what it holds, per cloud

The steps are pure functions over the clouds' arrays: :func:`plan_sky` (which model, scale, turn,
place and share of particles for each cloud), :func:`fill_sky` (the report's fill and seeded 3D
noise, each cloud in its own frame), :func:`light_sky` (one sun; clouds shadow clouds) and
:func:`sky_scene` (a node per cloud with its bounds, and a lower level of detail by ``MSFT_lod``).
The package imports nothing heavy until a name is used (``fishgen --help`` stays numpy-free).
"""
from __future__ import annotations

from fishgen.lazy import lazy_exports

_API = {
    "MODES": "fishgen.sky.modes", "SkyMode": "fishgen.sky.modes",
    "build_sky": "fishgen.sky.build", "Sky": "fishgen.sky.build", "load_models": "fishgen.sky.build",
    "shipped_models": "fishgen.sky.build",
    "plan_sky": "fishgen.sky.compose", "fill_sky": "fishgen.sky.compose", "SkyPlan": "fishgen.sky.compose",
    "Placement": "fishgen.sky.compose", "SkyCloud": "fishgen.sky.compose",
    "light_sky": "fishgen.sky.light", "sky_scene": "fishgen.sky.scene",
}
__getattr__, __all__ = lazy_exports(__name__, _API)
