"""Fish schools: simulate (VRFish's brain or the particle swarm), measure, and bake into one scene.

    from fishgen.school import SchoolRun, run_school
    from fishgen.school.scene_file import SceneFile, SpeciesEntry
    run = run_school(SceneFile(species=(SpeciesEntry(Path("params/bonybream.txt"), 200),)))
    fishgen.export(run.scene, "school.glb", require=["node animation"])

The package itself imports nothing heavy (numpy stays out of ``fishgen --help``); its public
names load their modules when first used.
"""
from __future__ import annotations

from fishgen.lazy import lazy_exports

_API = {"SchoolRun": "fishgen.school.run", "run_school": "fishgen.school.run",
        "brain_of": "fishgen.school.run", "DEFAULT_BOUNDS_BODY_LENGTHS": "fishgen.school.run"}
__getattr__, __all__ = lazy_exports(__name__, _API)
