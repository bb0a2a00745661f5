"""The real `fishgen edit` page in headless Chromium (the system's, driven by Playwright), for the
tests, the README's screenshot and the benchmark."""
from __future__ import annotations

import queue
import subprocess
import sys
import threading
from contextlib import contextmanager
from pathlib import Path

from tests.browser import browser as shared_browser
from tests.browser import close as close_browser
from tests.browser import unavailable  # noqa: F401 - the editor tests ask here

ROOT = Path(__file__).resolve().parents[2]
TIMEOUT_MS = 60_000


@contextmanager
def chromium():
    """The shared Chromium (:mod:`tests.browser`) for a script outside pytest, closed after."""
    try:
        yield shared_browser()
    finally:
        close_browser()


def serve_editor(file: Path, *args: str) -> tuple[subprocess.Popen, str]:
    """`fishgen edit FILE --no-open --port 0 ARGS...` started: the process and the page's address."""
    proc = subprocess.Popen([sys.executable, "-u", "-m", "fishgen", "edit", str(file), "--no-open",
                             "--port", "0", *args], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    lines: queue.Queue = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in proc.stdout], daemon=True).start()
    try:
        return proc, lines.get(timeout=60).strip()
    except queue.Empty:
        proc.kill()
        raise RuntimeError(f"fishgen edit printed no address: {proc.stderr.read()}") from None


def stop(proc: subprocess.Popen) -> None:
    """End a :func:`serve_editor` process (killed if it has not ended 10 s after being asked)."""
    proc.terminate()
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


class EditorPage:
    """`fishgen edit FILE --no-open --port 0 ARGS...` and its page, loaded and ready."""

    def __init__(self, browser, file: Path, *args: str, viewport=(1280, 800)):
        self.file = Path(file)
        self.proc, self.url = serve_editor(file, *args)
        self.errors: list[str] = []
        self.dialogs: list[str] = []
        self.page = browser.new_page(viewport={"width": viewport[0], "height": viewport[1]})
        self.page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))
        self.requests: list[str] = []
        self.page.on("request", lambda r: self.requests.append(r.url))
        self.page.goto(self.url)
        self.page.wait_for_function("window.fishgenEditor && (fishgenEditor.ready || fishgenEditor.error)",
                                    timeout=TIMEOUT_MS)
        if self.state("error"):
            raise RuntimeError(f"the editor did not start: {self.state('error')}")

    def state(self, expression: str):
        """``fishgenEditor.<expression>`` evaluated in the page."""
        return self.page.evaluate(f"fishgenEditor.{expression}")

    def settle(self) -> None:
        """Wait until every fill asked for is shown, and a frame after it."""
        self.page.wait_for_function("fishgenEditor.fill.shown === fishgenEditor.fill.sent && "
                                    "!fishgenEditor.fill.busy", timeout=TIMEOUT_MS)
        frames = self.state("frames")
        self.page.evaluate("() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
        self.page.wait_for_function(f"fishgenEditor.frames >= {frames}", timeout=TIMEOUT_MS)

    def field(self, label: str):
        return self.page.get_by_label(label, exact=True)

    def button(self, name: str):
        return self.page.get_by_role("button", name=name, exact=True)

    def close(self) -> None:
        try:
            self.page.close()
        finally:
            stop(self.proc)
