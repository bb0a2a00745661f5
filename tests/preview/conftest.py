"""Preview fixtures: one asset of each format (the OpenGL check, `gl_available`, is in tests/conftest.py)."""
from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def assets(tmp_path_factory):
    """bonybream in every asset format fishgen writes, and table 4.3 as lit glb and ply clouds."""
    import fishgen
    from fishgen.clouds import export_cloud, fill_cloud, light_cloud, load_cubes
    from tests.conftest import PARAMS

    folder = tmp_path_factory.mktemp("assets")
    fish = fishgen.build_fish(fishgen.load_species(PARAMS / "bonybream.txt"))
    out = {}
    for ext in ("glb", "gltf", "obj", "ply"):
        out[f"fish.{ext}"] = folder / f"fish.{ext}"
        fishgen.export(fish, out[f"fish.{ext}"])
    # as `clouds` does
    cloud = light_cloud(fill_cloud(load_cubes(PARAMS / "clouds" / "table_4_3.awn"), seed=0))
    for ext in ("glb", "ply"):
        out[f"cloud.{ext}"] = folder / f"cloud.{ext}"
        export_cloud(cloud, out[f"cloud.{ext}"])
    out["cloud_len"] = len(cloud)
    return out
