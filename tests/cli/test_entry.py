"""The command's process: what the entry point sets up before any work is done."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

# whether numpy asks for huge pages, as the command's process has it (numpy 2 moved the module)
PROBE = ("import fishgen.cli, numpy\n"
         "try:\n    from numpy._core.multiarray import _set_madvise_hugepage as flip\n"
         "except ImportError:\n    from numpy.core.multiarray import _set_madvise_hugepage as flip\n"
         "print(flip(False))")


def _huge_pages(env_value: str | None) -> str:
    env = {k: v for k, v in os.environ.items() if k != "NUMPY_MADVISE_HUGEPAGE"}
    if env_value is not None:
        env["NUMPY_MADVISE_HUGEPAGE"] = env_value
    out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, cwd=ROOT, env=env,
                         check=True)
    return out.stdout.strip()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="numpy asks for huge pages on Linux only")
def test_the_command_turns_numpys_huge_pages_off():
    # a fresh 500 MB array's first touch took 1.9 s with them and 0.22 s without (docs/decisions.md)
    assert _huge_pages(None) == "False"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="numpy asks for huge pages on Linux only")
@pytest.mark.parametrize("value", ["1", "-1", "+1"])
def test_a_users_choice_of_huge_pages_stands(value):
    assert _huge_pages(value) == "True"       # numpy reads any whole number but 0 as on


@pytest.mark.parametrize("value", ["", "yes", "\u00b2"])
def test_a_setting_numpy_cannot_read_is_not_a_traceback(value):
    # numpy raised ValueError at its import, before any of fishgen's error handling
    assert _huge_pages(value) == "False"


def test_a_name_the_terminal_cannot_encode_is_printed_escaped(tmp_path):
    """The summary line names the output; in a latin-1 terminal a ``✓`` in it was a traceback and
    exit 1 after the file had landed, so a pipeline threw a good asset away."""
    out = tmp_path / "fïsh✓.glb"
    env = {**os.environ, "PYTHONIOENCODING": "latin-1"}
    done = subprocess.run([sys.executable, "-m", "fishgen", "build", str(ROOT / "params" / "bonybream.txt"),
                           "-o", str(out)], capture_output=True, cwd=ROOT, env=env)
    assert done.returncode == 0, done.stderr.decode("latin-1")
    assert out.exists() and b"Traceback" not in done.stderr
    assert b"\\u2713.glb: bonybream" in done.stdout


def test_a_mistyped_command_is_one_line_that_names_the_nearest():
    """Options were suggested; commands were not (QA pass 21)."""
    from tests.cli_runner import run_cli

    run = run_cli("buidl", "params/bonybream.txt")
    assert (run.returncode, run.stderr) == (2, "fishgen: No such command 'buidl'. Did you mean 'build'?\n")
    far = run_cli("zzz")
    assert (far.returncode, far.stderr) == (2, "fishgen: No such command 'zzz'.\n")


def test_fishgen_alone_prints_its_help_as_click_does_not_an_error_line_around_it():
    """The help came behind an error prefix, `fishgen: Usage: fishgen …` (QA pass 21)."""
    from tests.cli_runner import run_cli

    run = run_cli()
    assert run.returncode == 2 and run.stdout == ""
    assert run.stderr.startswith("Usage: fishgen [OPTIONS] COMMAND [ARGS]...") and "  build " in run.stderr
    plain = run_cli("--help")
    assert plain.returncode == 0 and plain.stdout.rstrip() == run.stderr.rstrip()
