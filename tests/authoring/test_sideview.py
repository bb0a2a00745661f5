"""A species' side view: every vertex the file names, measured as the fish is built."""
from __future__ import annotations

import numpy as np

from fishgen.authoring.photo.anatomy import calibrate
from fishgen.authoring.photo.sideview import rasterize, side_view
from fishgen.species.parser import load_species
from tests.conftest import PARAMS


def test_every_named_vertex_is_kept_but_the_fish_is_drawn_as_built():
    """BonyBream's anal and adipose fins are built shorter than its file names them (they end in
    front of the caudal fin): the texture points keep one per named vertex, and the raster the
    photo is calibrated against shows the shorter fins, as its photo does."""
    sp = load_species(PARAMS / "bonybream.txt")
    view = side_view(sp)
    assert len(view.fins["anal"]) == sp.anal.texture_point_count
    assert len(view.fins["adipose"]) == sp.adipose.texture_point_count
    tail_front = view.shown_fins["caudal"][:, 0].min()
    for name in ("anal", "adipose"):
        assert view.fins[name][:, 0].max() > tail_front   # as named: over the peduncle
        assert view.shown_fins[name][:, 0].max() <= tail_front + 1e-9
    mask, origin = rasterize(view, 2000.0)
    behind = np.ceil(origin[0] + tail_front * 2000.0).astype(int) + 2
    rows = np.flatnonzero(mask[:, behind:].any(axis=1))
    caudal_rows = origin[1] - view.shown_fins["caudal"][:, 1] * 2000.0
    assert rows.min() >= caudal_rows.min() - 2 and rows.max() <= caudal_rows.max() + 2


def test_a_symmetric_tail_calibrates_its_base_on_the_axis():
    """The whole fins over BonyBream's peduncle made its tail base look 0.8 % of the length low,
    which tilted and misplaced every texture point by 1-2 px (round trips at IoU 0.958)."""
    cal = calibrate(side_view(load_species(PARAMS / "bonybream.txt")), 572.0)
    assert abs(cal.tail_drop) < 0.002, cal
