"""Species fin records -> geometry parameters (fishgen.assembly.fins)."""
from __future__ import annotations

import dataclasses

import pytest

from fishgen.assembly.fins import caudal_params, pectoral_params, pelvic_params, vertical_params
from fishgen.species.parser import parse_species
from tests.conftest import PARAMS

SPECIES = [parse_species(p.read_text(), str(p)) for p in sorted(PARAMS.glob("*.txt"))]


@pytest.mark.parametrize("sp", SPECIES, ids=lambda s: s.name)
def test_every_geometry_parameter_comes_from_the_same_named_species_field(sp):
    mapped = [(sp.caudal, caudal_params(sp.caudal)), (sp.dorsal, vertical_params(sp.dorsal)),
              (sp.adipose, vertical_params(sp.adipose)), (sp.anal, vertical_params(sp.anal)),
              (sp.pectoral, pectoral_params(sp.pectoral)), (sp.pelvic, pelvic_params(sp.pelvic))]
    for record, params in mapped:
        for field in dataclasses.fields(params):
            assert getattr(params, field.name) == getattr(record, field.name), field.name
