"""The editor's page: fishgen's one page (fishgen/web/page.py) with the editor's app."""
from __future__ import annotations

import re

from fishgen.editor.page import build_page
from fishgen.web.page import KIT, STATIC, bundle


def test_the_editor_app_is_bundled_with_its_cloud_view_and_without_three():
    import json

    inputs = json.loads((STATIC / "manifest.json").read_text())["bundles"]["editor"]["inputs"]
    assert sorted(inputs) == ["fishgen/editor/app.js", "fishgen/editor/cloudview.js"]


def test_the_page_inlines_the_kit_and_the_editor_and_escapes_the_file_name():
    page = build_page("<b>&.awn")
    assert "<title>&lt;b&gt;&amp;.awn · fishgen edit</title>" in page
    assert f"<script>\n{KIT.read_text(encoding='ascii')}\n</script>" in page
    assert f'<script type="module">\n{bundle("editor").read_text(encoding="ascii")}\n</script>' in page
    assert page.count("<script") == 2 and not re.search(r"<script[^>]+src=", page)
    assert '<body data-mode="particles">' in page
