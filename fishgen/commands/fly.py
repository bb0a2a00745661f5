"""`fishgen fly`: Pakawan's fly-through of clouds, a local three.js page that reports its frame rate."""
from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import click

from fishgen.clouds.lighting import Lighting
from fishgen.clouds.model import DEFAULT_MAX_PARTICLES
from fishgen.commands import QUIET, Command, Events, Inputs, Made
from fishgen.options import (
    FILE,
    FiniteRange,
    Size,
    cloud_textures_option,
    group,
    instancing_option,
    max_particles_option,
    option,
    seed_option,
)
from fishgen.sky.modes import MODES

HEADLESS_TIMEOUT = 10.0
WEBGL = ("swiftshader", "llvmpipe")   # fishgen.fly.headless.WEBGL, without importing it at --help time


@dataclass(frozen=True)
class FlyOptions:
    mode: str | None = option(click.Choice(tuple(MODES)), "Fly a sky of this mode (Pakawan's cloud_mode 1, "
                              "2, 3): with no INPUT, of the shipped clouds; with cube files, of them.", None,
                              shown_default="none: fly INPUT as it is")
    size: tuple[int, int] = option(Size(16, 8192), "Window size in pixels (Pakawan's width and height).",
                                   (800, 600), shown_default="800x600")
    timeout: float | None = option(FiniteRange(0, 86_400, min_open=True), "Seconds to fly after the warm-up, "
                                   "then write the report and stop (Pakawan's time_out).", None,
                                   shown_default=f"until Ctrl-C; {HEADLESS_TIMEOUT:g} with --headless",
                                   metavar="SECONDS")
    report: Path | None = option(FILE, "Write the report here when the time is up: .json, or .csv with one "
                                 "row per second (Pakawan's report_file).", None, metavar="FILE.json|.csv",
                                 path=True, shown_default="none (--headless prints its summary)")
    headless: bool = option(click.BOOL, "Fly in headless Chromium along a seeded path, with no window; needs "
                            "pip install 'fishgen[fly]' and a Chromium.", False, flag=True)
    warmup: float = option(FiniteRange(0, 600), "Seconds flown before frames are counted (shaders compiled, "
                           "first sorts).", 2.0, metavar="SECONDS")
    cloud_resolution: float = option(FiniteRange(0.1, 1), "Draw the clouds into a buffer of this share of "
                                     "the window's width and height, laid over the view (off-screen "
                                     "particles: a quarter of the pixels at 0.5); 1 draws them on the "
                                     "window.", 0.5,
                                     metavar="SHARE")
    impostors: bool = option(click.BOOL, "Draw each cloud (but those nearer than --impostor-near) "
                             "into a texture and show it as one camera-facing quad until the view of it "
                             "changes (SkyWorks' dynamic impostors, docs/fly.md); --no-impostors draws "
                             "every particle every frame.",
                             True, flag=True, off="--no-impostors")
    impostor_angle: float = option(FiniteRange(0.001, 10), "Redraw a cloud's impostor once the angle between "
                                   "the near and far points of its bounding sphere, seen from the camera, "
                                   "reaches this many degrees (SkyWorks' error tolerance).", 0.125,
                                   metavar="DEGREES")
    impostor_budget: int = option(click.IntRange(1, 10**9), "Most particles drawn into impostors a frame, "
                                  "the stalest first; a bigger redraw is spread over the next frames (the "
                                  "old picture shown meanwhile), and a cloud with none yet is drawn "
                                  "directly.", 5_000, metavar="PARTICLES")
    impostor_near: float = option(FiniteRange(1, 100), "Clouds whose centre is nearer than this many of "
                                  "their radii are drawn directly, particle by particle (1: those the camera "
                                  "is in, as SkyWorks did).",
                                  1.0, metavar="RADII")
    webgl: str = option(click.Choice(WEBGL), "--headless: software WebGL, Chromium's SwiftShader or Mesa's "
                        "llvmpipe (through ANGLE).", "swiftshader")
    seed: int = seed_option("It picks a --mode sky's clouds and the headless flight path.")
    port: int = option(click.IntRange(0, 65535), "Port on 127.0.0.1 to serve the page from; 0 picks a free "
                       "one.", 0, manifest=False)
    max_particles: int = max_particles_option(DEFAULT_MAX_PARTICLES)
    textures: Path | None = cloud_textures_option()
    lighting: Lighting = group(Lighting)
    instancing: bool = instancing_option()


COMMAND = Command(
    name="fly",
    summary="Fly through clouds, a sky or any glb in a local three.js page, and report the frame rate.",
    help="""Fly through INPUT... (cube files .awn, texture clouds .awa, a sky or any .glb)
    or a sky of --mode, as Pakawan flew through RekAwan's clouds.

    The page is served on 127.0.0.1 (a token in its address): W/S forward and
    back, A/D left and right, the arrows look up and down and turn, 1/2/3 low,
    medium and high speed, drag the mouse to look. The upper left shows the
    window size, the time and the FPS. Clouds are drawn back to front, culled
    as wholes, distant ones at their lower level, lit by Harris's second pass.

    With --timeout, the page reports after that many seconds (plus the
    warm-up) and fishgen stops; --report writes it. --headless flies a seeded
    path in headless Chromium, frames measured honestly (docs/fly.md).

    \b
    Examples:
      fishgen fly --mode thick
      fishgen fly params/clouds/table_4_4.awn --size 1024x768
      fishgen fly --mode medium --headless --timeout 5 --report out/fly.json
      fishgen fly out/sky.glb out/reef.glb --headless --report out/fly.csv
    """,
    options=FlyOptions,
    run="fishgen.commands.fly:fly",
    inputs=Inputs("[INPUT]...", required=False),
)


def fly(inputs: Sequence[Path], output: str | os.PathLike | None = None, options: FlyOptions = FlyOptions(),
        events: Events = QUIET) -> Made:
    """Headless: fly, wait for the report, write it; else bind the page's server (the caller serves it
    until Ctrl-C, or until the page reports at its time-out)."""
    inputs = COMMAND.given(inputs, options)
    from fishgen.commands.paths import check_targets, suffix_of
    from fishgen.errors import UsageError
    from fishgen.fly.report import SUFFIXES, full_report, summary, write_report

    inputs = tuple(Path(p) for p in inputs)
    if output is not None:
        raise UsageError("expected no -o (the report goes to --report), found one")
    if options.report is not None:
        suffix_of(options.report, SUFFIXES, "a report")
        check_targets([options.report], inputs)
        from fishgen.atomic import check_writable

        check_writable(options.report)  # before the flight, not after it
    timeout = options.timeout
    if timeout is None and options.headless:
        timeout = HEADLESS_TIMEOUT
    if options.report is not None and timeout is None:
        raise UsageError("expected --timeout with --report (the report is written when the time is up), "
                         "found none")
    chromium = None
    if options.headless:
        from fishgen.fly.headless import check_headless

        chromium = check_headless()                  # before any work: a missing browser says so now
    from fishgen.fly.assets import prepare_assets
    from fishgen.fly.session import FlyConfig, FlySession

    assets, read = prepare_assets(inputs, mode=options.mode, seed=options.seed, lighting=options.lighting,
                                  textures_dir=options.textures, max_particles=options.max_particles)
    title = ", ".join(a.name for a in assets)
    # how the page drew: a report of --no-instancing is told from an instanced one
    run = {"inputs": [str(p) for p in inputs], "mode": options.mode, "timeout": timeout,
           "instancing": options.instancing}
    config = FlyConfig(size=options.size, timeout=timeout, warmup=options.warmup,
                       path="fly" if options.headless else None, seed=options.seed,
                       report=timeout is not None, cloud_scale=options.cloud_resolution,
                       instancing=options.instancing,
                       impostors=options.impostors, impostor_angle=options.impostor_angle,
                       impostor_budget=options.impostor_budget, impostor_near=options.impostor_near)
    if options.headless:
        from fishgen.fly.headless import run_headless

        session = _session(assets, config, options.port, title)
        browser = run_headless(session, webgl=options.webgl, chromium=chromium)
        assert session.report is not None
        report = full_report(session.report, {**run, **browser})
        written = (write_report(report, options.report),) if options.report is not None else ()
        return Made(written, tuple(read), tuple(summary(report)), facts=report)

    holder: dict[str, FlySession] = {}

    def reported(page: dict) -> None:
        import threading

        report = full_report(page, {**run, "headless": False})
        if options.report is not None:
            write_report(report, options.report)
            events.note(f"wrote {options.report}")
        for line in summary(report):    # the summary, on stdout as every command's (-q silences it)
            events.line(line, None)
        server = holder["session"].server
        threading.Timer(0.2, server.shutdown).start()   # Pakawan closed its window at the time-out

    session = _session(assets, config, options.port, title, reported)
    holder["session"] = session
    lines = (session.url(), f"flying {title}: W/S/A/D move, arrows look and turn, 1/2/3 speed, drag to look"
             + (f"; stops {timeout:g} s after the page starts flying" if timeout else "; Ctrl-C to stop"))
    return Made((), tuple(read), lines, server=session.server)


def _session(assets, config, port: int, title: str, on_report=None):
    from fishgen.errors import SystemFailure
    from fishgen.fly.session import FlySession

    try:
        return FlySession(assets, config, port=port, title=title, on_report=on_report)
    except OSError as err:
        raise SystemFailure(f"expected a free port {port} on 127.0.0.1, found it taken ({err.strerror}); "
                            "try --port 0") from None
