"""Billboards hold from every side in three.js (headless Chromium, stock GLTFLoader).

The billboard glb is drawn from the front, the side and above, beside the same particles as
opaque spheres of 0.7 x their radius. A pixel counts as covered at 10 % opacity or more; the
billboards must cover at least 70 % of the spheres' share of the frame from each side (the
+Z quads before issue 20 covered 35 % from the side and 26 % from above), and their mean
opacity must reach 70 % of the spheres' too.
"""
from __future__ import annotations

import pytest
from browser import ThreePage, image, unavailable
from cloud_tables import TABLES

from fishgen.clouds import export_cloud, fill_cloud, light_cloud, load_cubes

pytestmark = pytest.mark.skipif(unavailable() is not None, reason=str(unavailable()))
SIDES = ("front", "side", "above")


@pytest.fixture(scope="module")
def three(tmp_path_factory):
    folder = tmp_path_factory.mktemp("three")
    page = ThreePage(folder)
    yield page
    page.close()


@pytest.mark.parametrize("table", ["4.3", "4.4"])
def test_billboards_cover_what_the_particles_cover_from_every_side(three, table, gltf_validator):
    cloud = light_cloud(fill_cloud(load_cubes(TABLES[table]), seed=0))
    export_cloud(cloud, three.assets / f"billboards_{table}.glb", billboards=True)
    export_cloud(cloud, three.assets / f"points_{table}.glb")
    gltf_validator(three.assets / f"billboards_{table}.glb")
    result = three.coverage(three.assets / f"billboards_{table}.glb", three.assets / f"points_{table}.glb",
                            SIDES, pixels=True)
    assert not three.errors, three.errors
    (material,) = result["materials"]   # as three.js made it from the file: blended, vertex colours
    assert (material["transparent"] and not material["depthWrite"] and material["vertexColors"]
            and material["map"])
    for side in SIDES:
        billboards, spheres = result[side]["billboards"], result[side]["spheres"]
        assert billboards["pixels"] >= 0.7 * spheres["pixels"], side
        assert billboards["alpha"] >= 0.7 * spheres["alpha"], side
        shown = image(result[side])
        assert shown[..., :3].std() > 5, f"{side}: nothing but background"
