"""A fitted fish must be whole (issue 25): fins attached over the swim clip, none taller than the
photographed fish, the caudal fin on the tail, a body that does not cross itself. Each check is
shown to pass the shipped species and to catch the fault it names."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from fishgen.authoring.photo.checks import (
    attachment_problems,
    body_problems,
    caudal_problems,
    fit_problems,
    height_problems,
)
from fishgen.species.parser import load_species
from tests.authoring.conftest import SHIPPED
from tests.conftest import PARAMS


@pytest.fixture(scope="module")
def bream():
    return replace(load_species(PARAMS / "bonybream.txt"), texture_points=None)


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_species_are_whole(name):
    assert fit_problems(load_species(PARAMS / f"{name}.txt")) == []


def test_a_pectoral_fin_swinging_off_the_body_is_caught(bream):
    """Hinged on the line from its first to its last base point, a fin based on half a ring lifts
    its middle off the flank as it swings."""
    bad = replace(bream, pectoral=replace(bream.pectoral, triangles=6, movement_angle=45.0, step_size=3.0))
    (problem,) = attachment_problems(bad)
    assert problem.startswith("the left pectoral fin comes off the body while swimming")


def test_a_caudal_fin_off_the_tail_is_caught(bream):
    bad = replace(bream, caudal=replace(bream.caudal, connection=(1.2, 0.0, 0.0)))
    assert "caudal fin is off the tail" in caudal_problems(bad)[0]
    forward = replace(bream, caudal=replace(bream.caudal, top_angle=120.0))
    assert "points forward" in caudal_problems(forward)[0]


def test_a_body_pinched_to_nothing_is_caught(bream):
    # a control point on BodySection 7 of 16 (x = 7/15) with a radius of nothing
    pinched = replace(bream, shape_class="FishShapeSpline",
                      shape_params=(0.3, 0.5, 7 / 15, 1e-9, 0.7, 0.5))
    assert "pinches to nothing at BodySection 7" in body_problems(pinched)[0]
    assert body_problems(replace(bream, shape_class="FishShapeSpline", shape_params=(0.5, 0.5))) == []


def test_a_fin_taller_than_the_photographed_fish_is_caught(bream, gl_available, photos):
    """Fitted to BonyBream's own photo, then its dorsal fin made three times as long."""
    from fishgen.authoring.photo.fit import fit_species

    _, photo = photos["bonybream"]
    fit = fit_species(bream, photo.rgba[:, :, 3] >= 64)
    assert height_problems(fit.species, fit.work, fit.placement) == []
    d = fit.species.dorsal
    tall = replace(fit.species, dorsal=replace(d, start_length=3 * d.start_length))
    (problem,) = height_problems(tall, fit.work, fit.placement)
    assert problem.startswith("the dorsal fin stands") and "past the photo's fish" in problem
    assert np.isfinite(fit.iou)
