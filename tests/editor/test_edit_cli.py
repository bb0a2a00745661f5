"""`fishgen edit` on the command line: the page's address first, a bad file refused in one line."""
from __future__ import annotations

import http.client
import queue
import signal
import socket
import subprocess
import sys
import threading
from pathlib import Path
from urllib.parse import urlsplit

import pytest

from tests.conftest import ROOT, run_cli


@pytest.fixture
def edit():
    """``edit(*args)`` starts the real `fishgen edit ... --no-open`; yields (process, its stdout lines)."""
    procs = []

    def start(*args):
        proc = subprocess.Popen([sys.executable, "-u", "-m", "fishgen", "edit", *map(str, args), "--no-open"],
                                cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        procs.append(proc)
        lines: queue.Queue = queue.Queue()
        threading.Thread(target=lambda: [lines.put(line) for line in proc.stdout], daemon=True).start()
        return proc, lines

    yield start
    for proc in procs:
        if proc.poll() is None:
            proc.kill()
        proc.wait(timeout=10)


def _get(url: str) -> tuple[int, bytes]:
    parts = urlsplit(url)
    conn = http.client.HTTPConnection(parts.hostname, parts.port, timeout=30)
    conn.request("GET", f"{parts.path}?{parts.query}")
    response = conn.getresponse()
    return response.status, response.read()


def test_it_prints_the_pages_address_first_and_serves_it_until_ctrl_c(tmp_path, edit):
    proc, lines = edit(tmp_path / "mycloud.awn", "--port", "0")
    url = lines.get(timeout=30).strip()
    assert url.startswith("http://127.0.0.1:") and "?token=" in url
    assert lines.get(timeout=5).startswith(f"new file, empty workspace: {tmp_path / 'mycloud.awn'}")
    status, page = _get(url)
    assert status == 200 and b"fishgen edit" in page
    status, doc = _get(url.replace("/?", "/api/document?"))
    assert status == 200 and b'"exists": false' in doc
    assert _get(url.split("?")[0])[0] == 403  # without the token
    proc.send_signal(signal.SIGINT)
    assert proc.wait(timeout=20) in (0, 130)
    assert not (tmp_path / "mycloud.awn").exists()  # nothing written by opening


@pytest.mark.parametrize("content, message", [
    ("200\n1\n200, 7.3, 1.0\n",
     ":3: expected 8 fields (particles, x y z size, centre x y z, maximum radius), found 3 fields"),
    ("", ":1: expected the total particle count on line 1, found an empty file"),
])
def test_a_file_that_does_not_parse_is_refused_in_one_line_before_serving(tmp_path, content, message):
    bad = tmp_path / "bad.awn"
    bad.write_text(content)
    out = run_cli("edit", bad, "--no-open")
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr.strip().splitlines() == [f"{bad}{message}"]


@pytest.mark.parametrize("name, message", [
    ("fish.txt", "expected an input of `fishgen edit` (.awn, .awa)"),
    ("nowhere/cloud.awn", "expected an existing folder for cloud.awn, found none"),
])
def test_it_edits_only_cube_files_in_a_folder_that_exists(tmp_path, name, message):
    if name == "fish.txt":
        (tmp_path / name).write_text((ROOT / "params" / "bonybream.txt").read_text())
    out = run_cli("edit", tmp_path / name, "--no-open")
    assert out.returncode == 2 and message in out.stderr and len(out.stderr.strip().splitlines()) == 1


def test_a_port_taken_is_the_systems_refusal(tmp_path):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        out = run_cli("edit", tmp_path / "x.awn", "--no-open", "--port", taken.getsockname()[1])
    assert out.returncode == 1 and "expected a free port" in out.stderr and "try --port 0" in out.stderr


def test_its_help_loads_no_numpy():
    code = ("import sys, fishgen.cli as c\n"
            "sys.argv=['fishgen','edit','--help']\n"
            "try: c.main()\nexcept SystemExit: pass\n"
            "print('numpy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert out.stdout.strip().splitlines()[-1] == "False"
    assert "--no-open" in out.stdout and "--sun X,Y,Z" in out.stdout and "--seed" in out.stdout


def test_a_cube_file_over_the_particle_limit_names_no_option_edit_lacks(tmp_path):
    big = tmp_path / "big.awn"
    big.write_text("2000000000\n1\n2000000000, 1, 1, 1, 0, 0, 0, 1\n")
    out = run_cli("edit", big, "--no-open")
    assert out.returncode == 2 and "--max-particles" not in out.stderr, out.stderr
    assert out.stderr == f"{big}:1: expected at most 50,000,000 particles, found 2,000,000,000\n"


def test_a_bad_file_is_named_as_it_was_given_not_as_resolved(tmp_path):
    (tmp_path / "garbage.awn").write_text("garbage\n")
    out = run_cli("edit", "garbage.awn", "--no-open", cwd=tmp_path)
    assert out.returncode == 2
    assert out.stderr == ("garbage.awn:1: expected a whole number for the total particle count, "
                          "found 'garbage'\n")


def test_the_browser_is_given_a_private_file_not_the_token(tmp_path):
    """`fishgen edit` started the browser with the tokened address on its command line, which every
    local user can read in `ps` (QA pass 15). It gets a 0600 file that forwards to the address."""
    import os
    import signal
    import stat
    import time

    told = tmp_path / "told.txt"
    browser = tmp_path / "browser.sh"
    browser.write_text(f'#!/bin/sh\nprintf "%s\\n" "$@" > {told}\n')
    browser.chmod(0o755)
    env = {**os.environ, "BROWSER": str(browser)}
    proc = subprocess.Popen([sys.executable, "-u", "-m", "fishgen", "edit", str(tmp_path / "x.awn")],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        url = proc.stdout.readline().strip()
        deadline = time.monotonic() + 30
        while not (told.exists() and told.read_text()) and time.monotonic() < deadline:
            time.sleep(0.05)
        argv = told.read_text()
        token = url.split("token=")[1]
        assert token not in argv and argv.startswith("file://"), argv
        forward = Path(argv.strip().removeprefix("file://"))
        assert stat.S_IMODE(forward.stat().st_mode) == 0o600
        assert stat.S_IMODE(forward.parent.stat().st_mode) == 0o700
        assert f'content="0;url={url}"' in forward.read_text()
    finally:
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=30)
    assert proc.returncode == 143 and not forward.exists()    # removed when fishgen exits


def test_quiet_still_gives_the_address_and_nothing_else(tmp_path):
    """`edit -q` served on a random port with a random token and said nothing (QA pass 15): --quiet
    drops the summary, not the one line the page can be opened by."""
    proc = subprocess.Popen([sys.executable, "-u", "-m", "fishgen", "edit", str(tmp_path / "x.awn"),
                             "--no-open", "-q"], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    try:
        import select

        ready, _, _ = select.select([proc.stdout], [], [], 30)     # nothing said: fail, not hang
        line = proc.stdout.readline() if ready else ""
        assert line.startswith("http://127.0.0.1:") and "token=" in line, line
    finally:
        proc.send_signal(signal.SIGTERM)
        out, _ = proc.communicate(timeout=30)
    assert out == ""            # the summary's other line stays unsaid
