"""Fuzz targets: how case ``index`` of a target is generated from ``(seed, target, index)`` and run.

What a case holds is :mod:`fishgen.fuzz.inputs`; how its outcome is judged, :mod:`fishgen.fuzz.verdict`;
the command-line cases run through :mod:`fishgen.fuzz.cli_run`, issue 26's through
:mod:`fishgen.fuzz.new_cases`.
"""
from __future__ import annotations

import warnings
from pathlib import Path

from fishgen.fuzz import mutate
from fishgen.fuzz.cli_run import run_cli
from fishgen.fuzz.inputs import Case, Seeds, case_rng, fresh_folder, write_files
from fishgen.fuzz.verdict import CaseTimeout, Outcome, classify, formatted, innermost_fishgen_frame

TARGETS = ("species", "cubes", "gltf", "obj", "ply", "cli",
           "scene", "paths", "manifest", "fxl", "photo", "awa", "editor", "options")
READERS = ("gltf", "obj", "ply")
#: Issue 26's targets (the newer commands' inputs).
NEW_TARGETS = ("scene", "paths", "manifest", "fxl", "photo", "awa", "editor", "options")


def make_case(seeds: Seeds, target: str, seed: int, index: int) -> Case:
    """Case ``index`` of ``target``: the first ones replay the seed corpus verbatim, then mutants."""
    rng = case_rng(seed, target, index)
    verbatim = index < seeds.count(target)
    if target == "species":
        text = seeds.species[index] if verbatim else mutate.species_text(seeds.species, rng)
        return Case(target, index, text=text)
    if target == "cubes":
        data = seeds.cubes[index] if verbatim else mutate.cubes_bytes(seeds.cubes, rng)
        return Case(target, index, data=data)
    if target in READERS:
        main, files = seeds.assets[target][index if verbatim else rng.randrange(len(seeds.assets[target]))]
        if not verbatim:
            fn = {"gltf": mutate.mutate_gltf, "obj": mutate.mutate_obj, "ply": mutate.mutate_ply}[target]
            files = fn(files, main, rng)
        return Case(target, index, files=files, main=main)
    if target == "cli":
        from fishgen.fuzz.cli_gen import cli_case
        files, argv = cli_case(seeds, rng)
        return Case(target, index, files=files, argv=argv)
    if target in NEW_TARGETS:
        from fishgen.fuzz.new_cases import make_new_case
        return make_new_case(seeds, target, rng, index, verbatim)
    raise ValueError(f"unknown target {target!r}")


def run_case(case: Case, workdir: Path) -> Outcome:
    """Run one case in this process (the worker); never raises except CaseTimeout/KeyboardInterrupt."""
    try:
        if case.target == "species":
            from fishgen.species.parser import parse_species
            parse_species(case.text or "", "<fuzz>")
            return Outcome("ok")
        if case.target == "cubes":
            return _run_cubes(case)
        if case.target in READERS:
            return _run_reader(case, workdir)
        if case.target in NEW_TARGETS and case.target not in ("photo", "options"):
            from fishgen.fuzz.new_cases import run_new_case
            return run_new_case(case, workdir)
        return run_cli(case, workdir)
    except CaseTimeout as err:
        return Outcome("finding", f"budget overrun (time) in {case.target} at "
                                  f"{innermost_fishgen_frame(err.__traceback__)}", formatted(err))
    except Exception as err:  # the point of the harness: judge whatever came out
        return classify(err)


def _run_cubes(case: Case) -> Outcome:
    from fishgen.clouds.parser import parse_cubes
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cubes = parse_cubes(case.data or b"", "<fuzz>", max_particles=10_000_000)
    if cubes.total <= 2000:  # a small valid file is also filled: its particles must be finite
        import numpy as np

        from fishgen.clouds.fill import fill_cloud
        cloud = fill_cloud(cubes, seed=case.index, method="paper" if case.index % 2 else "uniform")
        for name in ("centers", "radii", "density"):
            values = getattr(cloud, name, None)
            if values is not None and not np.isfinite(np.asarray(values, float)).all():
                return Outcome("finding", f"non-finite cloud {name} from fill_cloud", "")
    return Outcome("ok")


def _run_reader(case: Case, workdir: Path) -> Outcome:
    from fishgen.preview.inputs import load_input
    from fishgen.scene.pose import bounds

    folder = fresh_folder(workdir)
    write_files(folder, case.files)
    scene = load_input(folder / case.main)
    # What every consumer does next (preview frames the subject, the viewer poses it): a reader
    # that accepts a file must hand over a scene that can be posed, at rest and mid-clip.
    import numpy as np

    boxes = [bounds(scene)]
    clip = scene.clips[0] if scene.clips else None
    if clip is not None:
        boxes.append(bounds(scene, t=clip.duration / 2, clip=clip))
    if not all(np.isfinite(np.asarray(b, float)).all() for b in boxes):
        return Outcome("finding", f"{case.target} reader accepted an asset whose posed bounds are not finite",
                       "")
    return Outcome("ok")
