"""Ctrl-C and SIGTERM: one line on stderr, the shell's exit status, no partial or temp file."""
from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.conftest import PARAMS, ROOT


def _wait_for_handlers(proc: subprocess.Popen, seconds: float = 60.0) -> None:
    """Until fishgen has installed its SIGTERM handler (it does so with its SIGINT one, as its main
    starts): a signal before that is the interpreter's, not fishgen's. Linux shows the caught
    signals in /proc; elsewhere a fixed wait stands in."""
    status = Path(f"/proc/{proc.pid}/status")
    if not status.exists():
        time.sleep(2.0)
        return
    limit = time.monotonic() + seconds
    while time.monotonic() < limit and proc.poll() is None:
        caught = next((line.split()[1] for line in status.read_text().splitlines()
                       if line.startswith("SigCgt:")), "0")
        if int(caught, 16) >> (signal.SIGTERM - 1) & 1:
            return
        time.sleep(0.05)


@pytest.mark.parametrize("signum,status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupted_preview_says_one_line_and_leaves_nothing(tmp_path, signum, status):
    out = tmp_path / "long.gif"
    proc = subprocess.Popen([sys.executable, "-m", "fishgen", "preview", str(PARAMS / "bonybream.txt"),
                             "-o", str(out), "--duration", "60", "--size", "400x300"],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_for_handlers(proc)
    time.sleep(0.5)  # rendering: 720 frames take far longer
    proc.send_signal(signum)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == status and stderr == "fishgen: interrupted\n" and stdout == ""
    assert list(tmp_path.iterdir()) == []
