"""Cloud cube files (.awn) to particle clouds: parse, fill (report section 4.5), export.

    cubes = load_cubes("params/clouds/table_4_3.awn")
    cloud = fill_cloud(cubes, seed=7, method="paper", offset=(0, 0, 0))
    cloud = light_cloud(cloud, Lighting(sun=(1, 0.3, 0)))     # Harris's first pass, baked
    export_cloud(cloud, "cloud.glb", billboards=True)
    export_cloud(cloud, "cloud.vdb", voxel_size=0.1)               # density and light grids

Several files make one scene with ``merge_clouds([fill_cloud(a, offset=...), ...])``, lit after
merging so the clouds shadow each other.
The package itself imports nothing heavy (numpy stays out of ``fishgen --help``); its public
names load their modules when first used.
"""
from __future__ import annotations

from fishgen.lazy import lazy_exports

_API = {
    "FORMATS": "fishgen.exchange.clouds", "check_output": "fishgen.exchange.clouds",
    "export_cloud": "fishgen.exchange.clouds",
    "METHODS": "fishgen.clouds.model", "fill_cloud": "fishgen.clouds.fill",
    "merge_clouds": "fishgen.clouds.fill",
    "DEFAULT_MAX_PARTICLES": "fishgen.clouds.model", "Cloud": "fishgen.clouds.model",
    "Cube": "fishgen.clouds.model", "CubeFile": "fishgen.clouds.model",
    "CubeFileWarning": "fishgen.clouds.parser", "load_cubes": "fishgen.clouds.parser",
    "parse_cubes": "fishgen.clouds.parser",
    "Lighting": "fishgen.clouds.lighting",
    "incident_light": "fishgen.clouds.light", "light_cloud": "fishgen.clouds.light",
    "lit_colors": "fishgen.clouds.light",
    "Volume": "fishgen.clouds.volume", "particle_volume": "fishgen.clouds.volume",
}
__getattr__, __all__ = lazy_exports(__name__, _API)
