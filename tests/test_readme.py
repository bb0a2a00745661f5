"""The README holds: its examples run as written, in order, on a fresh copy of the project; no
example overwrites another's output; its command and exit-status tables match fishgen."""
from __future__ import annotations

import re
import shutil
import signal
import subprocess
import sys

import pytest

from tests.conftest import ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")
#: Examples that cannot run here, and why.
NOT_HERE = {"--scheduler": "needs a Dask scheduler at that address"}


def examples() -> list[str]:
    """Every command line of the ```sh blocks under ## Commands, in order (the Quick start installs)."""
    commands = README[README.index("\n## Commands"):]
    lines = []
    for block in re.findall(r"```sh\n(.*?)```", commands, re.S):
        lines += [line.split("  #")[0].strip() for line in block.splitlines() if line.strip()]
    return lines


def serves(line: str) -> bool:
    """An example that serves a page until Ctrl-C (view, edit, and fly without a time-out)."""
    return ((line.startswith("fishgen view") and "--no-serve" not in line) or line.startswith("fishgen edit")
            or (line.startswith("fishgen fly") and "--timeout" not in line))


def outputs(line: str) -> list[str]:
    """The files an example names as its outputs."""
    found = re.findall(r"(?:-o|--output|--metrics|--tracks|--plot|--report|--compare|--fxl-out)\s+(\S+)",
                       line)
    return [f for f in found if not f.endswith("/")]


def test_no_example_overwrites_another_ones_output():
    seen: dict[str, str] = {}
    for line in examples():
        for path in outputs(line):
            assert path not in seen, f"{path} is written by both `{seen[path]}` and `{line}`"
            seen[path] = line


@pytest.mark.slow
def test_the_examples_run_as_written_in_order(tmp_path):
    """On a fresh copy of the shipped data, every example exits 0 with no traceback; the reef's
    summary is the one the README shows."""
    for folder in ("params", "textures"):
        shutil.copytree(ROOT / folder, tmp_path / folder)
    (tmp_path / "out").mkdir()
    fishgen = f"{sys.executable} -m fishgen"
    # BROWSER: `fishgen edit` opens the system's browser, as a user wants; here it opens nothing
    env = {"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "BROWSER": "true"}
    printed = {}
    for line in examples():
        if any(flag in line for flag in NOT_HERE):
            continue
        command = re.sub(r"^fishgen\b", fishgen, line)
        if serves(line):  # a page served until Ctrl-C: it must say where, then stop on ^C
            proc = subprocess.Popen(["bash", "-c", f"exec {command}"], cwd=tmp_path, env=env, text=True,
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            assert proc.stdout is not None
            try:
                said = [proc.stdout.readline() for _ in range(2)]
                proc.send_signal(signal.SIGINT)
                proc.communicate(timeout=60)
            finally:   # a server that outlived its Ctrl-C is the test's failure, not the machine's
                proc.kill()
                proc.wait()
            assert any("http://127.0.0.1:" in s and "token=" in s for s in said), (line, said)
            continue
        run = subprocess.run(["bash", "-c", command], cwd=tmp_path, env=env, capture_output=True, text=True,
                             timeout=600)
        assert run.returncode == 0 and "Traceback" not in run.stderr, f"`{line}`:\n{run.stderr}"
        printed[line] = run.stdout
    reef = next(line for line in printed if "params/reef.toml" in line)
    shown = re.search(r"```text\n(out/reef\.glb:.*?)```", README, re.S)
    assert shown is not None and printed[reef] == shown[1], printed[reef]


def test_the_command_table_lists_every_command_with_its_manifest_table():
    from fishgen.commands import MODULES, command

    table = README[README.index("\n## Commands"):README.index("\n### Exit status")]
    rows = {m[1]: m[2] for m in re.finditer(r"^\| `fishgen (\w+)` \|[^\n]*\| ([^|\n]*)\|$", table, re.M)}
    assert set(rows) == set(MODULES)
    for name, manifest in rows.items():
        assert (f"`[[{name}]]`" in manifest) == command(name).batch, name


def test_the_exit_status_table_is_what_the_errors_say():
    """Each row's (status, kind) is an error class's, and every class has its row."""
    from fishgen.batch.jobs import InternalError, WorkerLost
    from fishgen.errors import FishgenError, JobsFailed, MissingDependency, SystemFailure, UsageError

    table = README[README.index("\n### Exit status"):README.index("\n### Reliability")]
    rows = set()
    for status, kinds in re.findall(r"^\| (\d+) \| ([^|]*)\|", table, re.M):
        rows |= {(int(status), k) for k in re.findall(r"`(\w+)`", kinds)} or {(int(status), "")}
    said = {(0, ""), (130, "interrupted"), (143, "interrupted"), (JobsFailed("", True).status, "jobs"),
            (JobsFailed("", False).status, "jobs")}
    said |= {(cls.status, cls.kind) for cls in (FishgenError, UsageError, SystemFailure, MissingDependency)}
    assert said <= rows and {(s, k) for s, k in rows if k not in ("worker", "internal")} <= said
    assert (WorkerLost.status, InternalError.status) == (1, 1)


def _anchors(markdown: str) -> set[str]:
    """The anchors GitHub gives a page's headings: lower case, punctuation dropped, spaces to
    hyphens, and -1, -2, … after a repeated one."""
    anchors: set[str] = set()
    for heading in re.findall(r"^#{1,6} +(.+?) *#*$", _FENCED.sub("", markdown), re.M):
        slug = re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")
        repeat = next(n for n in range(len(anchors) + 1) if (f"{slug}-{n}" if n else slug) not in anchors)
        anchors.add(f"{slug}-{repeat}" if repeat else slug)
    return anchors


_FENCED = re.compile(r"^```.*?^```", re.S | re.M)


def _prose(markdown: str) -> str:
    """The page without its fenced code blocks and code spans, where brackets are not links."""
    return re.sub(r"`[^`\n]*`", "", _FENCED.sub("", markdown))


def test_every_relative_link_and_image_resolves():
    """Each relative link or image in the README and docs/*.md names a file that exists, and a
    heading of that page where it names one."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    broken = []
    for page in pages:
        for target in re.findall(r"\]\(([^()\s]+)\)", _prose(page.read_text(encoding="utf-8"))):
            if re.match(r"[a-z]+:", target):
                continue
            path, _, anchor = target.partition("#")
            file = (page.parent / path).resolve() if path else page
            if not file.exists():
                broken.append(f"{page.name}: {target} (no such file)")
            elif anchor and file.suffix == ".md" and anchor not in _anchors(file.read_text(encoding="utf-8")):
                broken.append(f"{page.name}: {target} (no such heading)")
    assert not broken, "\n".join(broken)
