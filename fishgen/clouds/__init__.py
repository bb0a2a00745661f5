"""Cloud cube files (.awn) to particle clouds: parse, fill (report section 4.5), export.

    cubes = load_cubes("params/clouds/table_4_3.awn")
    cloud = fill_cloud(cubes, seed=7, method="paper", offset=(0, 0, 0))
    export_cloud(cloud, "cloud.glb", billboards=True)

Several files make one scene with ``merge_clouds([fill_cloud(a, offset=...), ...])``.
"""
from fishgen.clouds.export import FORMATS, check_output, export_cloud
from fishgen.clouds.fill import METHODS, fill_cloud, merge_clouds
from fishgen.clouds.model import DEFAULT_MAX_PARTICLES, Cloud, Cube, CubeFile
from fishgen.clouds.parser import CubeFileWarning, load_cubes, parse_cubes

__all__ = ["Cloud", "Cube", "CubeFile", "CubeFileWarning", "DEFAULT_MAX_PARTICLES", "FORMATS",
           "METHODS", "check_output", "export_cloud", "fill_cloud", "load_cubes", "merge_clouds",
           "parse_cubes"]
