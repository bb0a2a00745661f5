"""A `fishgen school` drawn instanced (fishgen/web/schools.js) in `fishgen view` and `fishgen fly`:
one instanced mesh per species and material, the same picture and the same fish positions as the
node-per-fish drawing, and that drawing back with --no-instancing or ?instancing=0.

Needs Debian's chromium and the `playwright` package (the test extra), as every browser test does.
"""
from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from fishgen.viewer.page import write_page
from tests.browser import browser as shared_browser
from tests.browser import frames, unavailable
from tests.conftest import PARAMS, run_cli

pytestmark = pytest.mark.skipif(unavailable() is not None, reason=str(unavailable()))
LOAD_MS = 120_000
MEAN_DIFFERENCE = 1.0
"""Most mean absolute difference (0-255 levels) over the pixels that show a fish in either, between
the instanced and the node-per-fish drawing of one moment; measured 0.0003-0.0013 (tinted, body
wave) and 0.03-0.15 (translucent fins, drawn in another order); two seconds apart: 57-66."""


def school(folder, name, *args):
    path = folder / f"{name}.glb"
    made = run_cli("school", PARAMS / "bonybream.txt", "-o", path, "--frames", "150", "--seed", "2", *args)
    assert made.returncode == 0, made.stderr
    return path


@pytest.fixture(scope="module")
def schools(tmp_path_factory):
    folder = tmp_path_factory.mktemp("schools")
    return {"small": school(folder, "small", "--count", "12", "--tints", "3"),
            "thousand": school(folder, "thousand", "--count", "1000", "--frames", "60"),
            "translucent": school(folder, "translucent", "--count", "12", "--fins", "blend",
                                  "--swim", "fins"),
            "merged": school(folder, "merged", "--count", "6", "--merge"),
            "reef": _reef(folder)}


def _reef(folder):
    path = folder / "reef.glb"
    made = run_cli("school", PARAMS / "reef.toml", "-o", path, "--frames", "60")
    assert made.returncode == 0, made.stderr
    return path


def open_view(asset, query="", instancing=True):
    """The viewer page of ``asset``, from disk, loaded and paused; and the console's errors."""
    page_file = write_page(asset, asset.with_name(f"{asset.stem}-{int(instancing)}.html"),
                           instancing=instancing)
    tab = shared_browser().new_page(viewport={"width": 800, "height": 600})
    problems: list[str] = []
    tab.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
    tab.on("pageerror", lambda e: problems.append(str(e)))
    tab.goto(page_file.as_uri() + query)
    tab.wait_for_function("window.fishgenViewer.loaded || window.fishgenViewer.error", timeout=LOAD_MS)
    assert tab.evaluate("window.fishgenViewer.error") is None
    # pause: each moment is posed by the time slider. Clicked from the page, not by Playwright, whose
    # click waits for the button to hold still over two frames: 6 s of a thousand fish in software GL
    # (the button itself is clicked in tests/viewer)
    tab.evaluate("document.querySelector('#play').click()")
    assert not tab.evaluate("window.fishgenViewer.playing")
    return tab, problems


def difference(a: np.ndarray, b: np.ndarray) -> float:
    """Mean absolute difference over the pixels where either picture differs from the background."""
    background = np.median(a.reshape(-1, 3), axis=0)
    subject = (np.abs(a - background).max(-1) > 10) | (np.abs(b - background).max(-1) > 10)
    assert subject.mean() > 0.01, "no fish in view"
    return float(np.abs(a - b)[subject].mean())


def show(tab, t: float) -> None:
    """Show the clip at ``t`` seconds, drawn."""
    tab.fill("#time", str(t))
    tab.dispatch_event("#time", "input")
    frames(tab, 3)


def pose(tab, t: float) -> np.ndarray:
    """Show the clip at ``t`` seconds; the canvas as RGB."""
    show(tab, t)
    shot = tab.locator("#view").screenshot()
    return np.asarray(Image.open(io.BytesIO(shot)).convert("RGB"), np.float32)


def drawn(asset, query="", instancing=True) -> dict:
    """What the viewer drew of ``asset`` at one second: its instanced species, fish and meshes, its
    counts, and its draw calls; the page showed no error."""
    tab, problems = open_view(asset, query, instancing)
    try:
        show(tab, 1.0)
        state = tab.evaluate("({...window.fishgenViewer.instanced, counts: window.fishgenViewer.counts, "
                             "calls: window.fishgenViewer.calls})")
        assert problems == []
        return state
    finally:
        tab.close()


def test_a_thousand_fish_of_one_species_are_two_draw_calls(schools):
    state = drawn(schools["thousand"])
    assert (state["species"], state["fish"], state["meshes"]) == (1, 1000, 2) and state["calls"] <= 2
    assert state["counts"]["vertices"] == 1000 * 227   # counted as the file holds it: nine parts a fish


def test_two_species_are_two_draw_calls_each(schools):
    state = drawn(schools["reef"])
    assert state["species"] == 2 and state["calls"] <= 4


@pytest.mark.parametrize("kind", ["small", "translucent"])
def test_instanced_frames_match_the_node_per_fish_drawing(schools, kind):
    """Tinted fish with the body wave, and translucent fins on a rigid body, at three moments."""
    instanced, problems = open_view(schools[kind])
    nodes, node_problems = open_view(schools[kind], instancing=False)
    try:
        assert instanced.evaluate("window.fishgenViewer.instanced.fish") == 12
        assert nodes.evaluate("window.fishgenViewer.instanced.fish") == 0
        shots = {t: (pose(instanced, t), pose(nodes, t)) for t in (0.5, 2.5, 4.5)}
        for t, (a, b) in shots.items():
            assert difference(a, b) < MEAN_DIFFERENCE, f"t={t}: mean difference {difference(a, b):.3f}"
        # the measure sees a moment's change: the same drawing two seconds apart differs far more
        assert difference(shots[0.5][1], shots[2.5][1]) > 20 * MEAN_DIFFERENCE
        assert problems == [] and node_problems == []
    finally:
        instanced.close()
        nodes.close()


def test_fish_stand_where_the_files_tracks_put_them(schools):
    from fishgen.exchange.gltf_reader import read_gltf
    from fishgen.scene.pose import sample

    scene = read_gltf(schools["small"])
    clip = scene.clip("school")
    moves = {scene.nodes[c.node].name: c for c in clip.channels if c.path == "translation"}
    tab, _ = open_view(schools["small"])
    try:
        for t in (0.0, 1.7, 4.9):
            show(tab, t)
            (drawn,) = tab.evaluate("window.fishgenViewer.instances()")
            assert drawn["species"] == "bonybream" and len(drawn["fish"]) == 12
            expected = np.array([sample(moves[name], t) for name in drawn["fish"]])
            assert np.abs(np.array(drawn["positions"]) - expected).max() < 1e-5
    finally:
        tab.close()


def test_no_instancing_and_the_address_flag_draw_fish_by_fish(schools):
    for query, instancing in (("", False), ("?instancing=0", True)):
        state = drawn(schools["small"], query, instancing)
        assert state["species"] == 0 and state["calls"] == 12 * 9


def test_a_school_of_skinned_fish_stays_node_by_node(schools):
    state = drawn(schools["merged"])
    assert state["species"] == 0 and state["calls"] == 6 * 2   # --merge: two draw calls a fish


@pytest.mark.parametrize("instancing", [True, False])
def test_fly_draws_a_school_instanced_unless_told_not_to(schools, instancing):
    from fishgen.fly.assets import Asset
    from fishgen.fly.session import FlyConfig, FlySession

    # the thousand fish instanced; node by node, a small school shows the same path (a thousand fish
    # drawn part by part took 9-12 s of a software renderer)
    asset = Asset("school", schools["thousand" if instancing else "small"].read_bytes(), "glb")
    # frames are counted once the warm-up is over: a tenth of a second, not the default two
    session = FlySession([asset], FlyConfig(size=(640, 480), warmup=0.1, path="still", instancing=instancing))
    session.serve_in_background()
    tab = shared_browser().new_page(viewport={"width": 640, "height": 480})
    try:
        tab.goto(session.url())
        tab.wait_for_function("window.fishgenFly.loaded && window.fishgenFly.frames > 1 "
                              "|| window.fishgenFly.error", timeout=LOAD_MS)
        state = tab.evaluate("({error: window.fishgenFly.error, instanced: window.fishgenFly.instanced, "
                             "meshes: window.fishgenFly.counts.meshes, "
                             "calls: window.fishgenFly.meshCalls()})")
        assert state["error"] is None and state["meshes"] == (9000 if instancing else 12 * 9)
        if instancing:
            assert state["instanced"] == {"species": 1, "fish": 1000, "meshes": 2} and 0 < state["calls"] <= 2
        else:
            assert state["instanced"]["species"] == 0 and state["calls"] > 12   # the fish in view, each part
    finally:
        tab.close()
        session.close()
