"""The fly-through's report, as Pakawan wrote one after its time-out: checked, then JSON or CSV.

The page measures and posts; this module checks what it posted (numbers finite and in range,
lists bounded, text short: the page is ours, but a report is data) and writes it:

* ``.json``: the whole report (window size, time flown, frames, FPS median / 5th percentile /
  min / max, particles and billboards in the scene and drawn on average, the WebGL renderer,
  fishgen's version, how it was run, and the per-second rows);
* ``.csv``: one row per second of the time flown, each row carrying the run's constants too.
"""
from __future__ import annotations

import csv
import io
import math
import os
from pathlib import Path
from typing import Any

from fishgen.errors import FishgenError, plural

SUFFIXES = (".json", ".csv")
MAX_SECONDS = 86_400
MAX_TEXT = 300
SCENE = ("particles", "billboards", "distant_particles", "distant_billboards", "clouds", "meshes")
DRAWN = ("particles", "billboards", "clouds")
SPLIT = ("update", "submit", "wait")
IMPOSTORS = ("on", "angle", "budget", "shown", "redraws", "particles", "error", "redraw_share", "textures")
CSV_COLUMNS = ("second", "frames", "fps", "particles_drawn", "billboards_drawn", "width", "height",
               "particles_in_scene", "billboards_in_scene", "fps_median", "renderer", "fishgen")


def _number(value: Any, what: str, low: float = 0.0, high: float = 1e12) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
            or not low <= value <= high:
        raise FishgenError(f"expected {what} as a number from {low:g} to {high:g}, found {value!r}")
    return float(value)


def _text(value: Any, what: str) -> str:
    if not isinstance(value, str) or len(value) > MAX_TEXT:
        raise FishgenError(f"expected {what} as text of at most {MAX_TEXT} characters, found "
                           f"{str(value)[:40]!r}")
    return value


def _members(value: Any, what: str, names: tuple[str, ...]) -> dict[str, Any]:
    if not isinstance(value, dict) or not all(n in value for n in names):
        raise FishgenError(f"expected {what} with {', '.join(names)}, found {str(value)[:60]!r}")
    return value


def check_report(page: Any) -> dict[str, Any]:
    """The page's report, checked and in fishgen's order; a malformed one is a FishgenError."""
    r = _members(page, "a report", ("window", "seconds", "warmup", "frames", "fps", "scene", "drawn", "split",
                                    "renderer", "path", "seed", "sorts", "impostors", "per_second"))
    window = _members(r["window"], "window", ("width", "height"))
    fps = _members(r["fps"], "fps", ("median", "p5", "min", "max"))
    scene = _members(r["scene"], "scene", SCENE)
    drawn = _members(r["drawn"], "drawn", DRAWN)
    split = _members(r["split"], "split", SPLIT)
    impostors = _members(r["impostors"], "impostors", IMPOSTORS)
    if not isinstance(impostors["on"], bool):
        raise FishgenError(f"expected impostors on as true or false, found {impostors['on']!r}")
    rows = r["per_second"]
    if not isinstance(rows, list) or len(rows) > MAX_SECONDS + 1:
        raise FishgenError(f"expected per_second as a list of at most {MAX_SECONDS + 1} rows, found "
                           f"{type(rows).__name__}")
    per_second = []
    for row in rows:
        row = _members(row, "a per-second row", ("second", "frames", "fps", "particles", "billboards"))
        per_second.append({"second": int(_number(row["second"], "second", 0, MAX_SECONDS)),
                           "frames": int(_number(row["frames"], "frames", 0, 1e9)),
                           "fps": round(_number(row["fps"], "fps", 0, 1e9), 3),
                           "particles": round(_number(row["particles"], "particles drawn"), 1),
                           "billboards": round(_number(row["billboards"], "billboards drawn"), 1)})
    return {
        "window": {"width": int(_number(window["width"], "width", 1, 1e5)),
                   "height": int(_number(window["height"], "height", 1, 1e5))},
        "seconds": round(_number(r["seconds"], "seconds", 0, MAX_SECONDS), 3),
        "warmup": round(_number(r["warmup"], "warmup", 0, MAX_SECONDS), 3),
        "frames": int(_number(r["frames"], "frames", 0, 1e9)),
        "fps": {k: round(_number(fps[k], f"fps {k}", 0, 1e9), 3) for k in ("median", "p5", "min", "max")},
        "scene": {k: int(_number(scene[k], f"scene {k}")) for k in SCENE},
        "drawn": {k: round(_number(drawn[k], f"drawn {k}"), 1) for k in DRAWN},
        "split": {k: round(_number(split[k], f"split {k}", 0, 1e9), 3) for k in SPLIT},
        "renderer": _text(r["renderer"], "renderer"),
        "path": _text(r["path"], "path"),
        "seed": int(_number(r["seed"], "seed", 0, 2**63)),
        "sorts": int(_number(r["sorts"], "sorts")),
        "impostors": {"on": impostors["on"], "angle": _number(impostors["angle"], "impostors angle", 0, 360),
                      "budget": int(_number(impostors["budget"], "impostors budget", 0, 1e9)),
                      "shown": round(_number(impostors["shown"], "impostors shown"), 2),
                      "redraws": round(_number(impostors["redraws"], "impostor redraws"), 3),
                      "particles": round(_number(impostors["particles"], "particles redrawn"), 1),
                      "error": round(_number(impostors["error"], "impostor error"), 2),
                      "redraw_share": round(_number(impostors["redraw_share"], "impostor redraw share", 0, 1),
                                            4),
                      "textures": int(_number(impostors["textures"], "impostor textures"))},
        "per_second": per_second,
    }


def full_report(page: dict[str, Any], run: dict[str, Any]) -> dict[str, Any]:
    """The checked page report with what the command knows (fishgen's version, inputs, headless,
    browser and its flags) around it."""
    from fishgen import __version__

    return {"fishgen": __version__, **run, **page}


def csv_text(report: dict[str, Any]) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for row in report["per_second"]:
        writer.writerow([row["second"], row["frames"], f"{row['fps']:.3f}", f"{row['particles']:.1f}",
                         f"{row['billboards']:.1f}", report["window"]["width"], report["window"]["height"],
                         report["scene"]["particles"], report["scene"]["billboards"],
                         f"{report['fps']['median']:.3f}", report["renderer"], report["fishgen"]])
    return out.getvalue()


def write_report(report: dict[str, Any], path: str | os.PathLike) -> Path:
    """Write ``report`` atomically as JSON or CSV (by the extension)."""
    import json

    from fishgen.atomic import write_bytes

    path = Path(path)
    if path.suffix.lower() == ".csv":
        data = csv_text(report).encode("utf-8")
    else:
        data = (json.dumps(report, indent=1) + "\n").encode("utf-8")
    write_bytes(path, data)
    return path


def summary(report: dict[str, Any]) -> list[str]:
    """The report in a few lines, for the terminal."""
    fps, w = report["fps"], report["window"]
    scene, drawn = report["scene"], report["drawn"]
    things = f"{scene['particles']:,} particles"
    if scene["billboards"]:
        things += f", {scene['billboards']:,} billboards"
    clouds = [f"{things} in {plural(scene['clouds'], 'cloud')}; drawn on average "
              f"{drawn['particles']:,.0f} particles"
              + (f", {drawn['billboards']:,.0f} billboards" if scene["billboards"] else "")
              + f" in {drawn['clouds']:.1f} clouds"] if scene["clouds"] else []
    # a school flown alone said only "0 particles in 0 clouds"
    meshes = [f"{scene['meshes']:,} mesh{'es' * (scene['meshes'] != 1)} (fish and other solids), schools "
              + ("instanced" if report.get("instancing", True) else "drawn fish by fish (--no-instancing)")
              ] if scene["meshes"] else []
    return [f"flew {report['seconds']:.1f} s at {w['width']}x{w['height']}: {report['frames']:,} frames, "
            f"{fps['median']:.1f} FPS median (5th percentile {fps['p5']:.1f}, min {fps['min']:.1f}, "
            f"max {fps['max']:.1f})",
            *clouds, *meshes, *(impostor_lines(report["impostors"]) if scene["clouds"] else []),
            f"renderer: {report['renderer']}"]


def impostor_lines(imp: dict[str, Any]) -> list[str]:
    """What the impostors did, a frame on average (nothing when they were off)."""
    if not imp["on"]:
        return []
    return [f"impostors: {imp['shown']:.1f} clouds shown as impostors (their particles not counted above), "
            f"{imp['redraws']:.2f} redraws finished and {imp['particles']:,.0f} particles redrawn a frame, "
            f"{100 * imp['redraw_share']:.0f}% of the time; the pictures shown {imp['error']:.1f} times the "
            f"--impostor-angle off on average"]
