"""Lay renders out as a labelled contact sheet (Pillow only)."""
from __future__ import annotations

import math

from PIL import Image, ImageDraw, ImageFont


def label_height(tile_height: int) -> int:
    return max(16, tile_height // 14)


def grid(tiles: int, columns: int | None) -> tuple[int, int]:
    """(columns, rows) of a sheet of ``tiles``: about square unless ``columns`` is given, and never
    more columns than tiles (``--columns 10**12`` for two inputs sized a sheet of 8e14 pixels)."""
    columns = min(columns or math.ceil(math.sqrt(tiles)), max(tiles, 1))
    return columns, math.ceil(tiles / columns)


def contact_sheet(tiles: list[Image.Image], labels: list[str], columns: int | None,
                  background: tuple[int, int, int, int]) -> Image.Image:
    """Grid of equally sized ``tiles``, each with its label in a strip below it."""
    columns, rows = grid(len(tiles), columns)
    w, h = tiles[0].size
    strip = label_height(h)
    sheet = Image.new("RGBA", (columns * w, rows * (h + strip)), background)
    draw = ImageDraw.Draw(sheet)
    font = _font(int(strip * 0.7))
    # Text colour picked against the background so labels stay readable on any --background.
    r, g, b, a = background
    ink = (20, 24, 28, 255) if a < 128 or (0.299 * r + 0.587 * g + 0.114 * b) > 140 else (245, 245, 245, 255)
    for k, (tile, shown) in enumerate(zip(tiles, labels, strict=True)):
        label = drawable(shown)
        x, y = (k % columns) * w, (k // columns) * (h + strip)
        sheet.paste(tile, (x, y))
        box = draw.textbbox((0, 0), label, font=font)
        draw.text((x + (w - (box[2] - box[0])) / 2, y + h + (strip - (box[3] - box[1])) / 2 - box[1]),
                  label, fill=ink, font=font)
    return sheet


def drawable(label: str) -> str:
    """``label`` in the characters Pillow's default font draws (ASCII): accents dropped
    (``pòisson`` is ``poisson``), anything else ``?``, where the font drew an empty box."""
    import unicodedata

    if label.isascii():
        return label
    bare = "".join(c for c in unicodedata.normalize("NFKD", label) if not unicodedata.combining(c))
    return "".join(c if c.isascii() and c.isprintable() else "?" for c in bare)


def _font(size: int):
    try:
        return ImageFont.load_default(size=size)  # Pillow >= 10.1 ships a scalable default
    except TypeError:
        return ImageFont.load_default()
