"""Round-trip fixtures: one rendered photo per shipped species, made once per session."""
from __future__ import annotations

import pytest

SHIPPED = ("bonybream", "centroberyx", "pineapplefish", "threadfingoldie")


@pytest.fixture(scope="session")
def photos():
    """species name -> (species, Photo)."""
    from fishgen.species.parser import load_species
    from tests.authoring.photos import render_photo
    from tests.conftest import PARAMS

    out = {}
    for name in SHIPPED:
        sp = load_species(PARAMS / f"{name}.txt")
        out[name] = (sp, render_photo(sp))
    return out
