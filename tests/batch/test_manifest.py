"""Manifests: typed jobs, every option as the commands take it, one-line FILE:LINE errors."""
from __future__ import annotations

import pytest

from fishgen.batch import manifest
from fishgen.batch.manifest import derived_seed
from fishgen.commands.batch import job_kinds
from fishgen.commands.build import BuildOptions
from fishgen.errors import FishgenError
from tests.conftest import PARAMS


def load_manifest(path, out=None):
    """A manifest as `fishgen batch` reads it: of the commands' jobs."""
    return manifest.load_manifest(path, out, kinds=job_kinds())


def scan_folder(folder, out):
    return manifest.scan_folder(folder, out, kinds=job_kinds())


def write(tmp_path, text: str):
    path = tmp_path / "m.toml"
    path.write_text(text)
    return path


def test_the_example_manifest_builds_every_shipped_species_a_school_and_the_three_clouds():
    manifest = load_manifest(PARAMS / "assets.toml")
    kinds = [job.kind for job in manifest.jobs]
    assert kinds.count("school") == 1 and kinds.count("clouds") == 4  # the report's three, and a texture sky
    built = {job.inputs[0].name for job in manifest.jobs if job.kind == "build"}
    assert built == {p.name for p in PARAMS.glob("*.txt")}
    assert {job.inputs[0].name for job in manifest.jobs if job.kind == "clouds"} == {
        p.name for p in (PARAMS / "clouds").glob("*.aw[na]")}
    assert manifest.out == (PARAMS.parent / "out" / "assets").resolve()


def test_options_are_filled_with_the_commands_defaults_and_seeds_come_from_the_output_name(tmp_path):
    manifest = load_manifest(write(tmp_path, """
[[build]]
input = "a.txt"
output = "a.glb"
[[clouds]]
inputs = ["c.awn", "d.awn"]
output = "sky/c.ply"
offset = [[0, 0, 0], [1, 2, 3]]
[[clouds]]
input = "c.awn"
output = "seeded.ply"
seed = 5
"""), out=tmp_path / "o")
    build, clouds, seeded = manifest.jobs
    assert build.options == BuildOptions()  # the command's own defaults, every one
    assert build.output == tmp_path / "o" / "a.glb" and build.inputs == (tmp_path / "a.txt",)
    assert clouds.options.seed == derived_seed("sky/c.ply") and clouds.options.method == "paper"
    assert clouds.options.offset == ((0, 0, 0), (1, 2, 3))
    assert clouds.where == f"{tmp_path / 'm.toml'}:7"
    assert seeded.options.seed == 5
    assert derived_seed("a.ply") != derived_seed("b.ply")


def test_a_school_scene_file_keeps_its_own_seed_and_species_files_get_one_from_the_job(tmp_path):
    manifest = load_manifest(write(tmp_path, """
[[school]]
input = "reef.toml"
output = "reef.glb"
[[school]]
inputs = ["a.txt", "b.txt"]
output = "ab.glb"
"""))
    assert manifest.jobs[0].options.seed is None  # the scene file's, as `fishgen school` does
    assert manifest.jobs[1].options.seed == derived_seed("ab.glb")


def test_a_school_job_takes_a_layout(tmp_path):
    manifest = load_manifest(write(tmp_path, """
[[school]]
input = "a.txt"
output = "ring.glb"
layout = "ring"
[[school]]
input = "a.txt"
output = "torus.glb"
preset = "torus"
"""))
    assert manifest.jobs[0].options.layout == "ring"
    assert manifest.jobs[1].options.layout is None  # the scene file's, else the preset's: a ring


@pytest.mark.parametrize("text,line,message", [
    ('[[build]]\ninput = "a.txt"\noutput = "a.glb"\nfins = "sparkly"\n', 4,
     "expected fins as one of blend, mask, opaque, found 'sparkly'"),
    ('[[build]]\ninput = "a.txt"\noutput = "a.glb"\nlength = -1\n', 4,
     "expected length as a number from 0.001 to 10000, found '-1'"),
    ('[[build]]\ninput = "a.txt"\noutput = "a.glb"\ncolour = 1\n', 4, "found 'colour'"),
    ('[[build]]\ninput = "a.txt"\noutput = "a.ply.txt"\n', 3, "expected an output ending in"),
    ('[[school]]\ninput = "a.txt"\noutput = "a.obj"\n', 3, "holds node animation"),
    ('[[build]]\ninput = "a.txt"\noutput = "../a.glb"\n', 3, "inside the out folder"),
    ('[[build]]\ninput = "a.txt"\n', 1, "expected output as a file name"),
    ('[[build]]\ninputs = ["a.txt", "b.txt"]\noutput = "a.glb"\n', 2, "one species file"),
    ('[[clouds]]\ninputs = ["a.awn", "b.awn"]\noutput = "a.ply"\noffset = [[0, 0, 0]]\n', 4,
     "one [x, y, z] per input (2)"),
    ('[[clouds]]\ninput = "a.awn"\noutput = "a.ply"\nbillboards = "yes"\n', 4, "true or false"),
    ('[[build]]\ninput = "a.txt"\noutput = "a.glb"\n\n[[build]]\ninput = "b.txt"\noutput = "a.glb"\n', 7,
     "one job per output, the first at"),
    ('[[build]]\ninput = "a.txt"\noutput = "a.gltf"\n\n[[build]]\ninput = "b.txt"\noutput = "a.obj"\n', 7,
     "expected jobs whose outputs are different files, found a.gltf (FILE:3) and a.obj, which both write "
     "a_*.png"),
    ('[[build]]\ninput = "a.txt"\noutput = "f/a.txt.glb"\n\n[[clouds]]\ninput = "c.awn"\n'
     'output = "f/a.gltf"\n\n[[build]]\ninput = "b.txt"\noutput = "f/a_c.ply"\n', 11,
     "found f/a.gltf (FILE:7) and f/a_c.ply"),
    ('[[bild]]\ninput = "a.txt"\n', 1, "expected one of out, [[build]]"),
    # options that cannot go together, as `fishgen school` refuses them, at the job's output line
    ('[[school]]\ninput = "a.txt"\noutput = "s.glb"\npreset = "torus"\nmodel = "boids"\n', 3,
     "expected preset with the couzin model, found model boids"),
    ('[[school]]\ninput = "a.txt"\noutput = "s.glb"\nlayout = "donut"\n', 4,
     "expected layout as one of sphere, box, line, ring, found 'donut'"),
    ('[[school]]\ninput = "a.txt"\noutput = "s.glb"\ntints = 3\nmerge = true\n', 3,
     "expected tints 1 with lods or merge"),
    # options the job would ignore: speed without a body wave, voxel-size without voxels
    ('[[build]]\ninput = "a.txt"\noutput = "a.glb"\nswim = "fins"\nspeed = 3\n', 3,
     "expected swim body with speed (it sets the body wave's tail beat, which swim fins does not have)"),
    ('[[clouds]]\ninput = "a.awn"\noutput = "a.glb"\nvoxel-size = 0.5\n', 3,
     "expected a .nvdb or .vdb output with voxel-size, found '.glb'"),
    # or cannot be met: each failed later as a job, one at a time (QA pass 9)
    ('[[clouds]]\ninput = "a.awn"\noutput = "a.ply"\nbillboards = true\n', 3,
     "expected a .glb or .gltf output with billboards, found '.ply'"),
    ('[[clouds]]\ninput = "a.awn"\noutput = "a.ply"\nlight = false\nsun = [1, 1, 1]\n', 3,
     "expected no lighting options with no-light, found sun"),
    ('[[build]\ninput = "a.txt"\n', 1, "expected TOML"),
    ('out = "o"\n', None, "expected at least one job ([[build]], [[clouds]], [[school]])"),
])
def test_every_mistake_is_one_line_at_its_place(tmp_path, text, line, message):
    path = write(tmp_path, text)
    with pytest.raises(FishgenError) as caught:
        load_manifest(path)
    assert caught.value.file == str(path) and caught.value.line == line
    assert message.replace("FILE", str(path)) in caught.value.message and "\n" not in str(caught.value)


def test_a_folder_scan_makes_one_default_job_per_species_and_cube_file(tmp_path):
    manifest = scan_folder(PARAMS, tmp_path / "out")
    names = sorted(job.name for job in manifest.jobs)
    assert names == sorted([f"{p.stem}.glb" for p in PARAMS.glob("*.txt")]
                           + [f"clouds/{p.stem}.glb" for p in (PARAMS / "clouds").glob("*.aw[na]")])
    (tmp_path / "empty").mkdir()
    with pytest.raises(FishgenError, match="expected species files"):
        scan_folder(tmp_path / "empty", tmp_path / "o2")


@pytest.mark.parametrize("kind", ["build", "school", "clouds"])
def test_a_job_takes_every_option_of_its_command_that_a_manifest_may_set(kind):
    """Both come from one declaration: the command's options record."""
    import click

    from fishgen.cli import cli
    from fishgen.commands import command
    from fishgen.options import manifest_options

    click_command = cli.get_command(None, kind)  # type: ignore[arg-type]
    names = {opt.lstrip("-") for p in click_command.params if isinstance(p, click.Option) for opt in p.opts
             if opt.startswith("--")}
    local = {"output", "quiet", "verbose", "json", "help"}  # -o is a manifest's `output`
    declared = manifest_options(command(kind).options)
    assert set(declared) <= names - local
    assert all(not spec.manifest
               for f, spec in manifest_options.__globals__["declared"](command(kind).options)
               if f.name.replace("_", "-") in names - local - set(declared))


def test_a_seed_the_command_line_takes_a_manifest_takes_too(tmp_path):
    """Issue 19: `--seed 1099511627776` worked on the command line and was refused in a manifest."""
    manifest = load_manifest(write(tmp_path, '[[clouds]]\ninput = "a.awn"\noutput = "a.ply"\n'
                                             'seed = 1099511627776\n'))
    assert manifest.jobs[0].options.seed == 1099511627776


def test_a_textures_folder_that_is_not_there_is_refused_at_its_line(tmp_path):
    """`--textures typo/` was taken without a word where no texture was looked up (a sky of .awn
    clouds); a manifest's folder is checked relative to the manifest, at its line."""
    (tmp_path / "tex").mkdir()
    good = load_manifest(write(tmp_path, '[[build]]\ninput = "a.txt"\noutput = "a.glb"\ntextures = "tex"\n'))
    assert good.jobs[0].options.textures == tmp_path / "tex"
    path = write(tmp_path, '[[build]]\ninput = "a.txt"\noutput = "a.glb"\ntextures = "text"\n')
    with pytest.raises(FishgenError) as caught:
        load_manifest(path)
    assert str(caught.value) == (f"{path}:4: expected textures as an existing folder (relative to the "
                                 "manifest), found 'text'")


def test_a_school_job_with_prototypes_and_a_glb_is_refused_at_its_line(tmp_path):
    path = write(tmp_path, '[[school]]\ninput = "a.txt"\noutput = "s.glb"\nprototypes = 2\n')
    with pytest.raises(FishgenError, match="expected prototypes with a USD output"):
        load_manifest(path)
    assert load_manifest(write(tmp_path, '[[school]]\ninput = "a.txt"\noutput = "s.usdc"\nprototypes = 2\n'))


def test_a_usd_job_without_usd_core_is_a_missing_package_at_its_line(tmp_path, monkeypatch):
    """It was said at the job's line as bad input (exit 2, kind input), where `build` and `school`
    say exit 1, kind dependency, as the README's table does (QA pass 14)."""
    import importlib.util

    from fishgen.errors import MissingDependency

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "pxr" else real(name, *a))
    path = write(tmp_path, '[[build]]\ninput = "a.txt"\noutput = "a.usdz"\n')
    with pytest.raises(MissingDependency) as caught:
        load_manifest(path)
    assert (caught.value.status, caught.value.kind) == (1, "dependency")
    assert str(caught.value) == (f"{path}:3: writing .usdz needs usd-core (pxr), which is not installed; "
                                 "install it with pip install 'fishgen[usd]'")


@pytest.mark.parametrize("text,message", [
    (b'[build]\ninput = "a.txt"\noutput = "a.glb"\n',
     ":1: expected [[build]] tables (one a job), found a single [build] table"),      # was a Python dict
    (b'[[build]]\ninput = "a.txt"\ninput = "b.txt"\noutput = "a.glb"\n',
     ":3: expected each key once in its table, found one given again"),    # was "cannot overwrite a value"
    (b'[[build]]\ninput = "a\xff.txt"\noutput = "a.glb"\n',
     ":2: expected UTF-8 text (TOML), found the byte 0xff"),       # was a job's missing 'a\ufffd.txt'
])
def test_a_manifest_fault_is_said_at_its_line_in_its_own_words(tmp_path, text, message):
    """QA pass 14's manifest notes: each now FILE:LINE, said as a user would say it."""
    path = tmp_path / "m.toml"
    path.write_bytes(text)
    with pytest.raises(FishgenError) as caught:
        load_manifest(path)
    assert str(caught.value) == f"{path}{message}"
