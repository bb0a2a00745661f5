"""Package layering: geometry knows nothing of species files, species nothing of geometry, cube
files nothing of species files, and a lit cloud nothing of the writers.

Each check imports the modules in a fresh interpreter, so what other tests have
already imported cannot hide a dependency.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from tests.conftest import ROOT


def modules_loaded_by(modules: tuple[str, ...], then: str) -> list[str]:
    """fishgen modules loaded after importing ``modules`` and running ``then`` (which
    reaches imports done lazily inside functions)."""
    code = (f"import json, sys\nimport {', '.join(modules)}\n{then}\n"
            "print(json.dumps(sorted(m for m in sys.modules if m.startswith('fishgen'))))")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout)


@pytest.mark.parametrize("imports,then,forbidden", [
    (("fishgen.geometry", "fishgen.geometry.body", "fishgen.geometry.fins", "fishgen.geometry.mesh",
      "fishgen.geometry.shapes"),
     "fishgen.geometry.body.build_body(fishgen.geometry.shapes.profile_for('FishShapeSpline', (0.5, 0.3)),"
     " 8, 6, (1, 1, 1))", "fishgen.species"),
    (("fishgen.species.parser", "fishgen.species.model"),
     "fishgen.species.parser.load_species('params/bonybream.txt')", "fishgen.geometry"),
    (("fishgen.clouds.parser",), "fishgen.clouds.parser.load_cubes('params/clouds/sky.awa')",
     "fishgen.species"),
    (("fishgen.clouds", "fishgen.clouds.pipeline"),
     "fishgen.clouds.pipeline.cube_clouds(fishgen.clouds.pipeline.read_cube_files("
     "['params/clouds/sky.awa', 'params/clouds/table_4_3.awn']))", "fishgen.exchange"),
], ids=["geometry-without-species", "species-without-geometry", "cube-files-without-species",
        "lit-clouds-without-writers"])
def test_package_does_not_import_the_other(imports, then, forbidden):
    loaded = modules_loaded_by(imports, then)
    assert set(imports) <= set(loaded)          # the check ran the imports it names
    assert [m for m in loaded if m == forbidden or m.startswith(forbidden + ".")] == []
