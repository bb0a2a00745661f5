"""`fishgen view` in a real headless Chromium: the model loads, plays, and shows something.

Needs Debian's chromium (apt-get install chromium) and the `playwright` package
from the test extra; Playwright drives the system browser, never a downloaded one.
"""
from __future__ import annotations

import io
import queue
import re
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from tests.browser import browser as shared_browser
from tests.browser import frames, unavailable
from tests.conftest import ROOT, run_cli

pytestmark = pytest.mark.skipif(unavailable() is not None, reason=str(unavailable()))
LOAD_TIMEOUT_MS = 30_000


@pytest.fixture(scope="module")
def browser():
    return shared_browser()


@pytest.fixture
def served():
    """Start the real `fishgen view ASSET --port 0`; yields a function returning the page URL."""
    procs = []

    def start(asset: Path) -> str:
        proc = subprocess.Popen([sys.executable, "-u", "-m", "fishgen", "view", str(asset), "--port", "0"],
                                cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        procs.append(proc)
        lines: queue.Queue = queue.Queue()
        threading.Thread(target=lambda: [lines.put(printed) for printed in proc.stdout], daemon=True).start()
        while True:
            try:
                line = lines.get(timeout=20)
            except queue.Empty:
                pytest.fail(f"fishgen view printed no URL: {proc.stderr.read() if proc.poll() else ''}")
            if line.startswith("serving "):
                url = line.split()[1]
                assert url.startswith("http://127.0.0.1:")
                return url

    yield start
    for proc in procs:
        proc.terminate()
        proc.wait(timeout=10)


def _open(browser, url):
    page = browser.new_page(viewport={"width": 800, "height": 600})
    problems, requests = [], []
    page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: problems.append(str(e)))
    page.on("request", lambda r: requests.append(r.url))
    page.goto(url)
    page.wait_for_function(
        "window.fishgenViewer && (window.fishgenViewer.loaded || window.fishgenViewer.error)",
        timeout=LOAD_TIMEOUT_MS)
    state = page.evaluate("window.fishgenViewer")
    assert state["error"] is None, state["error"]
    return page, problems, requests


def _canvas(page) -> np.ndarray:
    shot = page.locator("#view").screenshot()
    return np.asarray(Image.open(io.BytesIO(shot)).convert("RGB"), np.float32)


def _assert_not_blank(img: np.ndarray) -> None:
    background = np.median(img.reshape(-1, 3), axis=0)
    subject = np.abs(img - background).max(-1) > 20
    assert img.std() > 5 and subject.mean() > 0.03, "the canvas shows (almost) nothing but background"


def _assert_offline(requests) -> None:
    outside = [u for u in requests if not u.startswith(("http://127.0.0.1", "blob:", "data:"))]
    assert not outside, f"the page fetched from outside: {outside[:5]}"


def test_fish_loads_plays_scrubs_and_toggles_wireframe(browser, served, viewer_assets):
    from fishgen.preview.inputs import load_input

    page, problems, requests = _open(browser, served(viewer_assets["fish"]))
    try:
        state = page.evaluate("window.fishgenViewer")
        expected = load_input(viewer_assets["fish"]).counts()
        assert state["counts"] == expected
        assert state["clips"] == ["swim"] and state["playing"]
        assert page.locator("#counts").inner_text().startswith(f"{expected['vertices']:,} vertices")
        t0 = page.evaluate("window.fishgenViewer.time")
        page.wait_for_function(f"window.fishgenViewer.time != {t0}", timeout=LOAD_TIMEOUT_MS)  # it advances
        img = _canvas(page)
        _assert_not_blank(img)

        page.click("#play")  # pause holds the time still
        paused = page.evaluate("window.fishgenViewer.time")
        frames(page, 10)
        assert page.evaluate("window.fishgenViewer.time") == paused
        page.fill("#time", "2")  # the scrubber poses the clip
        page.dispatch_event("#time", "input")
        assert page.evaluate("window.fishgenViewer.time") == pytest.approx(2.0)

        page.check("#wireframe")
        frames(page)
        assert np.abs(_canvas(page) - img).mean() > 1, "wireframe should change the picture"
        assert problems == []
        _assert_offline(requests)
    finally:
        page.close()


@pytest.fixture(scope="module")
def cli_clouds(tmp_path_factory):
    """Table 4.4 through the real `fishgen clouds`, as points and as billboards, with the count it prints."""
    folder = tmp_path_factory.mktemp("clouds")
    made = {}
    for form, flags in (("points", []), ("billboards", ["--billboards"])):
        out = folder / f"{form}.glb"
        result = run_cli("clouds", ROOT / "params" / "clouds" / "table_4_4.awn", "-o", out, *flags)
        assert result.returncode == 0, result.stderr
        made[form] = (out, int(re.search(r"(\d+) particles", result.stdout)[1]))
    return made


@pytest.mark.parametrize("form", ["billboards", "points"])
def test_cloud_from_the_cli_shows_its_particles_and_the_count_it_printed(browser, served, cli_clouds, form):
    """The cloud drawn, its particles counted as `fishgen clouds` printed them, and no clip to play.
    A billboard cloud is a mesh of one textured quad per particle: its quads are the particles."""
    asset, particles = cli_clouds[form]
    assert particles > 0
    page, problems, requests = _open(browser, served(asset))
    try:
        expected = {"vertices": 0, "triangles": 0, "particles": particles}
        assert page.evaluate("window.fishgenViewer.counts") == expected
        assert page.evaluate("window.fishgenViewer.clips") == [] and page.locator("#play").is_disabled()
        assert page.locator("#counts").inner_text() == f"0 vertices · 0 triangles · {particles:,} particles"
        frames(page)
        _assert_not_blank(_canvas(page))
        assert problems == []
        _assert_offline(requests)
    finally:
        page.close()


def test_a_triangle_with_the_cloud_material_is_still_a_mesh(browser, tmp_path):
    # The billboard rule needs the shape too (4 vertices and 6 indices per quad), not just the name.
    import base64
    import json

    from fishgen.viewer.page import write_page

    data = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32).tobytes() + np.array(
        [0, 1, 2, 0], np.uint16).tobytes()
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
           "nodes": [{"mesh": 0, "name": "cloud"}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
           "materials": [{"name": "cloud particle"}],
           "buffers": [{"byteLength": len(data),
                        "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
           "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                          "min": [0, 0, 0], "max": [1, 1, 0]},
                         {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]}
    asset = tmp_path / "triangle.gltf"
    asset.write_text(json.dumps(doc))
    page, problems, _ = _open(browser, write_page(asset).as_uri())
    try:
        assert page.evaluate("window.fishgenViewer.counts") == {"vertices": 3, "triangles": 1, "particles": 0}
        assert problems == []
    finally:
        page.close()


def test_page_works_from_disk_without_a_server(browser, viewer_assets):
    from fishgen.viewer.page import write_page

    page_file = write_page(viewer_assets["obj"])
    page, problems, requests = _open(browser, page_file.as_uri())
    try:
        assert page.evaluate("window.fishgenViewer.counts.triangles") > 0
        _assert_not_blank(_canvas(page))
        assert problems == []
        assert all(u.startswith(("file:", "blob:", "data:")) for u in requests), requests
    finally:
        page.close()


def test_a_school_plays_and_its_fish_move_in_three_js(browser, served, tmp_path):
    from fishgen.preview.inputs import load_input

    school = tmp_path / "school.glb"
    made = run_cli("school", ROOT / "params" / "bonybream.txt", "-o", school,
                   "--count", "12", "--frames", "150", "--seed", "2")
    assert made.returncode == 0, made.stderr
    page, problems, requests = _open(browser, served(school))
    try:
        state = page.evaluate("window.fishgenViewer")
        assert state["clips"] == ["school"] and state["counts"] == load_input(school).counts()
        page.click("#play")                       # pause, then pose two moments of the clip
        shots = []
        for t in ("0.5", "4.5"):
            page.fill("#time", t)
            page.dispatch_event("#time", "input")
            frames(page)
            shots.append(_canvas(page))
        _assert_not_blank(shots[0])
        moved = np.abs(shots[1] - shots[0]).max(-1) > 30
        assert moved.mean() > 0.01, "the fish should be elsewhere four seconds later"
        assert problems == []
        _assert_offline(requests)
    finally:
        page.close()


def _lit_cloud_page(folder, sun, billboards):
    from fishgen.clouds import Lighting, export_cloud, fill_cloud, light_cloud, load_cubes
    from fishgen.viewer.page import write_page

    cloud = light_cloud(fill_cloud(load_cubes(ROOT / "params" / "clouds" / "table_4_4.awn"), seed=0),
                        Lighting(sun=sun))
    asset = folder / f"lit_{'billboards' if billboards else 'points'}_{sun[0]:+g}.glb"
    export_cloud(cloud, asset, billboards=billboards)
    return write_page(asset).as_uri(), len(cloud)


@pytest.mark.parametrize("billboards", [False, True], ids=["points", "billboards"])
def test_a_lit_cloud_gets_the_second_pass_and_follows_its_sun(browser, tmp_path, billboards):
    """The viewer reads the sun from the file and scatters each particle's baked light towards the
    eye: the same cloud lit from the left or from the right looks brighter on that side."""
    sides = {}
    for sun in ((-1, 0.2, 0.3), (1, 0.2, 0.3)):
        url, particles = _lit_cloud_page(tmp_path, sun, billboards)
        page, problems, _ = _open(browser, url)
        try:
            state = page.evaluate("window.fishgenViewer")
            assert state["cloudLight"] is not None and state["counts"]["particles"] == particles
            page.evaluate("() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))")
            img = _canvas(page)
            _assert_not_blank(img)
            lum = img @ np.array([0.2126, 0.7152, 0.0722])
            background = np.median(lum)
            cloud = np.abs(lum - background) > 8
            xs = np.nonzero(cloud)[1]
            left = np.arange(img.shape[1])[None, :] < (xs.min() + xs.max()) / 2
            sides[sun[0]] = lum[cloud & left].mean() / lum[cloud & ~left].mean()
            assert problems == []
        finally:
            page.close()
    assert sides[-1] > sides[1] + 0.03


def test_an_obj_named_with_spaces_shows_its_texture(browser, tmp_path):
    """`build -o "my fish.obj"`: the page carries `my fish.mtl` and `my fish_skin.png`, and
    three.js's loaders, which read a map's whole name, find them in it (QA pass 10)."""
    from fishgen.viewer.page import write_page

    asset = tmp_path / "my fish.obj"
    assert run_cli("build", ROOT / "params" / "bonybream.txt", "-o", asset).returncode == 0
    page, problems, requests = _open(browser, write_page(asset).as_uri())
    try:
        assert page.evaluate("window.fishgenViewer.counts.triangles") > 0
        img = _canvas(page)
        _assert_not_blank(img)
        # the skin's colours, not the untextured grey: the subject's pixels vary in hue
        background = np.median(img.reshape(-1, 3), axis=0)
        subject = img[np.abs(img - background).max(-1) > 20]
        assert np.ptp(subject, axis=0).max() > 60
        assert problems == []
    finally:
        page.close()


def test_the_camera_answers_the_keys_and_every_control_has_a_name(browser, viewer_assets, tmp_path):
    """The view took no focus and the camera no key, and the clip list and the timeline were named by
    their tooltips alone (QA pass 22). Once the view has the focus: + and - zoom, arrows pan,
    Shift+arrows orbit."""
    from fishgen.viewer.page import write_page

    page, problems, _ = _open(browser, write_page(viewer_assets["fish"], tmp_path / "v.html").as_uri())
    try:
        assert page.get_by_role("combobox", name="Animation clip", exact=True).count() == 1
        assert page.get_by_role("slider", name="Time in the clip", exact=True).count() == 1
        page.click("#play")                    # paused: only the keys move the picture
        frames(page)
        view = page.locator("#view")
        view.focus()
        assert page.evaluate("document.activeElement.id") == "view"
        before = _canvas(page)
        for key in ("+", "+", "ArrowLeft", "Shift+ArrowUp"):
            shown = _canvas(page)
            view.press(key)
            frames(page, 3)
            assert np.abs(_canvas(page) - shown).mean() > 0.5, f"{key} left the picture as it was"
        assert np.abs(_canvas(page) - before).mean() > 1
        assert problems == []
    finally:
        page.close()
