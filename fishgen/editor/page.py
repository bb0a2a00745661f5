"""The editor's page: fishgen's page (fishgen/web/page.py) with the editor's app, which fetches
nothing but the server's routes."""
from __future__ import annotations

from fishgen.file_names import name_text
from fishgen.web.page import page_html


def build_page(name: str) -> str:
    """The page as HTML text; ``name`` (the file being edited) is its title."""
    return page_html("editor", name_text(name))     # a title, as text whatever the locale
