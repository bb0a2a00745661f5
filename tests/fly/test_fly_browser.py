"""`fishgen fly` in a real headless Chromium: reports, Pakawan's keys, culling, levels and sorting."""
from __future__ import annotations

import csv
import json
import math
import threading

import pytest

from fishgen.commands.fly import FlyOptions, fly
from fishgen.commands.sky import SkyOptions, sky
from fishgen.errors import MissingDependency
from fishgen.fly.assets import prepare_assets
from fishgen.fly.session import FlyConfig, FlySession
from tests.browser import browser as shared_browser
from tests.browser import close as close_browser
from tests.browser import frames
from tests.conftest import PARAMS
from tests.fly.conftest import needs_chromium

pytestmark = needs_chromium


@pytest.fixture(scope="module")
def thin_sky(tmp_path_factory):
    path = tmp_path_factory.mktemp("sky") / "thin.glb"
    made = sky((), path, SkyOptions(mode="thin", seed=2))
    return path, made.facts


def test_a_cube_file_flown_headless_reports_its_particles_and_frames(tmp_path, cli):
    report = tmp_path / "r.json"
    run = cli("fly", PARAMS / "clouds" / "table_4_4.awn", "--headless", "--timeout", "1", "--warmup", "0.1",
              "--report", report)
    assert run.returncode == 0, run.stderr
    r = json.loads(report.read_text())
    assert r["scene"]["particles"] == 615 and r["scene"]["clouds"] == 1 and r["frames"] > 0
    assert r["window"] == {"width": 800, "height": 600} and r["seconds"] >= 1
    assert r["fps"]["min"] <= r["fps"]["p5"] <= r["fps"]["median"] <= r["fps"]["max"]
    assert r["renderer"] and r["fishgen"] and r["headless"] is True and "--disable-gpu-vsync" in r["flags"]
    assert "FPS median" in run.stdout and "615 particles" in run.stdout


def test_a_port_chromium_will_not_open_is_said_in_one_line_without_the_token(cli):
    """Chromium refuses some ports outright (X11's 6000, 10080): one line saying so and what to give,
    not Playwright's traceback; the page's address, which holds its token, is left out."""
    import socket

    def free(port: int) -> bool:
        with socket.socket() as s:
            try:
                s.bind(("127.0.0.1", port))
            except OSError:
                return False
            return True

    port = next(p for p in (6000, 10080, 6665, 6697) if free(p))
    run = cli("fly", PARAMS / "clouds" / "table_4_4.awn", "--headless", "--timeout", "1", "--port", str(port))
    assert run.returncode == 1 and run.stderr.count("\n") == 1 and "Traceback" not in run.stderr, run.stderr
    assert run.stderr.startswith(f"fishgen: expected Chromium to open the page on port {port}, found "
                                 "net::ERR_UNSAFE_PORT; try another --port"), run.stderr
    assert "token" not in run.stderr


def test_a_chromium_that_will_not_start_is_said_once(cli, monkeypatch):
    monkeypatch.setenv("FISHGEN_CHROMIUM", "/bin/false")
    run = cli("fly", PARAMS / "clouds" / "table_4_4.awn", "--headless", "--timeout", "1")
    assert run.returncode == 1 and run.stderr.startswith("fishgen: cannot start Chromium ("), run.stderr
    assert run.stderr.count("\n") == 1


def test_a_mode_alone_flies_a_sky_of_that_mode_and_reports_it_per_second_in_csv(tmp_path, cli):
    """`fly --mode thin` with no file flies the thin sky (20,000 particles in 16 clouds); its CSV
    report has a row per second flown. (A sky's .glb is flown from a file below, in a page.)"""
    report = tmp_path / "r.csv"
    run = cli("fly", "--mode", "thin", "--headless", "--timeout", "2", "--warmup", "0.1", "--size", "640x480",
              "--report", report)
    assert run.returncode == 0, run.stderr
    assert "20,000 particles in 16 clouds" in run.stdout, run.stdout
    rows = list(csv.DictReader(report.open()))
    assert len(rows) >= 2 and [r["second"] for r in rows[:2]] == ["0", "1"]
    assert all(r["particles_in_scene"] == "20000" for r in rows)
    assert sum(int(r["frames"]) for r in rows) > 0
    assert rows[0]["width"] == "640" and rows[0]["height"] == "480"


def test_a_texture_cloud_flies_with_its_billboards_drawn(tmp_path):
    # fly's billboard material once called, in its fragment shader, a function only its vertex shader had
    import numpy as np
    from PIL import Image

    from fishgen.fly.headless import run_headless

    assets, _ = prepare_assets([PARAMS / "clouds" / "sky.awa"])
    session = FlySession(assets, FlyConfig(timeout=1, warmup=0.1, path="still", report=True))
    close_browser()  # fishgen's own Playwright runs in this thread now
    run_headless(session, screenshot=tmp_path / "fly.png")
    assert session.report["scene"]["billboards"] > 0 and session.report["frames"] > 0
    sky = np.asarray(Image.open(tmp_path / "fly.png").convert("RGB"), np.float32)[60:]   # below the overlay
    cloud = np.abs(sky - np.median(sky.reshape(-1, 3), axis=0)).max(-1) > 20
    assert 0.005 < cloud.mean() < 0.5, "the billboards should show as clouds on the sky"


# Run before the page's own script: keeps what modes() and drawn say at the moment `loaded` turns true.
AT_LOAD = """(() => {
    let state;
    Object.defineProperty(window, 'fishgenFly', { configurable: true, get: () => state, set(s) {
        state = s;
        let loaded = s.loaded;
        Object.defineProperty(s, 'loaded', { enumerable: true, get: () => loaded, set(on) {
            if (on && ! loaded) window.atLoad = { modes: s.modes(), drawn: s.drawn || null };
            loaded = on;
        } });
    } });
})()"""


def test_once_the_page_says_loaded_a_frame_is_drawn_and_modes_describe_it():
    # `loaded` once came a frame early: modes() then gave the cloud no place (centre 0, radius -1) and
    # called it drawn directly, and a test that read it at once built its views (and boxes) from that
    session = FlySession(prepare_assets([PARAMS / "clouds" / "table_4_4.awn"])[0],
                         FlyConfig(size=(320, 240), warmup=0.1, path="still"))
    session.serve_in_background()
    tab = shared_browser().new_page(viewport={"width": 320, "height": 240})
    try:
        tab.add_init_script(AT_LOAD)
        tab.goto(session.url())
        tab.wait_for_function("window.fishgenFly.loaded || window.fishgenFly.error", timeout=120_000)
        assert tab.evaluate("window.fishgenFly.error") is None
        seen = tab.evaluate("window.atLoad")
        assert seen["drawn"] is not None and seen["drawn"]["clouds"] == 1
        [cloud] = seen["modes"]
        assert cloud["radius"] > 0 and cloud["distance"] > 0 and cloud["mode"] in ("direct", "impostor")
        later = tab.evaluate("window.fishgenFly.modes()")[0]
        assert (cloud["centre"], cloud["radius"]) == (later["centre"], later["radius"])
    finally:
        tab.close()
        session.close()


@pytest.fixture(scope="module")
def served_sky(thin_sky):
    """The thin sky served for interactive flights (no path: the keys steer), every cloud drawn
    directly (impostors: tests/fly/test_impostors_browser.py)."""
    assets, _ = prepare_assets([thin_sky[0]])
    session = FlySession(assets, FlyConfig(size=(640, 480), warmup=0.1, impostors=False))
    session.serve_in_background()
    yield session
    session.close()


@pytest.fixture
def page(served_sky):
    """A fresh page of the served thin sky, in the shared headless Chromium, drawing."""
    tab = shared_browser().new_page(viewport={"width": 640, "height": 480})
    tab.goto(served_sky.url())
    tab.wait_for_function("window.fishgenFly.loaded && window.fishgenFly.frames > 2", timeout=120_000)
    yield tab
    tab.close()


def camera(tab) -> dict:
    return tab.evaluate("({...window.fishgenFly.camera, speed: window.fishgenFly.speed})")


def hold(tab, key: str, until: str, count: int = 3) -> None:
    """Hold a key down for at least ``count`` frames and until ``until`` (a JavaScript test of the
    camera ``c``) holds, sending keydown again every second as a keyboard's auto-repeat does.

    The page moves on a key it holds down, not on each keydown; the repeats only guard against
    a keydown a loaded headless Chromium lost (CI saw one arrow move nothing in four frames).
    """
    import playwright.sync_api as pw

    drawn = tab.evaluate("window.fishgenFly.frames")
    test = f"window.fishgenFly.frames > {drawn + count} && (c => {until})(window.fishgenFly.camera)"
    for _ in range(30):
        tab.keyboard.down(key)
        try:
            tab.wait_for_function(test, timeout=1_000)
            break
        except pw.TimeoutError:
            continue
    tab.keyboard.up(key)


def test_pakawans_keys_move_and_turn_the_camera(page):
    start = camera(page)
    assert start["yaw"] == 0 and start["pitch"] == 0          # looking along -z, into the sky
    hold(page, "w", f"c.position[2] < {start['position'][2]}", 6)
    ahead = camera(page)
    dx, dy, dz = (a - b for a, b in zip(ahead["position"], start["position"], strict=True))
    assert dz < 0 and abs(dx) < 1e-6 * abs(dz) + 1e-9 and abs(dy) < 1e-6 * abs(dz) + 1e-9   # forward
    hold(page, "s", f"c.position[2] > {ahead['position'][2]}")
    assert camera(page)["position"][2] > ahead["position"][2]                                  # back
    before = camera(page)
    hold(page, "d", f"c.position[0] > {before['position'][0]}")
    assert camera(page)["position"][0] > before["position"][0]                                 # right
    hold(page, "ArrowLeft", "c.yaw > 0")
    assert camera(page)["yaw"] > 0                                                             # turned left
    hold(page, "ArrowUp", "c.pitch > 0")
    assert camera(page)["pitch"] > 0                                                           # looks up
    page.keyboard.press("3")
    assert camera(page)["speed"] == 3
    page.keyboard.press("1")
    assert camera(page)["speed"] == 1


def test_the_mouse_looks_around(page):
    before = camera(page)
    page.mouse.move(320, 240)
    page.mouse.down()
    page.mouse.move(220, 240, steps=5)
    page.mouse.up()
    frames(page)
    assert camera(page)["yaw"] > before["yaw"]


def test_the_overlay_shows_window_size_time_and_fps(page):
    page.wait_for_function("document.querySelector('#hud').innerText.includes('FPS')", timeout=60_000)
    text = page.inner_text("#hud")
    assert text.startswith("640 × 480") and " s " in text and "FPS" in text
    # particles drawn directly this frame, out of all: a cloud shown as an impostor is a picture
    assert " particles drawn · " in page.inner_text("#detail")


def test_clouds_out_of_view_are_culled_far_ones_levelled_and_the_rest_sorted_back_to_front(page):
    units = page.evaluate("window.fishgenFly.inspect()")
    assert len(units) == 16
    visible = [u for u in units if u["visible"]]
    assert 0 < len(visible) < len(units)                     # the clouds behind the camera are culled
    assert any(u["level"] > 0 for u in visible)              # distant clouds at a lower level
    tan = math.tan(math.radians(30))
    for u in visible:
        cover = u["radius"] / (u["distance"] * tan) if u["distance"] > u["radius"] else 1
        assert (u["level"] == 0) == (cover >= 0.8 or u["levels"] == 1)
        assert u["sorted"] and u["disorder"] < 1e-3          # back to front, to a bucket's width
        assert u["turn"] <= 4.5 and u["moved"] <= 0.06       # re-sorted once the view turned or moved
    drawn = page.evaluate("window.fishgenFly.drawn")
    assert drawn["clouds"] == len(visible) and drawn["particles"] == sum(u["particles"] for u in visible)


def test_with_a_timeout_the_page_reports_writes_the_file_and_stops_serving(tmp_path, thin_sky):
    from fishgen.commands import Events

    report = tmp_path / "r.json"
    notes: list[str] = []
    lines: list[str] = []

    options = FlyOptions(timeout=1, warmup=0.1, report=report)
    events = Events(note=notes.append, line=lambda text, _: lines.append(text))
    made = fly((thin_sky[0],), None, options, events)
    assert made.lines[0].startswith("http://127.0.0.1:") and made.written == ()
    served = threading.Thread(target=made.server.serve_forever, daemon=True)
    served.start()
    tab = shared_browser().new_page()
    tab.goto(made.lines[0])
    served.join(timeout=120)
    if not tab.is_closed():
        # the page says the flight ended, its figures with the command (it said "(time out)" alone: QA 22)
        tab.wait_for_function("window.fishgenFly.done", timeout=30_000)
        assert "(time out: the figures are sent, and fishgen fly has stopped)" in tab.inner_text("#hud")
        tab.close()
    made.server.server_close()
    assert not served.is_alive()                             # Pakawan closed its window at the time-out
    r = json.loads(report.read_text())
    # the summary is a summary (stdout, silenced by -q), as the headless flight's; notes say what was written
    assert r["headless"] is False and r["frames"] > 0 and any("FPS median" in n for n in lines)
    assert notes == [f"wrote {report}"]


def test_headless_without_playwright_says_what_to_install_before_any_work(monkeypatch, tmp_path):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "playwright" else real(name, *a))
    with pytest.raises(MissingDependency, match=r"pip install 'fishgen\[fly\]'"):
        fly((tmp_path / "missing.awn",), None, FlyOptions(headless=True))
