"""fishgen: procedural fish and cloud assets (VRFish species files, RekAwan cube files).

The public API is imported lazily so that ``import fishgen`` (and the CLI's
``--help``) does not pay for numpy and trimesh.
"""
from __future__ import annotations

from fishgen.lazy import lazy_exports

__version__ = "0.2.19"

_API = {
    "load_species": "fishgen.species.parser",
    "Species": "fishgen.species.model",
    "build_fish": "fishgen.assembly.fish",
    "Scene": "fishgen.scene.model",
    "export": "fishgen.exchange",
    "FishgenError": "fishgen.errors",
    "load_cubes": "fishgen.clouds",
    "fill_cloud": "fishgen.clouds",
    "merge_clouds": "fishgen.clouds",
    "export_cloud": "fishgen.clouds",
}

__getattr__, __all__ = lazy_exports(__name__, _API)
