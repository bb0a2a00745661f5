"""One declaration per option: the command line, batch manifests and the library function all
take it from the options record (issue 19)."""
from __future__ import annotations

import pytest
from click.testing import CliRunner

from fishgen.commands import MODULES, Made, command
from tests.commands import toy
from tests.conftest import PARAMS


@pytest.fixture
def with_toy(monkeypatch):
    monkeypatch.setitem(MODULES, "toy", "tests.commands.toy")
    toy.SEEN.clear()
    return toy


def test_an_option_declared_once_is_in_help_in_a_manifest_and_in_the_function(with_toy, tmp_path):
    from fishgen.batch import run_batch
    from fishgen.batch.manifest import load_manifest
    from fishgen.cli import cli
    from fishgen.commands.batch import job_kinds, run_job

    help_text = CliRunner().invoke(cli, ["toy", "--help"]).output
    assert "--brightness" in help_text and "How bright the toy shines.  [default: 2.5]" in help_text

    (tmp_path / "in.txt").write_text("x")
    ran = CliRunner().invoke(cli, ["toy", str(tmp_path / "in.txt"), "-o", str(tmp_path / "a.csv"),
                                   "--brightness", "7"])
    assert ran.exit_code == 0 and ran.output == "toy 7.0\n"
    bad = CliRunner().invoke(cli, ["toy", str(tmp_path / "in.txt"), "-o", str(tmp_path / "a.csv"),
                                   "--brightness", "11"])
    assert bad.exit_code == 2

    manifest = tmp_path / "m.toml"
    manifest.write_text('[[toy]]\ninput = "in.txt"\noutput = "b.csv"\nbrightness = 4\n')
    outcomes = run_batch(load_manifest(manifest, tmp_path / "out", kinds=job_kinds()), run_job)
    assert ([o.status for o in outcomes] == ["built"]
            and (tmp_path / "out" / "b.csv").read_text() == "4.0 red\n")
    assert [o.brightness for o in toy.SEEN] == [7.0, 4.0]

    manifest.write_text('[[toy]]\ninput = "in.txt"\noutput = "b.csv"\n\nbrightness = 11\n')
    from fishgen.errors import FishgenError
    with pytest.raises(FishgenError) as caught:
        load_manifest(manifest, kinds=job_kinds())
    assert str(caught.value) == f"{manifest}:5: expected brightness as a number from 0 to 10, found '11'"


@pytest.mark.parametrize("name", sorted(MODULES))
def test_every_option_of_every_command_says_its_default(name):
    """`--help` shows the default of every option, flags and optional outputs included."""
    import click

    from fishgen.cli import cli

    click_command = cli.get_command(None, name)  # type: ignore[arg-type]
    for param in click_command.params:
        if isinstance(param, click.Option) and param.name != "help":
            text = param.help or ""
            assert "[default: " in text or param.required, f"fishgen {name} {param.opts[0]}: {text!r}"


@pytest.mark.parametrize("name", sorted(MODULES))
def test_every_bounded_option_of_every_command_says_its_bounds(name):
    """click shows a number range's bounds in `--help`; a size (WxH) or a list of numbers with
    bounds of its own shows them the same way (`fly --size` said nothing of its 16 to 8192)."""
    import click

    from fishgen.cli import cli
    from fishgen.options import FLOAT32_MAX, Numbers, Size

    click_command = cli.get_command(None, name)  # type: ignore[arg-type]
    for param in click_command.params:
        kind = param.type
        bounded = isinstance(kind, Size) or (isinstance(kind, Numbers)
                                             and (kind.low, kind.high) != (-FLOAT32_MAX, FLOAT32_MAX))
        if isinstance(param, click.Option) and bounded:
            text = " ".join((param.help or "").split())
            low, high = (str(int(v)) if float(v).is_integer() else f"{v:g}" for v in (kind.low, kind.high))
            assert f"[{low}<=" in text and f"<={high}]" in text, f"fishgen {name} {param.opts[0]}: {text!r}"


@pytest.mark.parametrize("name", sorted(MODULES))
def test_no_number_option_of_any_command_takes_nan_or_infinity(name):
    """click's FloatRange lets NaN through (every comparison with it is false): `texture
    --focal-length nan` got past it into a traceback. Every number option refuses both."""
    import click

    from fishgen.options import declared, long_name

    for f, spec in declared(command(name).options):
        kind = spec.type
        if isinstance(kind, click.FloatRange) or kind is click.FLOAT:
            for value in ("nan", "inf", "-inf"):
                with pytest.raises(click.BadParameter):
                    kind.convert(value, None, None)
                    pytest.fail(f"fishgen {name} --{long_name(f)} took {value}")


def test_the_school_scene_file_checks_its_keys_with_the_options_declarations(tmp_path):
    """The scene file's ranges are the options' own: a seed the command line takes, it takes."""
    from fishgen.commands.school import SchoolOptions
    from fishgen.errors import FishgenError
    from fishgen.options import declared
    from fishgen.school.scene_file import FRAMES, load_scene_file

    frames = next(spec for f, spec in declared(SchoolOptions) if f.name == "frames")
    assert frames.type is FRAMES.type
    scene = tmp_path / "s.toml"
    scene.write_text('seed = 1099511627776\n[[species]]\nfile = "a.txt"\n')
    assert load_scene_file(scene).seed == 1099511627776
    scene.write_text('frames = 1\n[[species]]\nfile = "a.txt"\n')
    with pytest.raises(FishgenError,
                       match=r":1: expected frames as a whole number from 2 to 100000, found '1'"):
        load_scene_file(scene)


def test_the_library_function_is_what_the_cli_and_a_batch_job_run():
    for name in MODULES:
        declared = command(name)
        assert declared.function().__name__ == name
        assert declared.function().__annotations__["return"] in ("Made", Made)


# A Python caller's values, each outside what the option's declaration takes (the command line
# refuses each): they had reached the work as tracebacks (a count of -1 compared a complex number,
# a size of -1 x 100 said the framebuffer was out of memory) or were written as given (2.5 fish).
_BAD = [("preview", "size", (-1, 100)), ("preview", "size", (100.5, 100)), ("preview", "fps", 0),
        ("preview", "background", (300, 0, 0, 255)), ("preview", "columns", -3),
        ("school", "count", -1), ("school", "count", 2.5), ("school", "frames", -5),
        ("texture", "body_sections", 1), ("texture", "focal_length", -1.0),
        ("sky", "area", (-400.0, 400.0)), ("sky", "mode", "bogus"), ("sky", "noise", -5.0),
        ("species", "seed", -1), ("clouds", "max_particles", -1), ("clouds", "seed", True),
        ("view", "background", None)]


@pytest.mark.parametrize(("name", "field", "value"), _BAD, ids=[f"{n}-{f}-{v}" for n, f, v in _BAD])
def test_a_python_caller_s_option_is_checked_by_its_declaration_before_any_work(name, field, value,
                                                                                 tmp_path):
    from dataclasses import fields

    from fishgen.errors import UsageError

    declared = command(name)
    record = declared.options
    assert field in {f.name for f in fields(record)}, f"{record.__name__} has no {field}"
    try:
        options = record(**{field: value})
    except TypeError:   # a record with a required field (texture's base species)
        options = record(**{field: value, "species": PARAMS / "bonybream.txt"})
    with pytest.raises(UsageError) as caught:
        declared.function()([PARAMS / "bonybream.txt"], tmp_path / "out.glb", options)
    assert str(caught.value).startswith(f"expected options.{field} (--{field.replace('_', '-')}) to be ")
    assert str(caught.value).endswith(f", found {value!r}")
    assert not list(tmp_path.iterdir())


def test_every_option_s_own_value_from_the_command_line_passes_the_library_check():
    """The command line's values reach the function converted; each type takes its own output back
    (the school's --bounds, a pair of corners, had been refused)."""
    from fishgen.commands.school import SchoolOptions
    from fishgen.options import check_record

    check_record(SchoolOptions(bounds=((-3.0, -1.0, -3.0), (3.0, 1.0, 3.0))))
    for name in MODULES:
        record = command(name).options
        try:
            check_record(record())
        except TypeError:   # texture's required base species
            pass


def test_a_python_caller_s_inputs_may_be_one_path_and_are_counted_as_the_command_line_counts():
    from fishgen.commands.batch import batch
    from fishgen.commands.build import build
    from fishgen.errors import UsageError

    with pytest.raises(UsageError, match=r"^expected one or more SPECIES_FILE\.\.\., found none$"):
        build([], None)
    with pytest.raises(UsageError, match=r"^expected one MANIFEST\.toml\|DIR, found 2$"):
        batch(["a.toml", "b.toml"], None)
    with pytest.raises(UsageError, match=r"^expected the inputs as a list of SPECIES_FILE\.\.\., found 7$"):
        build(7, None)   # type: ignore[arg-type]
    with pytest.raises(UsageError, match=r"^expected options to be a BuildOptions, found dict$"):
        build(["x.txt"], None, {"fps": 30})   # type: ignore[arg-type]
    from fishgen.commands import command as declaration

    assert declaration("build").given(str(PARAMS / "bonybream.txt"), declaration("build").options()) == (
        PARAMS / "bonybream.txt",)
