"""Assets for the viewer tests: bonybream as glb and obj, table 4.3 as a cloud glb."""
from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def viewer_assets(tmp_path_factory):
    import fishgen
    from fishgen.clouds import export_cloud, fill_cloud, load_cubes
    from tests.conftest import PARAMS

    folder = tmp_path_factory.mktemp("viewer")
    fish = fishgen.build_fish(fishgen.load_species(PARAMS / "bonybream.txt"))
    fishgen.export(fish, folder / "bream.glb")
    fishgen.export(fish, folder / "bream.obj")
    cloud = fill_cloud(load_cubes(PARAMS / "clouds" / "table_4_3.awn"), seed=0)
    export_cloud(cloud, folder / "cloud.glb")
    return {"fish": folder / "bream.glb", "obj": folder / "bream.obj", "cloud": folder / "cloud.glb",
            "particles": len(cloud)}
