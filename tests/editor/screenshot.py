"""The README's picture of the editor, taken from the real page in headless Chromium:

    python -m tests.editor.screenshot docs/images/editor.png [CUBES.awn]
"""
from __future__ import annotations

import sys
from pathlib import Path

from tests.editor.browser import ROOT, EditorPage, chromium

FILE = ROOT / "params" / "clouds" / "table_4_4.awn"


def screenshot(browser, file: Path, out: Path, size=(1280, 720)) -> Path:
    """``file`` opened in the editor, previewed, its first cube selected (red, with its handles)."""
    ed = EditorPage(browser, file, viewport=size)
    try:
        ed.button("Preview").click()
        ed.settle()
        ed.page.get_by_label("Cube", exact=True).select_option("0")
        ed.page.locator("#view").focus()
        ed.settle()
        if ed.errors:
            raise RuntimeError(f"the page reported errors: {ed.errors}")
        ed.page.screenshot(path=str(out))
    finally:
        ed.close()
    return out


def main(argv: list[str]) -> int:
    out = Path(argv[0]) if argv else ROOT / "docs" / "images" / "editor.png"
    file = Path(argv[1]) if len(argv) > 1 else FILE
    with chromium() as browser:
        screenshot(browser, file, out)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
