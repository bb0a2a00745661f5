"""The --plot figure: labelled constants instead of magnified rounding, whole paths, one file."""
from __future__ import annotations

import numpy as np
import pytest

from fishgen.school.model import TargetPath
from fishgen.school.plot import _panel, _whole_path, plot_school
from fishgen.school.run import run_school
from fishgen.school.scene_file import SceneFile, SpeciesEntry
from tests.conftest import PARAMS

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
from matplotlib import pyplot as plt  # noqa: E402


def drawn(values, digits=1, scale=1.0):
    fig, ax = plt.subplots()
    times = np.arange(len(values)) / 30.0
    _panel(ax, times, [("turn", np.asarray(values, float))], ["a"], scale, digits, "title")
    texts = [t.get_text() for t in ax.texts]
    lines = [line.get_ydata() for line in ax.lines]
    plt.close(fig)
    return texts, lines


def test_a_panel_within_rounding_of_one_value_is_drawn_as_that_value():
    texts, lines = drawn(1e-16 * np.random.default_rng(0).random(90), digits=1)   # rounding noise
    assert texts == ["0.0 throughout"] and len(lines) == 1 and np.ptp(lines[0]) == 0
    texts, lines = drawn([1, 1, 1, 1], digits=0)
    assert texts == ["1 throughout"]
    texts, lines = drawn(np.linspace(0, 0.3, 90), digits=1)                        # a real change
    assert texts == [] and np.ptp(lines[0]) > 0.29


def test_the_whole_path_of_a_closed_curve_is_one_lap():
    loop = _whole_path(TargetPath(kind="figure8", radius=2.0, period=20.0), np.arange(300) / 30.0)
    assert np.allclose(loop[0], loop[-1]) and loop[:, 0].min() < -1.9 and loop[:, 0].max() > 1.9
    points = TargetPath(kind="points", points=((0, 0, 0, 0), (5, 1, 0, 2), (9, 3, 0, 0)))
    assert _whole_path(points, np.arange(10.0)).tolist() == [[0, 0, 0], [1, 0, 2], [3, 0, 0]]
    assert _whole_path(TargetPath(kind="none"), np.arange(10.0)) is None


def test_the_plot_is_written(tmp_path):
    run = run_school(SceneFile(species=(SpeciesEntry(PARAMS / "bonybream.txt", 10),), frames=40,
                               predator=TargetPath(kind="figure8", radius=1.0, period=20.0)))
    path = plot_school(tmp_path / "p.png", run, run.measures(every_frame=True))
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
