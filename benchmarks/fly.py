"""The cloud report's chapter 5, redone: frame rate against particle count at three window sizes.

    python benchmarks/fly.py                 # the whole table (about 15 minutes) and the plot
    python benchmarks/fly.py --quick         # 500 and 5,000 particles at 800x600 only
    python benchmarks/fly.py --sky           # the thick sky target only: fishgen fly --mode thick
    python benchmarks/fly.py --targets       # issue 33's two targets, impostors and today's (< 5 min)
    python benchmarks/fly.py --pictures      # still frames with and without impostors: SSIM, side by side
    python benchmarks/fly.py --write         # fishgen sky --mode thick: whole command and its steps
    python benchmarks/fly.py --screenshot docs/images/sky-thick.png   # the README's picture

The report (section 5.3, Figures 5.4-5.11) rendered clouds of 500 to 50,000 particles "distributed
randomly in the cloud bounding volume" at 800x600, 1024x768 and 1152x864 on five PCs of 2004
(Tables 5.1-5.5). Here the cloud is the report's Table 4.4 with its cubes' counts scaled to N and
its radii scaled by (615 / N)^(1/3) (the same cloud at any N: its particles pack as the editor's
did, fishgen.sky.compose.scaled_model), filled and lit as `fishgen clouds` does it, and shown in
`fishgen fly`'s page in headless Chromium on this machine's software WebGL, the camera turning
round it at a distance where it spans about 0.8 of the view's height. Each cell is measured as
`fishgen fly --headless` measures (docs/fly.md): a 2 s warm-up, then FPS over a fixed wall time.

Four ways to draw the same particles, in one run, interleaved per cell:

* ``plain``: the baseline, three.js ``Points`` with a size per particle set by the mean radius,
  one colour each (the baked light), unsorted, no second pass, drawn on the window;
* ``lit``: fishgen fly's particles, sorted back to front, Harris's second pass, Gaussian sprites,
  drawn on the window (cloud resolution 1);
* ``lit 0.5``: the same into a half-size cloud buffer laid over the window (fly's default before
  impostors);
* ``imp 0.5``: the same with dynamic impostors (issue 33, fly's default): the cloud drawn into a
  texture a slice a frame (``--impostor-budget`` particles) and shown as one quad.

The first three have impostors off, so they are the baseline of issue 22 measured again.
``--targets`` measures issue 33's two targets on seeded paths that move and turn, today's drawing
(``lit 0.5``) and impostors interleaved: 50,000 lit particles at 800x600 on the ``around`` path (a
seeded loop round the cloud), and the thick sky on its ``fly`` path; each row gives the median and
the mean FPS (frames / seconds: the slow frames that finish a redraw count fully) and the
impostors' redraws a frame and their share of the time.

Levels of detail are off (the chapter's test has one cloud, all of it in view). Results are
printed as a table and, with matplotlib, drawn beside the report's System1-5 figures as its
text gives them (docs/images/fly-chapter5.png).
"""
from __future__ import annotations

import argparse
import io
import json
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fishgen.clouds.fill import fill_cloud  # noqa: E402
from fishgen.clouds.parser import load_cubes  # noqa: E402
from fishgen.exchange.gltf import glb_bytes  # noqa: E402
from fishgen.fly.assets import Asset  # noqa: E402
from fishgen.fly.headless import run_headless  # noqa: E402
from fishgen.fly.session import FlyConfig, FlySession  # noqa: E402
from fishgen.sky.compose import Placement, SkyCloud, scaled_model  # noqa: E402
from fishgen.sky.light import light_sky  # noqa: E402
from fishgen.sky.scene import sky_scene  # noqa: E402

TABLE = ROOT / "params" / "clouds" / "table_4_4.awn"
COUNTS = (500, 1_000, 5_000, 10_000, 20_000, 50_000)
SIZES = ((800, 600), (1024, 768), (1152, 864))
WAYS = {"plain": dict(baseline=True, cloud_scale=1.0), "lit": dict(cloud_scale=1.0, impostors=False),
        "lit 0.5": dict(cloud_scale=0.5, impostors=False), "imp 0.5": dict(cloud_scale=0.5, impostors=True)}
# The report's own figures, as its text states them (the charts themselves are not in the
# extraction): (particles, FPS) read from section 5.3 for each system, at 800x600.
REPORT = {
    "System1: P4 3.2 GHz, GeForce FX 5950 Ultra": [(500, 120), (50_000, 20)],
    "System2: P4 1.5 GHz, Radeon 9600 XT": [(50_000, 18)],
    "System3: P4 1.4 GHz, GeForce FX 5200": [(500, 50), (50_000, 10)],
    "System4: P4 2.8 GHz, GeForce FX 5200": [(500, 120), (50_000, 20)],
    "System5: Athlon 1.4 GHz, GeForce MX": [(500, 120), (50_000, 10)],
}


def cloud_asset(n: int, seed: int = 0) -> Asset:
    """Table 4.4 scaled to n particles (radii by (615 / n)^(1/3)), lit, as one glb without levels."""
    model = load_cubes(TABLE)
    place = Placement("cloud", 0, (1.0, 1.0, 1.0), 0.0, (0.0, 0.0, 0.0), n, seed)
    cloud = fill_cloud(scaled_model(model, place, 1.0), seed=seed)
    lit = light_sky([SkyCloud(place, cloud)])
    scene, _ = sky_scene(None, lit, [TABLE.name], lod=False)
    return Asset(f"table 4.4 x {n:,}", glb_bytes(scene), "cubes")


def measure(asset: Asset, size: tuple[int, int], seconds: float, webgl: str, path: str = "orbit",
            **way) -> dict:
    config = FlyConfig(size=size, timeout=seconds, warmup=2.0, path=path, report=True, **way)
    session = FlySession([asset], config, title=asset.name)
    facts = run_headless(session, webgl=webgl)
    assert session.report is not None
    return {**session.report, **facts}


def chapter5(counts, sizes, seconds: float, webgl: str, out: Path | None) -> list[dict]:
    rows = []
    for n in counts:
        asset = cloud_asset(n)
        for size in sizes:
            for name, way in WAYS.items():
                r = measure(asset, size, seconds, webgl, **way)
                row = {"particles": n, "size": f"{size[0]}x{size[1]}", "way": name, "fps": r["fps"],
                       "frames": r["frames"], "split": r["split"], "renderer": r["renderer"],
                       "load_average": r["load_average"], "impostors": r["impostors"]}
                rows.append(row)
                print(f"{n:>7,} {row['size']:>9} {name:>8}: {r['fps']['median']:7.1f} FPS median "
                      f"(p5 {r['fps']['p5']:.1f}, {r['frames']} frames; wait {r['split']['wait']:.0f} ms; "
                      f"load {r['load_average'][0]}-{r['load_average'][1]})", flush=True)
                if out is not None:
                    out.write_text(json.dumps(rows, indent=1) + "\n")
    return rows


def table(rows: list[dict]) -> str:
    sizes = list(dict.fromkeys(r["size"] for r in rows))
    ways = list(dict.fromkeys(r["way"] for r in rows))
    head = "| particles | " + " | ".join(f"{s} {w}" for s in sizes for w in ways) + " |"
    lines = [head, "|---:|" + "---:|" * (len(sizes) * len(ways))]
    for n in dict.fromkeys(r["particles"] for r in rows):
        cells = []
        for s in sizes:
            for w in ways:
                hit = [r for r in rows if r["particles"] == n and r["size"] == s and r["way"] == w]
                cells.append(f"{hit[0]['fps']['median']:.1f}" if hit else "")
        lines.append(f"| {n:,} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def plot(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sizes = list(dict.fromkeys(r["size"] for r in rows))
    fig, axes = plt.subplots(1, len(sizes), figsize=(5 * len(sizes), 4.2), sharey=True, squeeze=False)
    styles = {"plain": ("tab:gray", "--"), "lit": ("tab:blue", "-"), "lit 0.5": ("tab:green", "-"),
              "imp 0.5": ("tab:purple", "-")}
    for ax, size in zip(axes[0], sizes, strict=True):
        for way, (colour, line) in styles.items():
            pts = sorted((r["particles"], r["fps"]["median"]) for r in rows
                         if r["size"] == size and r["way"] == way)
            if pts:
                ax.plot(*zip(*pts, strict=True), line, marker="o", color=colour, label=f"fishgen fly: {way}")
        if size == "800x600":
            for k, (name, pts) in enumerate(REPORT.items()):
                ax.plot(*zip(*pts, strict=True), ":", marker="s^vDx"[k], color="tab:red", alpha=1 - 0.15 * k,
                        label=f"report {name}")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("particles")
        ax.set_title(size)
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].set_ylabel("frames per second (median)")
    renderer = rows[0]["renderer"].split("(")[-1].rstrip(")") if rows else ""
    fig.suptitle(f"Chapter 5 redone: one cloud, software WebGL ({renderer}), {os.cpu_count()} cores, "
                 f"load {statistics.median(r['load_average'][0] for r in rows):.0f}")
    axes[0][-1].legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


def sky(seconds: float, webgl: str, repeats: int) -> None:
    """The thick sky target: `fishgen fly --mode thick --headless`, its seeded path, culling and levels."""
    from fishgen.fly.assets import prepare_assets

    started = time.perf_counter()
    assets, _ = prepare_assets([], mode="thick")
    print(f"thick sky built in {time.perf_counter() - started:.1f} s: {len(assets[0].data) / 1e6:.1f} MB")
    for k in range(repeats):
        r = measure(assets[0], (800, 600), seconds, webgl, path="fly", seed=k)
        print(f"thick sky, path seed {k}: {r['fps']['median']:.1f} FPS median (p5 {r['fps']['p5']:.1f}), "
              f"{r['frames']} frames, {r['drawn']['particles']:,.0f} of {r['scene']['particles']:,} "
              f"particles "
              f"drawn in {r['drawn']['clouds']:.1f} of {r['scene']['clouds']} clouds; split {r['split']}; "
              f"load {r['load_average']}", flush=True)


def write(repeats: int) -> None:
    """`fishgen sky --mode thick` as a user runs it (its own process, median of ``repeats``), with
    either shadow map, interleaved; then its steps in one process, to say where the time goes."""
    import subprocess
    import tempfile

    from fishgen.exchange import export
    from fishgen.sky.build import load_models
    from fishgen.sky.compose import fill_sky, plan_sky
    from fishgen.sky.modes import ALTITUDE, AREA, MODES
    from fishgen.sky.scene import sky_scene

    times: dict[str, list[float]] = {"cloud": [], "sky": []}
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "sky.glb"
        for _ in range(repeats):
            for shadow in times:
                started = time.perf_counter()
                subprocess.run([sys.executable, "-m", "fishgen", "sky", "--mode", "thick", "--shadow-map",
                                shadow, "-o", str(out)], check=True, cwd=ROOT, capture_output=True)
                times[shadow].append(time.perf_counter() - started)
        size = out.stat().st_size
        for shadow, values in times.items():
            print(f"fishgen sky --mode thick --shadow-map {shadow}: {statistics.median(values):.2f} s "
                  f"median of {repeats} ({', '.join(f'{v:.2f}' for v in values)}), {size / 1e6:.1f} MB",
                  flush=True)
        steps: dict[str, float] = {}
        started = time.perf_counter()
        models, files = load_models()
        plan = plan_sky(MODES["thick"], models, seed=0, area=AREA, altitude=ALTITUDE)
        clouds = fill_sky(plan, models, noise=0.0)
        steps["fill"] = time.perf_counter() - started
        started = time.perf_counter()
        clouds = fill_sky(plan, models, noise=0.5)
        steps["fill + noise"] = time.perf_counter() - started
        for shadow in ("cloud", "sky"):
            started = time.perf_counter()
            lit = light_sky(clouds, method=shadow)
            steps[f"light ({shadow} maps)"] = time.perf_counter() - started
        started = time.perf_counter()
        scene, _ = sky_scene(plan, lit, [f.name for f in files])
        steps["levels of detail + scene"] = time.perf_counter() - started
        started = time.perf_counter()
        export(scene, out)
        steps["write"] = time.perf_counter() - started
    for step, seconds in steps.items():
        print(f"  {step:>26}: {seconds:.2f} s")
    print(f"load average {os.getloadavg()}")


def screenshot(path: Path, webgl: str, seconds: float) -> None:
    """The README's picture: a thick sky flown headless along its seeded path, its last frame."""
    from fishgen.clouds.lighting import Lighting
    from fishgen.fly.assets import prepare_assets

    # a lower sun behind the camera, so the picture shows sunlit tops and sides
    assets, _ = prepare_assets([], mode="thick", lighting=Lighting(sun=(0.2, 0.6, 1.0)))
    config = FlyConfig(size=(1024, 576), timeout=seconds, warmup=1.0, path="still", report=True, seed=1)
    session = FlySession(assets, config, title="thick sky")
    run_headless(session, webgl=webgl, screenshot=path)
    print(f"wrote {path}")


TARGETS = {"50,000 lit particles": 20.0, "thick sky": 15.0}
TODAY, IMPOSTORS = {"impostors": False, "cloud_scale": 0.5}, {"impostors": True, "cloud_scale": 0.5}


def describe(r: dict) -> str:
    imp = r["impostors"]
    text = (f"{r['fps']['median']:5.1f} FPS median, {r['frames'] / r['seconds']:5.1f} mean, "
            f"p5 {r['fps']['p5']:4.1f} ({r['frames']} frames; wait {r['split']['wait']:.0f} ms")
    if imp["on"]:
        text += (f"; {imp['shown']:.1f} clouds as impostors, {imp['redraws']:.2f} redraws and "
                 f"{imp['particles']:,.0f} particles redrawn a frame, "
                 f"{100 * imp['redraw_share']:.0f}% of the time, pictures {imp['error']:.1f}x the angle off")
    return text + f"; load {r['load_average'][0]}-{r['load_average'][1]})"


def targets(seconds: float, webgl: str, repeats: int, out: Path | None) -> list[dict]:
    """Issue 33's targets, today's drawing and impostors interleaved, each `repeats` seeded paths."""
    from fishgen.fly.assets import prepare_assets

    runs = {"50,000 lit particles": (cloud_asset(50_000), "around"),
            "thick sky": (prepare_assets([], mode="thick")[0][0], "fly")}
    rows = []
    for what, (asset, path) in runs.items():
        for seed in range(repeats):
            for way, options in (("lit 0.5", TODAY), ("imp 0.5", IMPOSTORS)):
                r = measure(asset, (800, 600), seconds, webgl, path=path, seed=seed, **options)
                rows.append({"target": what, "way": way, "seed": seed, "fps": r["fps"], "frames": r["frames"],
                             "seconds": r["seconds"], "split": r["split"], "impostors": r["impostors"],
                             "renderer": r["renderer"], "load_average": r["load_average"]})
                print(f"{what:>20}, {path} path seed {seed}, {way}: {describe(r)}", flush=True)
                if out is not None:
                    out.write_text(json.dumps(rows, indent=1) + "\n")
    print(f"\n| target | goal FPS | lit 0.5 | imp 0.5 (median FPS, the median of {repeats} paths) |")
    print("|---|---:|---:|---:|")
    for what, goal in TARGETS.items():
        mine = [r for r in rows if r["target"] == what]
        cells = [statistics.median(r["fps"]["median"] for r in mine if r["way"] == way)
                 for way in ("lit 0.5", "imp 0.5")]
        verdict = "met" if cells[1] >= goal else f"missed ({cells[1] / goal:.2f} of it)"
        print(f"| {what} | {goal:g} | {cells[0]:.1f} | {cells[1]:.1f} "
              f"({cells[1] / cells[0]:.1f}x; {verdict}) |")
    print(f"renderer: {rows[0]['renderer']}; {os.cpu_count()} cores; load average now {os.getloadavg()}")
    return rows


def still_pictures(webgl: str, image: Path | None) -> None:
    """Ten seeded still views each of Table 4.4 and of the thick sky, drawn directly and with
    impostors: mean absolute difference and SSIM per view; one view of each side by side."""
    from fishgen.fly.assets import prepare_assets
    from fishgen.fly.headless import COMMON, WEBGL, find_chromium
    from fishgen.sky.modes import ALTITUDE, AREA
    from tests.fly import pictures

    shown = []
    for what in ("table 4.4", "thick sky"):
        one = what == "table 4.4"
        assets, _ = prepare_assets([TABLE] if one else [], mode=None if one else "thick")
        session = FlySession(assets, FlyConfig(size=(800, 600), warmup=0.1, path="still"))
        session.serve_in_background()
        from playwright.sync_api import sync_playwright

        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=find_chromium(), args=[*COMMON, *WEBGL[webgl]])
            page = browser.new_page(viewport={"width": 800, "height": 600},
                                    bypass_csp=True)  # wait_for_function polls with eval
            page.goto(session.url())
            page.wait_for_function("window.fishgenFly.loaded", timeout=300_000)
            if what == "table 4.4":
                u = page.evaluate("window.fishgenFly.modes()")[0]
                views = pictures.views_around(u["centre"], u["radius"], 10, seed=0, near=2.2, far=6)
            else:
                views = pictures.sky_views(AREA, ALTITUDE, 10, seed=0)
            ssims, mads = [], []
            for k, view in enumerate(views):
                direct, impostor, modes = pictures.both(page, view)
                ssims.append(pictures.ssim(direct, impostor))
                mads.append(pictures.mean_abs(direct, impostor))
                print(f"{what} view {k}: SSIM {ssims[-1]:.4f}, mean |difference| {mads[-1]:.2f} of 255, "
                      f"{sum(m['mode'] == 'impostor' for m in modes)} clouds as impostors, "
                      f"{sum(m['mode'] == 'direct' for m in modes)} directly", flush=True)
                if k == (0 if one else 3):
                    shown.append((what, direct, impostor))
            print(f"{what}: SSIM min {min(ssims):.4f} median {statistics.median(ssims):.4f}; "
                  f"mean |difference| max {max(mads):.2f} median {statistics.median(mads):.2f}", flush=True)
            browser.close()
        session.close()
    if image is not None:
        import numpy as np
        from PIL import Image, ImageDraw

        rows = [np.concatenate([d, np.full((d.shape[0], 8, 3), 255, np.uint8), i], 1) for _, d, i in shown]
        gap = np.full((8, rows[0].shape[1], 3), 255, np.uint8)
        picture = Image.fromarray(np.concatenate([rows[0], gap, rows[1]]))
        draw = ImageDraw.Draw(picture)
        for k, (what, _, _) in enumerate(shown):
            for j, label in enumerate(("drawn directly", "impostors")):
                draw.text((10 + j * 808, 8 + k * 608), f"{what}: {label}", fill=(0, 0, 0))
        buffer = io.BytesIO()
        picture.save(buffer, format="PNG", optimize=True)
        from fishgen.atomic import write_bytes

        write_bytes(image, buffer.getvalue())
        print(f"wrote {image}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="500 and 5,000 particles at 800x600 only")
    parser.add_argument("--sky", action="store_true", help="only the thick sky target")
    parser.add_argument("--targets", action="store_true",
                        help="only issue 33's targets: 50,000 lit particles and the thick sky, with and "
                             "without impostors (--repeats paths each, default 2 here)")
    parser.add_argument("--pictures", type=Path, nargs="?",
                        const=ROOT / "docs" / "images" / "fly-impostors.png",
                        help="only still frames with and without impostors (SSIM), one of each side by side "
                             "written here")
    parser.add_argument("--write", action="store_true", help="only fishgen sky --mode thick's write time")
    parser.add_argument("--screenshot", type=Path, help="only a picture of a thick sky, flown headless")
    parser.add_argument("--seconds", type=float, default=5.0,
                        help="seconds measured per cell (after 2 s warm-up)")
    parser.add_argument("--webgl", choices=("swiftshader", "llvmpipe"), default="swiftshader")
    parser.add_argument("--repeats", type=int, default=None,
                        help="thick sky runs (path seeds 0..; default 3, 2 with --targets)")
    parser.add_argument("--json", type=Path, default=ROOT / "out" / "fly-chapter5.json")
    parser.add_argument("--plot", type=Path, default=ROOT / "docs" / "images" / "fly-chapter5.png")
    args = parser.parse_args()
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()}")
    if args.targets:
        targets(max(args.seconds, 8.0), args.webgl, args.repeats or 2, ROOT / "out" / "fly-targets.json")
        return
    if args.pictures:
        still_pictures(args.webgl, args.pictures)
        return
    repeats = args.repeats or 3
    if args.sky:
        sky(max(args.seconds, 10.0), args.webgl, repeats)
        return
    if args.write:
        write(repeats)
        return
    if args.screenshot:
        screenshot(args.screenshot, args.webgl, args.seconds)
        return
    counts, sizes = ((500, 5_000), SIZES[:1]) if args.quick else (COUNTS, SIZES)
    args.json.parent.mkdir(parents=True, exist_ok=True)
    rows = chapter5(counts, sizes, args.seconds, args.webgl, args.json)
    print(table(rows))
    if not args.quick:
        try:
            plot(rows, args.plot)
            print(f"plotted {args.plot}")
        except ImportError:
            print("matplotlib is not installed: no plot (pip install 'fishgen[plot]')")


if __name__ == "__main__":
    main()
