"""A contact sheet's labels: drawn in the characters the font has."""
from PIL import Image, ImageChops

from fishgen.preview.sheet import contact_sheet


def sheet(label: str) -> Image.Image:
    tile = Image.new("RGBA", (160, 120), (90, 140, 200, 255))
    return contact_sheet([tile], [label], None, (240, 240, 240, 255)).convert("RGB")


def same(a: Image.Image, b: Image.Image) -> bool:
    return ImageChops.difference(a, b).getbbox() is None


def test_an_accented_name_is_drawn_without_its_accents_not_as_empty_boxes():
    assert same(sheet("pòisson"), sheet("poisson")) and same(sheet("naïve"), sheet("naive"))


def test_what_has_no_ascii_form_is_a_question_mark_and_ascii_is_unchanged():
    from fishgen.preview.sheet import drawable

    assert same(sheet("東"), sheet("?")) and drawable("東京 fish") == "?? fish"
    assert drawable("bonybream_00012 (LOD1)") == "bonybream_00012 (LOD1)"
