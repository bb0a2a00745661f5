"""Where a render in perspective shows a fish's fins, laid on a photo's silhouette."""
import numpy as np

from fishgen.authoring.photo.compare import seen_fins
from fishgen.species.parser import load_species
from tests.conftest import PARAMS


def test_fins_are_seen_inside_the_silhouette_they_are_laid_on_and_an_empty_one_places_none(gl_available):
    bream = load_species(PARAMS / "bonybream.txt")
    target = np.zeros((90, 160), bool)
    target[30:60, 20:140] = True
    seen = seen_fins(bream, 160, 90, 2.2, target)
    assert {"caudal", "dorsal", "pectoral"} <= set(seen)
    every = np.concatenate(list(seen.values()))
    assert every[:, 0].min() >= 19 and every[:, 0].max() <= 141 and every[:, 1].min() >= 29
    assert seen_fins(bream, 160, 90, 2.2, np.zeros((90, 160), bool)) == {}   # no traceback, side-on instead
