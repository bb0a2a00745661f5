"""Per-column measures of a silhouette: the run of fish through a given row."""
from __future__ import annotations

import warnings

import numpy as np

from fishgen.authoring.photo.columns import run_through


def test_the_run_through_a_row_spans_the_fish_pixels_around_it():
    mask = np.zeros((10, 3), bool)
    mask[2:6, 0] = True
    mask[7:9, 1] = True
    top, bottom = run_through(mask, np.array([3.5, 8.5, 4.5]))
    assert top[:2].tolist() == [2, 7] and bottom[:2].tolist() == [6, 9]
    assert np.isnan(top[2]) and np.isnan(bottom[2])            # background there


def test_a_column_with_no_row_has_no_run_even_where_its_top_pixel_is_fish():
    """A NaN row (a fin place an outline too thin could not give) used to be cast to an int, which
    is undefined: on x86 it became row 0, and a fish pixel there gave the column a run."""
    mask = np.ones((6, 2), bool)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        top, bottom = run_through(mask, np.array([np.nan, 2.5]))
    assert np.isnan(top[0]) and np.isnan(bottom[0])
    assert (top[1], bottom[1]) == (0, 6)
