"""Renders compared with the committed README images (docs/images), within a tolerance.

A change that turns a fish upside down, loses its texture or drops a fin must
fail here; the second half proves the tolerance catches exactly those. If a
change is *meant* to alter the look, run `python docs/make_renders.py`, look
at the images, and commit them.
"""
from __future__ import annotations

import copy
import importlib.util

import numpy as np
import pytest

from fishgen.preview.animation import Node
from tests.conftest import ROOT
from tests.preview.imagecompare import difference

pytestmark = pytest.mark.usefixtures("gl_available")

_spec = importlib.util.spec_from_file_location("make_renders", ROOT / "docs" / "make_renders.py")
make_renders = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(make_renders)
IMAGES = make_renders.IMAGES
STILLS = make_renders.stills()


@pytest.mark.parametrize("name,argv", STILLS, ids=[n for n, _ in STILLS])
def test_still_matches_readme_image(name, argv, tmp_path, monkeypatch):
    from fishgen.cli import main

    reference = IMAGES / name
    assert reference.is_file(), f"{reference} is missing: run python docs/make_renders.py"
    monkeypatch.chdir(ROOT)
    out = tmp_path / name
    main(["preview", *argv, "-o", str(out)])  # in-process: same code path as the script's CLI calls
    diff = difference(out, reference)
    assert diff.within_tolerance, (f"{name}: {diff}. If the new look is intended, run "
                                   "`python docs/make_renders.py` and commit docs/images/")


# --- the tolerance must catch the faults it exists for -----------------------------------------

@pytest.fixture(scope="module")
def bream():
    from fishgen.preview.inputs import load_input

    return load_input(ROOT / "params" / "bonybream.txt")


def _render(scene):
    from fishgen.preview.pipeline import PreviewOptions, parse_size, render_frames

    w, h = parse_size(make_renders.STILL_SIZE)
    images, _ = render_frames([scene], PreviewOptions(width=w, height=h), 1)
    return images[0][0]


def _upside_down(scene):
    s = copy.deepcopy(scene)
    roots = [i for i, n in enumerate(s.nodes) if n.parent is None]
    s.nodes.append(Node("flip", rotation=np.array([0.0, 0.0, 1.0, 0.0])))  # 180 degrees about the spine
    for i in roots:
        s.nodes[i].parent = len(s.nodes) - 1
    return s


def _untextured(scene):
    s = copy.deepcopy(scene)
    for m in s.meshes:
        m.material.texture = None
    return s


def _without(fin):
    def drop(scene):
        s = copy.deepcopy(scene)
        s.meshes = [m for m in s.meshes if fin not in s.nodes[m.node].name]
        assert len(s.meshes) < len(scene.meshes), f"bonybream has no {fin} fin any more"
        return s
    return drop


FAULTS = {"upside_down": _upside_down, "untextured": _untextured,
          "no_dorsal_fin": _without("dorsal"), "no_anal_fin": _without("anal")}


def test_unchanged_scene_is_within_tolerance(bream):
    diff = difference(_render(bream), IMAGES / "bonybream.png")
    assert diff.within_tolerance, str(diff)


@pytest.mark.parametrize("fault", FAULTS)
def test_tolerance_catches(fault, bream):
    diff = difference(_render(FAULTS[fault](bream)), IMAGES / "bonybream.png")
    assert not diff.within_tolerance, f"{fault} went unnoticed: {diff}"
