"""--quiet, --verbose and --json on every command, and one exit-status table for all of them."""
from __future__ import annotations

import json

import pytest

from fishgen.commands import MODULES as COMMANDS
from tests.conftest import PARAMS, run_cli


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_command_takes_quiet_verbose_and_json(command):
    help_text = run_cli(command, "--help").stdout
    for option in ("--quiet", "--verbose", "--json"):
        assert option in help_text, f"fishgen {command} has no {option}"


def test_quiet_drops_the_summary_and_verbose_lists_each_file_written(tmp_path):
    out = tmp_path / "b.glb"
    quiet = run_cli("build", PARAMS / "bonybream.txt", "-o", out, "--quiet")
    assert quiet.returncode == 0 and quiet.stdout == "" and quiet.stderr == "" and out.is_file()
    verbose = run_cli("-v", "clouds", PARAMS / "clouds" / "table_4_2.awn", "-o", tmp_path / "c.ply")
    assert verbose.returncode == 0 and verbose.stdout.startswith(str(tmp_path / "c.ply"))
    assert f"fishgen: wrote {tmp_path / 'c.ply'}\n" in verbose.stderr
    assert "fishgen clouds: done in" in verbose.stderr


def test_quiet_discards_a_summary_naming_a_file_whose_name_is_not_utf8(tmp_path):
    """-q wrote the summary to a strict UTF-8 sink: `wrote bad\\udcff.glb` raised after the write."""
    import os

    out = os.fsdecode(os.fsencode(str(tmp_path)) + b"/bad\xff.glb")
    result = run_cli("build", PARAMS / "bonybream.txt", "-o", out, "-q")
    assert (result.returncode, result.stdout, result.stderr) == (0, "", "") and os.path.isfile(out)


@pytest.mark.parametrize("args", [["-q", "-v", "build"], ["-v", "build", "-q"], ["build", "-q", "-v"]])
def test_quiet_wins_over_verbose_wherever_each_is_given(tmp_path, args):
    out = tmp_path / "b.glb"
    result = run_cli(*args, PARAMS / "bonybream.txt", "-o", out)
    assert (result.returncode, result.stdout, result.stderr) == (0, "", "") and out.is_file()


@pytest.mark.parametrize("args,status,kind,line", [
    (["build", "{missing}", "-o", "{out}"], 2, "input", None),
    (["build", str(PARAMS.parent / "tests" / "fixtures" / "appendix_a_as_printed.txt"), "-o", "{out}"], 2,
     "input", 2),
    (["build", "--no-such-option"], 2, "usage", None),
    # an output the command cannot write is the command line's fault, named as the file
    (["clouds", str(PARAMS / "clouds" / "table_4_2.awn"), "-o", "{out}.txt"], 2, "usage", None),
    (["school", str(PARAMS / "bonybream.txt"), "-o", "{out}.obj"], 2, "usage", None),
])
def test_json_errors_are_one_object_with_the_exit_status(tmp_path, args, status, kind, line):
    filled = [a.format(missing=tmp_path / "none.txt", out=tmp_path / "x.glb") for a in args]
    for placed in (["--json", *filled], [*filled, "--json"]):
        run = run_cli(*placed)
        error = json.loads(run.stderr)
        assert run.returncode == status == error["exit"] and error["kind"] == kind and error["line"] == line
        assert set(error) == {"error", "file", "line", "exit", "kind"} and "\n" not in error["error"]


def test_json_errors_of_a_multi_file_build_are_one_object_per_bad_file(tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("nothing like a species\n")
    run = run_cli("build", PARAMS / "bonybream.txt", bad, tmp_path / "none.txt",
                  "-o", f"{tmp_path}/out/", "--json")
    assert run.returncode == 2 and (tmp_path / "out" / "bonybream.glb").is_file()
    errors = [json.loads(line) for line in run.stderr.splitlines()]
    assert [(e["file"], e["line"], e["exit"], e["kind"]) for e in errors] == [
        (str(bad), 1, 2, "input"), (str(tmp_path / "none.txt"), None, 2, "input")]


def test_under_json_every_line_on_stderr_is_an_object_notes_too(tmp_path):
    """A warning was plain text among the JSON lines: a pipeline parsing stderr tripped on it
    (QA pass 21)."""
    bad = tmp_path / "bad.txt"
    bad.write_text("not a species\n")
    run = run_cli("build", PARAMS / "bonybream.txt", bad, "-o", f"{tmp_path}/", "--json")
    school = run_cli("school", PARAMS / "bonybream.txt", "--count", "150", "--frames", "10",
                     "-o", tmp_path / "s.glb", "--json", "-q")
    lines = [json.loads(line) for line in (run.stderr + school.stderr).splitlines()]
    assert [sorted(o) for o in lines] == [["error", "exit", "file", "kind", "line"], ["note"]]
    assert "Godot 3 plays at most 1,024" in lines[1]["note"]


def test_version():
    """The version every file records: an editable install's stale metadata said 0.2.0 after 0.2.1."""
    from fishgen import __version__

    run = run_cli("--version")
    assert run.returncode == 0 and run.stdout == f"fishgen, version {__version__}\n"


@pytest.mark.parametrize("args,message", [
    (["clouds", "{cubes}", "--offset", "0,0,0", "--offset", "1,1,1", "-o", "{out}/x.ply"],
     "expected one --offset per input (1), found 2"),
    (["school", "{fish}", "--count", "100000", "--frames", "100000", "-o", "{out}/s.glb"],
     "expected at most 100,000 fish and 200,000,000 fish x frames"),
    (["preview", "{fish}", "--size", "8192x8192", "--frames", "1000", "-o", "{out}/p.gif"],
     "expected at most 1073741824 pixels (2^30)"),
    (["fly"], "expected INPUT... (cube files, .awa, .glb) or --mode thin|medium|thick, found neither"),
    (["school", str(PARAMS / "reef.toml"), "{fish}", "-o", "{out}/s.glb"],
     "expected one scene file alone or species files, found 2 inputs"),
])
def test_a_usage_error_from_the_command_names_the_command_as_clicks_own_do(tmp_path, args, message):
    """They printed `fishgen: ...` while click's own usage errors print `fishgen build: ...`."""
    filled = [a.format(fish=PARAMS / "bonybream.txt", cubes=PARAMS / "clouds" / "table_4_3.awn", out=tmp_path)
              for a in args]
    plain = run_cli(*filled)
    assert plain.returncode == 2 and plain.stderr.startswith(f"fishgen {args[0]}: {message}"), plain.stderr
    assert plain.stderr.count("\n") == 1
    as_json = run_cli("--json", *filled)
    error = json.loads(as_json.stderr)
    assert (error["error"], error["kind"], error["exit"]) == (plain.stderr.strip(), "usage", 2)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args,output,message", [
    (["build", "{fish}"], "x.foo", "expected an output ending in .glb, .gltf, .obj, .ply"),
    (["build", "{fish}"], "x.awn", "found '.awn' (a RekAwan cloud cube file, an input of `fishgen clouds`)"),
    (["school", "{fish}"], "x.ply", "expected a format that holds"),
    (["clouds", "{cubes}"], "x.obj", "expected a format that holds points, found .obj"),
    (["clouds", "{cubes}", "--billboards"], "x.ply", "expected a .glb or .gltf output with --billboards"),
    (["sky"], "s.ply", "expected a .glb or .gltf output (a sky's nodes and levels of detail need glTF), "
                       "found '.ply'"),
    (["preview", "{fish}"], "p.bmp", "expected an output ending in .png, .webp, .gif, .jpg, .jpeg, "
                                     "found '.bmp'"),
    (["preview", "{fish}", "--frames", "3"], "p.png", "expected a .gif or .webp output for --frames 3, "
                                                      "found '.png'"),
    (["species", "--random"], "a.xyz", "expected -o to name a species file (.txt) or a folder"),
    (["species", "--random"], "axyz", "found 'no extension'"),
    (["build", "{fish}"], "o", "expected an output file with an extension, or a folder"),
    (["texture", str(PARAMS / "photos" / "bonybream-side.png"), "-s", "{fish}"], "s.xyz",
     "expected -o to name a species file (.txt), found '.xyz'"),
])
def test_an_output_of_the_wrong_kind_is_named_as_the_file_at_fault(tmp_path, args, output, message):
    """`build`, `school` and `clouds` named the output as bad input (kind input) while `sky`,
    `preview`, `species` and `texture` named the command: every one now names the output, as a bad
    command line (kind usage, exit 2)."""
    filled = [a.format(fish=PARAMS / "bonybream.txt", cubes=PARAMS / "clouds" / "table_4_3.awn")
              for a in args]
    out = tmp_path / output
    run = run_cli(*filled, "-o", out)
    assert run.returncode == 2 and run.stderr.startswith(f"{out}: "), run.stderr
    assert message in run.stderr and run.stderr.count("\n") == 1, run.stderr
    error = json.loads(run_cli("--json", *filled, "-o", out).stderr)
    assert (error["file"], error["kind"], error["exit"]) == (str(out), "usage", 2)
    assert list(tmp_path.iterdir()) == []


def _required(name: str) -> list[str]:
    """The options ``fishgen NAME --help`` marks [required]: -o and the declared ones."""
    from fishgen.commands import command
    from fishgen.options import declared, long_name

    cmd = command(name)
    found = ["-o"] if cmd.output is not None and cmd.output.required else []
    return found + [f"--{long_name(f)}" for f, spec in declared(cmd.options) if spec.required]


@pytest.mark.parametrize("name", [n for n in sorted(COMMANDS) if _required(n)])
def test_a_required_option_left_out_is_a_usage_error_in_one_line(tmp_path, name):
    """click 8.3 took an explicit default of None as a value given: `fishgen school SPECIES` with no
    -o (and `texture` without -s, `species` without --random) got past it into a traceback."""
    inputs = {"build": [PARAMS / "bonybream.txt"], "school": [PARAMS / "bonybream.txt"],
              "clouds": [PARAMS / "clouds" / "table_4_3.awn"], "preview": [PARAMS / "bonybream.txt"],
              "texture": [PARAMS / "photos" / "bonybream-side.png"], "edit": [tmp_path / "new.awn"],
              "fly": [PARAMS / "clouds" / "table_4_3.awn"], "view": [PARAMS / "bonybream.txt"]}
    values = {"-o": str(tmp_path / "x.txt"), "--species": str(PARAMS / "bonybream.txt"), "--random": None}
    required = _required(name)
    for left_out in required:
        given = [part for option in required if option != left_out
                 for part in ([option] if values[option] is None else [option, values[option]])]
        result = run_cli(name, *inputs.get(name, []), *given, cwd=tmp_path)
        assert result.returncode == 2, result.stderr
        assert result.stderr.startswith(f"fishgen {name}: Missing option"), result.stderr
        assert result.stderr.count("\n") == 1 and left_out in result.stderr
    assert not (tmp_path / "x.txt").exists()


@pytest.mark.parametrize("args", [["clouds", str(PARAMS / "clouds" / "table_4_3.awn"), "-o"],
                                  ["build", str(PARAMS / "bonybream.txt"), "--fps"],
                                  ["--json", "sky", "--mode"]])
def test_an_option_given_no_value_names_its_command(args):
    """click raises it in the group's context: the line read `fishgen: Option '-o' requires an
    argument.`, where every other usage error names the command (QA pass 13)."""
    result = run_cli(*args)
    name = next(a for a in args if a in COMMANDS)
    assert result.returncode == 2, result.stderr
    assert f"fishgen {name}: Option '{args[-1]}' requires an argument" in result.stderr
    assert result.stderr.count("\n") == 1


@pytest.mark.parametrize("args", [["--foo", "build", "x.txt"], ["-q", "--foo", "school", "x.txt"],
                                  ["--foo=1", "build", "x.txt"], ["-qf", "build", "x.txt"]])
def test_an_unknown_option_before_the_command_is_the_group_s(args):
    """It was named with the command typed after it, `fishgen build: No such option '--foo'`, as an
    option of build's (QA pass 21)."""
    result = run_cli(*args)
    option = "-f" if args[0] == "-qf" else "--foo"
    assert result.returncode == 2 and result.stderr == f"fishgen: No such option '{option}'.\n", result.stderr


@pytest.mark.parametrize("args", [
    ["sky", "--mode", "thin", "--particles", "500"], ["school", "{fish}", "--count", "3", "--frames", "5"],
    ["clouds", "{cubes}"], ["species", "--random"], ["build", "{fish}"],
])
def test_a_device_as_the_output_is_said_to_be_one(args):
    """`-o /dev/null` read "found 'no extension'" where the format was checked first."""
    fill = {"fish": PARAMS / "bonybream.txt", "cubes": PARAMS / "clouds" / "table_4_3.awn"}
    result = run_cli(*[str(fill[a[1:-1]]) if a.startswith("{") else a for a in args], "-o", "/dev/null")
    assert result.returncode == 2 and result.stderr == (
        "/dev/null: expected a regular file or no file as the output, found a device, pipe or other "
        "special file\n")


@pytest.mark.parametrize("args", [
    ["sky", "--mode", "thin", "--particles", "500"], ["preview", "{fish}"], ["view", "--no-serve", "{glb}"],
    ["school", "{fish}", "--count", "3", "--frames", "5"], ["clouds", "{cubes}"],
    ["texture", "{photo}", "-s", "{fish}"],
])
def test_a_folder_as_the_one_output_file_is_a_usage_error(tmp_path, args):
    """`-o` names a folder only for commands that write several files there (build, species): the
    others read 'found no extension', or 'fishgen: ... found a folder' with no command."""
    folder = tmp_path / "dirout"
    folder.mkdir()
    fill = {"fish": PARAMS / "bonybream.txt", "cubes": PARAMS / "clouds" / "table_4_3.awn",
            "photo": PARAMS / "photos" / "bonybream-side.png", "glb": tmp_path / "x.glb"}
    if "{glb}" in args:
        assert run_cli("build", PARAMS / "bonybream.txt", "-o", fill["glb"]).returncode == 0
    filled = [str(fill[a[1:-1]]) if a.startswith("{") else a for a in args]
    result = run_cli(*filled, "-o", folder)
    assert result.returncode == 2 and result.stderr == (
        f"fishgen {args[0]}: expected -o to name an output file, found the folder {str(folder)!r}\n")
    assert list(folder.iterdir()) == []


@pytest.mark.parametrize("args", [["sky", "--mode", "thin"], ["build", "{fish}"], ["clouds", "{cubes}"]])
def test_a_textures_folder_that_is_not_there_is_a_usage_error(tmp_path, args):
    fill = {"fish": PARAMS / "bonybream.txt", "cubes": PARAMS / "clouds" / "table_4_3.awn"}
    argv = [str(fill[a[1:-1]]) if a.startswith("{") else a for a in args]
    result = run_cli(*argv, "--textures", tmp_path / "typo", "-o", tmp_path / "x.glb")
    assert result.returncode == 2 and result.stderr == (
        f"fishgen {args[0]}: expected --textures to name an existing folder, found nothing at "
        f"'{tmp_path / 'typo'}'\n")
    assert not (tmp_path / "x.glb").exists()


@pytest.mark.parametrize("args", [
    ["species", "--random"], ["build", "{fish}"], ["school", "{fish}", "--count", "3", "--frames", "5"],
    ["clouds", "{cubes}"], ["texture", "{photo}", "-s", "{fish}"],
])
def test_an_empty_output_name_is_a_usage_error(tmp_path, args):
    """`-o ''` is no name: build and species wrote into the working folder, the others said
    'found the folder' (QA pass 10)."""
    fill = {"fish": PARAMS / "bonybream.txt", "cubes": PARAMS / "clouds" / "table_4_3.awn",
            "photo": PARAMS / "photos" / "bonybream-side.png"}
    filled = [str(fill[a[1:-1]]) if a.startswith("{") else a for a in args]
    result = run_cli(*filled, "-o", "", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.startswith(f"fishgen {args[0]}: expected -o to name an output")
    assert result.stderr.endswith("found an empty name\n") and result.stderr.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args", [
    ["batch", "{params}", "--out", ""], ["batch", "{params}", "--out", "{out}", "--report", ""],
    ["build", "{fish}", "-o", "{out}/x.glb", "--textures", ""],
])
def test_an_empty_path_option_is_a_usage_error(tmp_path, args):
    """`batch DIR --out ''` wrote its outputs and record into the working folder (review of QA pass
    10's fixes): a folder or file option must name one."""
    fill = {"params": PARAMS, "fish": PARAMS / "bonybream.txt", "out": tmp_path / "out"}
    filled = [a.format(**{k: str(v) for k, v in fill.items()}) for a in args]
    (tmp_path / "here").mkdir()
    result = run_cli(*filled, cwd=tmp_path / "here")
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert "expected a file or folder name, found an empty one" in result.stderr
    assert list((tmp_path / "here").iterdir()) == [] and not (tmp_path / "out").exists()


def test_under_json_pythons_own_warnings_are_notes_too(tmp_path):
    """A library's warning (Pillow's on a palette texture) came as Python's two plain lines."""
    import warnings

    from fishgen.cli.adapter import TerminalEvents, _warnings_as_notes
    from fishgen.cli.common import reset

    said: list[str] = []
    events = TerminalEvents("build")
    events.note = said.append           # type: ignore[method-assign]
    reset(json_errors=True)
    try:
        with _warnings_as_notes(events):
            warnings.warn("Palette images with Transparency expressed in bytes", UserWarning, stacklevel=1)
    finally:
        reset(json_errors=False)
    assert said == ["Palette images with Transparency expressed in bytes"]


@pytest.mark.parametrize("command", ["build", "view", "batch"])
def test_an_empty_input_path_is_a_usage_error(command):
    run = run_cli(command, "")
    assert run.returncode == 2 and run.stderr.count("\n") == 1 and "found an empty one" in run.stderr


def test_view_of_a_folder_is_one_line():
    """`fishgen view .` was a traceback: the page's name was taken from the folder's, which `.` lacks."""
    run = run_cli("view", ".", "--no-serve")
    assert (run.returncode, run.stderr) == (2, ".: expected a file, found a directory\n")


def test_a_python_caller_s_empty_input_path_is_a_usage_error(tmp_path):
    from fishgen.commands.batch import BatchOptions, batch
    from fishgen.errors import UsageError

    with pytest.raises(UsageError, match="found an empty one"):
        batch("", None, BatchOptions(out=tmp_path))
