"""`fishgen preview` as a user meets it: outputs, views, sheets, loops and one-line errors."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from tests.conftest import PARAMS, run_cli

pytestmark = pytest.mark.usefixtures("gl_available")
BREAM = PARAMS / "bonybream.txt"


def _ok(*args):
    result = run_cli("preview", *args)
    assert result.returncode == 0, result.stderr
    assert "Traceback" not in result.stderr
    return result


def test_default_still_is_800x600_with_a_subject(tmp_path):
    out = tmp_path / "bream.png"
    _ok(BREAM, "-o", out)
    img = np.asarray(Image.open(out).convert("RGB"), np.float32)
    assert img.shape == (600, 800, 3)
    background = np.array([0x8C, 0xAD, 0xCC])
    subject = np.abs(img - background).max(-1) > 10
    assert 0.05 < subject.mean() < 0.8  # framed: neither lost in the distance nor cropped to fill


def test_fish_faces_left_in_side_view(tmp_path):
    # Field-guide convention; test_reference.py checks the whole layout of every fin.
    out = tmp_path / "side.png"
    _ok(BREAM, "-o", out, "--view", "side", "--size", "400x300")
    img = np.asarray(Image.open(out).convert("RGB"), np.float32)
    eye_x = np.nonzero(img.sum(-1) < 120)[1]  # the pupil is the darkest thing in the picture
    subject_x = np.nonzero(np.abs(img - np.array([0x8C, 0xAD, 0xCC])).max(-1) > 10)[1]
    assert len(eye_x) > 0 and eye_x.mean() < subject_x.mean()


def test_views_time_and_background_change_the_image(tmp_path):
    paths = {}
    for key, extra in {"side": ["--view", "side"], "top": ["--view", "top"],
                       "front": ["--view", "front"], "posed": ["--view", "side", "--time", "1.0"],
                       "white": ["--view", "side", "--background", "white"]}.items():
        paths[key] = tmp_path / f"{key}.png"
        _ok(BREAM, "-o", paths[key], "--size", "320x240", *extra)
    side = np.asarray(Image.open(paths["side"]).convert("RGB"), np.float32)
    for other in ("top", "front", "posed", "white"):
        changed = np.abs(side - np.asarray(Image.open(paths[other]).convert("RGB"), np.float32)).max(-1) > 32
        assert changed.mean() > 0.01, other  # over 1 % of the pixels differ clearly


def test_transparent_background_keeps_alpha(tmp_path):
    out = tmp_path / "cut.png"
    _ok(BREAM, "-o", out, "--size", "200x150", "--background", "transparent")
    alpha = np.asarray(Image.open(out))[..., 3]
    assert alpha[0, 0] == 0 and alpha.max() == 255


def test_contact_sheet_is_a_labelled_grid(tmp_path):
    out = tmp_path / "sheet.png"
    _ok(BREAM, PARAMS / "clouds" / "table_4_2.awn", PARAMS / "centroberyx.txt", "-o", out,
        "--size", "200x150", "--columns", "3")
    w, h = Image.open(out).size
    assert w == 600 and 150 < h < 200  # one row of three tiles plus a label strip


def test_a_sheet_has_no_more_columns_than_inputs():
    """QA pass 12: --columns 10**12 for two inputs was refused as a sheet of 8e14 pixels."""
    from fishgen.preview.sheet import grid

    assert grid(2, 10**12) == (2, 1) and grid(5, 2) == (2, 3) and grid(5, None) == (3, 2)


def test_gif_swim_loop_moves(tmp_path):
    out = tmp_path / "swim.gif"
    _ok(BREAM, "-o", out, "--frames", "6", "--size", "200x150", "--view", "top")
    gif = Image.open(out)
    assert gif.n_frames == 6
    frames = []
    for k in range(6):
        gif.seek(k)
        frames.append(np.asarray(gif.convert("RGB"), np.int16))
    assert any(np.abs(frames[0] - f).max() > 40 for f in frames[1:]), "the fins should move"


def test_webp_turntable_of_a_static_cloud(tmp_path):
    out = tmp_path / "spin.webp"
    _ok(PARAMS / "clouds" / "table_4_3.awn", "-o", out, "--frames", "4", "--size", "160x120")
    webp = Image.open(out)
    assert webp.n_frames == 4


def test_help_lists_every_option_with_default():
    text = " ".join(run_cli("preview", "--help").stdout.split())
    for option in ("--view", "--size", "--time", "--background", "--frames", "--columns", "--seed",
                   "--clip", "--textures", "--output"):
        assert option in text
    assert "default: 800x600" in text and "default: three-quarter" in text


@pytest.mark.parametrize("args,message", [
    (["-o", "x.bmp"], "expected an output ending in"),
    (["-o", "x.png", "--frames", "5"], "expected a .gif or .webp output"),
    (["-o", "x.png", "--size", "800"],
     "Invalid value for '--size': expected WxH with 16 to 8192 pixels a side"),
    (["-o", "x.png", "--background", "mauvish"], "Invalid value for '--background': expected a colour"),
    (["-o", "x.gif", "--background", "transparent"], "expected an opaque --background"),
    (["-o", "x.png", "--clip", "dance"], "expected --clip to name one of swim"),
    (["-o", "x.png", "--seed", "-1"], "Invalid value for '--seed': -1 is not in the range 0<=x<="),
    (["-o", "x.gif", "--size", "8192x8192", "--frames", "1000"], "expected at most 1073741824 pixels"),
    (["-o", "x.webp", "--size", "8192x8192", "--frames", "17"], "expected at most 1073741824 pixels"),
])
def test_bad_options_are_one_line_errors_and_write_nothing(tmp_path, args, message):
    args = [a if a not in ("x.bmp", "x.png", "x.gif") else str(tmp_path / a) for a in args]
    result = run_cli("preview", BREAM, *args)
    assert result.returncode == 2
    assert message in result.stderr and "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_a_clip_asked_of_inputs_without_clips_is_refused(tmp_path):
    """--clip on a cloud (no clips) did nothing, silently; a sheet where a fish has it still poses the
    fish and leaves the cloud as it is."""
    cloud = PARAMS / "clouds" / "table_4_3.awn"
    alone = run_cli("preview", cloud, "-o", tmp_path / "a.png", "--clip", "swim")
    assert alone.returncode == 2 and alone.stderr == (f"{cloud}: expected --clip to name an animation clip, "
                                                      "found 'swim', but the input has no clips\n")
    both = run_cli("preview", cloud, cloud, "-o", tmp_path / "b.png", "--clip", "swim")
    assert both.returncode == 2 and "but none of the inputs has clips" in both.stderr
    assert list(tmp_path.iterdir()) == []
    mixed = run_cli("preview", cloud, BREAM, "-o", tmp_path / "c.png", "--clip", "swim", "--size", "64x48")
    assert mixed.returncode == 0, mixed.stderr


def test_missing_and_bad_inputs_name_the_file(tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("this is not a species file\n")
    for path in (tmp_path / "nope.glb", bad):
        result = run_cli("preview", path, "-o", tmp_path / "out.png")
        assert result.returncode == 2, result.stderr
        assert str(path) in result.stderr and "Traceback" not in result.stderr
    assert not (tmp_path / "out.png").exists()


def test_negative_seed_for_a_cube_file_is_a_one_line_error(tmp_path):
    result = run_cli("preview", PARAMS / "clouds" / "table_4_2.awn", "-o", tmp_path / "s.png", "--seed", "-1")
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert result.stderr.strip() == ("fishgen preview: Invalid value for '--seed': -1 is not in the range "
                                     "0<=x<=9223372036854775807.")
    assert list(tmp_path.iterdir()) == []


def test_pixel_budget_is_checked_before_any_input_is_read(tmp_path):
    from fishgen.errors import FishgenError
    from fishgen.preview.pipeline import (
        MAX_SHEET_PIXELS,
        MAX_TOTAL_PIXELS,
        PreviewOptions,
        preview,
        sheet_size,
        total_pixels,
    )

    missing = [tmp_path / "a.glb", tmp_path / "b.glb"]
    huge = PreviewOptions(width=8192, height=8192, frames=1000)
    with pytest.raises(FishgenError, match=f"expected at most {MAX_TOTAL_PIXELS} pixels"):
        preview(missing, tmp_path / "x.gif", huge)
    wide = PreviewOptions(width=8192, height=8192, columns=10**9)  # one row of 5 tiles, 40,960 px wide
    with pytest.raises(FishgenError, match=f"expected a contact sheet of at most {MAX_SHEET_PIXELS}"):
        preview(missing * 4 + missing[:1], tmp_path / "x.png", wide)
    big_tiles = PreviewOptions(width=8192, height=8192)  # 2x2 tiles of 8192 px: a 17k x 17k sheet
    with pytest.raises(FishgenError, match="contact sheet"):
        preview(missing * 2, tmp_path / "x.png", big_tiles)
    # Ordinary requests stay well inside: a 36-frame HD loop, a 4K still, a sheet of 16 tiles.
    assert total_pixels(PreviewOptions(width=1920, height=1080), 36) < MAX_TOTAL_PIXELS
    assert total_pixels(PreviewOptions(width=3840, height=2160), 1) < MAX_TOTAL_PIXELS
    assert total_pixels(PreviewOptions(), 36, inputs=16) < MAX_TOTAL_PIXELS
    assert sheet_size(PreviewOptions(width=1920, height=1080), 16)[0] == 4 * 1920
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("output", ["bonybream.png", "bonybream_mask.png"])
def test_a_render_over_the_species_texture_is_refused(tmp_path, output):
    """Run where the species file's texture is bonybream.png, `-o bonybream.png` replaced it."""
    from tests.conftest import species_textured_as

    inputs = species_textured_as(tmp_path, "bonybream.png", "bonybream_mask.png")
    result = run_cli("preview", "bonybream.txt", "-o", output, cwd=tmp_path)
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert "not one of the command's inputs" in result.stderr
    assert {p: p.read_bytes() for p in inputs} == inputs


def test_a_render_over_a_texture_clouds_picture_is_refused(tmp_path):
    import shutil

    shutil.copy(PARAMS / "clouds" / "sky.awa", tmp_path)
    shutil.copytree(PARAMS.parent / "textures" / "clouds", tmp_path / "clouds")
    before = (tmp_path / "clouds" / "billow.png").read_bytes()
    result = run_cli("preview", "sky.awa", "-o", "clouds/billow.png", cwd=tmp_path)
    assert result.returncode == 2 and "not one of the command's inputs" in result.stderr, result.stderr
    assert (tmp_path / "clouds" / "billow.png").read_bytes() == before


def test_a_cube_file_over_the_particle_limit_names_no_option_preview_lacks(tmp_path):
    big = tmp_path / "big.awn"
    big.write_text("2000000000\n1\n2000000000, 1, 1, 1, 0, 0, 0, 1\n")
    result = run_cli("preview", big, "-o", tmp_path / "p.png")
    assert result.returncode == 2 and "--max-particles" not in result.stderr, result.stderr
    assert result.stderr == f"{big}:1: expected at most 50,000,000 particles, found 2,000,000,000\n"


@pytest.mark.parametrize("name, still", [("w.webp", True), ("w.png", True), ("w.gif", False)])
def test_a_duration_that_makes_no_loop_is_said(tmp_path, name, still):
    """`--fps 2 --duration 3 -o w.webp` wrote a still with no word: a .webp loops only with --frames."""
    out = tmp_path / name
    result = run_cli("preview", PARAMS / "bonybream.txt", "--size", "64x48", "--duration", "1", "-o", out)
    assert result.returncode == 0, result.stderr
    note = f"{out}: a still; --duration makes a loop in a .gif, or in a .webp with --frames\n"
    assert result.stderr == (note if still else "")
    assert (getattr(Image.open(out), "n_frames", 1) == 1) == still


def test_help_names_every_input_kind():
    text = " ".join(run_cli("preview", "--help").stdout.split())
    assert "a cloud cube file (.awn), a texture cloud (.awa) or an asset" in text   # .awa went unsaid


@pytest.mark.parametrize("name", ["swim.gif", "swim.webp"])
def test_a_loop_lasts_its_duration_though_a_gif_counts_in_hundredths(tmp_path, name):
    """38 frames over 3.2 s were stored as 38 x 80 ms: the loop played 5 % fast."""
    out = tmp_path / name
    _ok(BREAM, "--size", "32x24", "--frames", "7", "--duration", "0.6", "-o", out)
    with Image.open(out) as loop:
        times = []
        for k in range(loop.n_frames):
            loop.seek(k)
            loop.load()       # a WebP frame's duration is known once it is read
            times.append(loop.info["duration"])
    assert len(times) == 7 and sum(times) == 600 and max(times) - min(times) <= 10


def test_lighting_options_on_an_asset_say_they_light_cube_files_only(tmp_path, assets):
    """A glb's light is baked: --sun gave the same picture, and nothing said so (QA pass 9)."""
    result = run_cli("preview", str(assets["cloud.glb"]), "-o", str(tmp_path / "c.png"), "--sun", "-1,0.2,0")
    assert result.returncode == 0, result.stderr
    assert "the lighting options light cube files (.awn, .awa) only" in result.stderr
    quiet = run_cli("preview", str(PARAMS / "clouds" / "table_4_3.awn"), "-o", str(tmp_path / "d.png"),
                    "--sun", "-1,0.2,0")
    assert quiet.returncode == 0 and "light cube files" not in quiet.stderr


@pytest.mark.parametrize("size", ["1e-25", "1e-3"])
def test_a_cloud_at_the_origin_of_any_size_in_float32_range_is_drawn_framed(tmp_path, size):
    """A cloud 1e-25 across was a ZeroDivisionError traceback (near and far were one float), and
    until 1e-22 it was framed from 1e-6 away, a blank picture."""
    cubes = tmp_path / "c.awn"
    cubes.write_text(f"1\n1\n1, {size},{size},{size}, 0,0,0, {size}\n")
    out = tmp_path / "c.png"
    _ok(cubes, "-o", out)
    img = np.asarray(Image.open(out).convert("RGB"), np.int32)
    assert 0.1 < (np.abs(img - img[0, 0]).max(-1) > 10).mean() < 0.8


@pytest.mark.parametrize("cube, message", [
    ("3, 3e38,3e38,3e38, 0,0,0, 3e38", "a scene a float32 camera can frame"),   # drawn from infinities
    ("1, 1e-8,1e-8,1e-8, 1,1,1, 1e-8", "a scene large enough for a float32 camera"),  # eye == target
])
def test_a_cloud_a_float32_camera_cannot_frame_is_one_line_not_noise_or_blank(tmp_path, cube, message):
    cubes = tmp_path / "c.awn"
    cubes.write_text(f"{cube.split(',')[0]}\n1\n{cube}\n")
    result = run_cli("preview", cubes, "-o", tmp_path / "c.png")
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert result.stderr.startswith(f"{cubes}: expected {message}")
    assert not (tmp_path / "c.png").exists()
