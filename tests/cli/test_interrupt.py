"""Ctrl-C and SIGTERM: one line on stderr, the shell's exit status, no partial or temp file."""
from __future__ import annotations

import signal
import subprocess
import sys
import time

import pytest

from tests.conftest import PARAMS, ROOT


@pytest.mark.parametrize("signum,status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupted_preview_says_one_line_and_leaves_nothing(tmp_path, signum, status):
    out = tmp_path / "long.gif"
    proc = subprocess.Popen([sys.executable, "-m", "fishgen", "preview", str(PARAMS / "bonybream.txt"),
                             "-o", str(out), "--duration", "60", "--size", "400x300"],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(2.0)  # loaded and rendering: 720 frames take far longer
    proc.send_signal(signum)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == status and stderr == "fishgen: interrupted\n" and stdout == ""
    assert list(tmp_path.iterdir()) == []
