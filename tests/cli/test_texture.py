"""`fishgen texture` from the command line: one command from photo to a buildable species, notes
for unseen fins, and one-line errors (exit 2, no traceback, nothing written) for bad photos."""
from __future__ import annotations

import platform
import re
import struct
import zlib

import numpy as np
import pytest
from PIL import Image, ImageDraw, ImageFilter

from tests.conftest import PARAMS, assert_valid_gltf, run_cli, run_cli_process

SMALL = (640, 320)


@pytest.fixture(scope="module")
def bream_photo(tmp_path_factory):
    from fishgen.species.parser import load_species
    from tests.authoring.photos import render_photo

    try:
        import moderngl

        moderngl.create_context(standalone=True, backend="egl").release()
    except Exception as err:  # noqa: BLE001 - any failure means no context
        pytest.fail(f"no headless OpenGL: install libegl1 libegl-mesa0 libgl1-mesa-dri ({err})")
    folder = tmp_path_factory.mktemp("photos")
    photo = render_photo(load_species(PARAMS / "bonybream.txt"), SMALL)
    photo.save(folder / "bream.png")
    return folder / "bream.png", photo


def test_photo_to_fish_in_one_command(tmp_path, cli, bream_photo):
    path, _ = bream_photo
    out = tmp_path / "out" / "mybream.txt"
    r = cli("texture", path, "-s", PARAMS / "bonybream.txt", "-o", out, "--compare", tmp_path / "cmp.png",
            "--fxl-out", tmp_path / "pts.FXL")
    assert r.returncode == 0, r.stderr
    assert "silhouette from the alpha" in r.stdout and "IoU" in r.stdout
    for name in ("mybream.txt", "mybream.png", "mybream_mask.png"):
        assert (out.parent / name).is_file()
    assert (tmp_path / "cmp.png").is_file() and (tmp_path / "pts.FXL").is_file()
    glb = tmp_path / "mybream.glb"
    b = cli("build", out, "-o", glb)
    assert b.returncode == 0, b.stderr
    assert_valid_gltf(glb)
    # Fixel's points carry over: reading the .FXL back gives the same species file.
    again = tmp_path / "again" / "mybream.txt"
    r2 = cli("texture", path, "-s", PARAMS / "bonybream.txt", "-o", again, "--fxl-in", tmp_path / "pts.FXL")
    assert r2.returncode == 0, r2.stderr
    assert again.read_text() == out.read_text()


def test_mirrored_jpeg_and_level_of_detail_options(tmp_path, cli, bream_photo):
    _, photo = bream_photo
    rgba = photo.rgba[:, ::-1]
    a = rgba[:, :, 3:4] / 255.0
    rgb = (rgba[:, :, :3] * a + np.array([180, 200, 215]) * (1 - a)).astype(np.uint8)
    exif = Image.Exif()
    exif.get_ifd(0x8769)[0xA405] = 85     # FocalLengthIn35mmFilm, as a camera writes it
    Image.fromarray(rgb).save(tmp_path / "p.jpg", quality=80, exif=exif)
    r = cli("texture", tmp_path / "p.jpg", "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "n.txt",
            "--body-sections", "24", "--circle-sections", "16", "--spacing", "even")
    assert r.returncode == 0, r.stderr
    assert "background model" in r.stdout and "head on the right" in r.stdout
    # the camera's lens is told, not taken: a cropped photo keeps its camera's figure
    assert "EXIF gives a 85 mm lens" in r.stderr and "give --focal-length 85" in r.stderr
    lines = (tmp_path / "n.txt").read_text().splitlines()
    assert str(24 * 16) in lines


def test_unseen_fin_falls_back_to_skin_and_says_so(tmp_path, cli, bream_photo):
    from fishgen.authoring.photo.sideview import side_view
    from fishgen.species.parser import load_species

    _, photo = bream_photo
    rgba = photo.rgba.copy()
    dorsal = photo.fins["dorsal"]
    img = Image.new("L", SMALL, 0)
    draw = ImageDraw.Draw(img)
    for tri in side_view(load_species(PARAMS / "bonybream.txt")).fin_faces["dorsal"]:
        draw.polygon([(float(x), float(y)) for x, y in dorsal[tri]], fill=255)
    grown = np.asarray(img.filter(ImageFilter.MaxFilter(5))) > 0
    top = dorsal[:, 1].max() - 3           # clear the fin down to just above its base line
    rgba[grown & (np.arange(SMALL[1])[:, None] < top), 3] = 0
    Image.fromarray(rgba).save(tmp_path / "nodorsal.png")
    r = cli("texture", tmp_path / "nodorsal.png", "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "n.txt")
    assert r.returncode == 0, r.stderr
    assert "no dorsal fin found in the photo" in r.stderr


def _png_header_only(path, width, height):
    """A PNG whose header claims ``width`` x ``height``: refused before a pixel is decoded."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    header = chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0))
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + header
                     + chunk(b"IDAT", zlib.compress(b"\0" * 64)) + chunk(b"IEND", b""))


def _photos(tmp_path, bream_photo):
    _, photo = bream_photo
    blank = np.zeros((SMALL[1], SMALL[0], 4), np.uint8)
    Image.fromarray(blank).save(tmp_path / "blank.png")
    two = np.zeros((SMALL[1], SMALL[0] * 2 + 20, 4), np.uint8)
    two[:, :SMALL[0]] = photo.rgba
    two[:, SMALL[0] + 20:] = photo.rgba
    Image.fromarray(two).save(tmp_path / "two.png")
    cols = np.flatnonzero(photo.rgba[:, :, 3].any(axis=0))
    Image.fromarray(np.ascontiguousarray(photo.rgba[:, cols[0] + 30:])).save(tmp_path / "cut.png")
    _png_header_only(tmp_path / "huge.png", 30000, 30000)   # PIL itself refuses this header
    _png_header_only(tmp_path / "big.png", 9000, 9000)      # PIL would decode it; fishgen does not
    (tmp_path / "notes.png").write_text("not a picture\n")
    (tmp_path / "phone.heic").write_bytes(b"\x00\x00\x00\x18ftypheic\x00\x00\x00\x00mif1heic" + bytes(64))
    Image.fromarray(photo.rgba[:40, :40]).save(tmp_path / "tiny.png")
    frames = [Image.fromarray(np.ascontiguousarray(rgba)).convert("RGB")
              for rgba in (photo.rgba, photo.rgba[:, ::-1])]
    frames[0].save(tmp_path / "swim.gif", save_all=True, append_images=frames[1:])  # 1st frame was used
    return {"swim.gif": "expected a still photo, found an animation of 2 frames",
            "blank.png": "expected a fish in the photo, found none",
            "two.png": "expected one fish, found 2 objects",
            "cut.png": "cut off at the left edge",
            "huge.png": "at most 64 megapixels, found 900 megapixels",
            "big.png": "at most 64 megapixels, found 9000 x 9000",
            "notes.png": "expected a photo",
            "phone.heic": "found a HEIF/HEIC picture, which fishgen cannot read (a phone's default)",
            "tiny.png": "at least 64 pixels a side",
            "missing.png": "found no such file"}


def test_bad_photos_get_one_line_errors_and_nothing_is_written(tmp_path, cli, bream_photo):
    for name, words in _photos(tmp_path, bream_photo).items():
        out = tmp_path / "o" / "x.txt"
        r = cli("texture", tmp_path / name, "-s", PARAMS / "bonybream.txt", "-o", out)
        assert r.returncode == 2, (name, r.stderr)
        assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1, (name, r.stderr)
        assert words in r.stderr, (name, r.stderr)
        assert str(tmp_path / name) in r.stderr, (name, r.stderr)
        assert not out.parent.exists() or not any(out.parent.iterdir()), name


def test_a_16_bit_grey_photo_is_scaled_to_8_bits_not_clipped_white(tmp_path, bream_photo):
    """Pillow converts I;16 to RGBA by clipping at 255: the photo read as all white ("no fish",
    or with --mask an all-white texture)."""
    from fishgen.authoring.photo.image import load_photo

    path, _ = bream_photo
    grey = np.asarray(Image.open(path).convert("L"))
    Image.fromarray(grey.astype(np.uint16) * 257).save(tmp_path / "grey16.png")
    assert Image.open(tmp_path / "grey16.png").mode == "I;16"
    photo = load_photo(tmp_path / "grey16.png")
    assert np.array_equal(photo.rgb[:, :, 0], grey) and np.array_equal(photo.rgb[:, :, 2], grey)


def test_failure_after_measuring_leaves_no_file(tmp_path, cli, bream_photo):
    path, _ = bream_photo
    (tmp_path / "cmp.png").mkdir()            # the comparison cannot be written
    r = cli("texture", path, "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "n.txt", "--compare",
            tmp_path / "cmp.png")
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert not (tmp_path / "n.txt").exists() and not (tmp_path / "n.png").exists()


def test_bad_mask_and_fxl(tmp_path, cli, bream_photo):
    path, _ = bream_photo
    Image.new("L", (10, 10)).resize((100, 100)).save(tmp_path / "m.png")
    r = cli("texture", path, "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "n.txt", "--mask",
            tmp_path / "m.png")
    assert r.returncode == 2 and "mask the size of the photo" in r.stderr
    (tmp_path / "p.FXL").write_text("//dorsal\n2\n0.1 0.2\n0.3 0.4\n")
    r = cli("texture", path, "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "n.txt", "--fxl-in",
            tmp_path / "p.FXL")
    assert r.returncode == 2 and "expected 8 //dorsal points" in r.stderr and "p.FXL" in r.stderr


def test_help_is_fast_and_lists_both_commands(cli):
    r = cli("--help")
    assert r.returncode == 0 and "texture" in r.stdout and "species" in r.stdout


def test_an_output_that_is_one_of_the_inputs_is_refused_and_nothing_is_written(tmp_path):
    """Issue 19: `-o base.txt` replaced the base species file silently."""
    import shutil

    base = tmp_path / "base.txt"
    shutil.copy(PARAMS / "bonybream.txt", base)
    before = base.read_bytes()
    result = run_cli("texture", PARAMS / "photos" / "bonybream-side.png", "-s", base, "-o", base)
    assert result.returncode == 2 and "is the input" in result.stderr and base.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["base.txt"]


def test_the_help_examples_read_as_one_command_each():
    lines = run_cli("texture", "--help").stdout.splitlines()
    example = [line.strip() for line in lines if line.strip().startswith("fishgen texture")]
    assert len(example) == 2 and example[1].endswith("\\")


@pytest.mark.parametrize("sections", ["3", "4"])
def test_the_coarsest_body_sections_still_give_fins_two_sections_each(tmp_path, sections):
    """--body-sections 3 and 4 were a shape-mismatch traceback: fins mapped onto one section."""
    out = tmp_path / "coarse.txt"
    r = run_cli("texture", PARAMS / "photos" / "bonybream-side.png", "-s", PARAMS / "bonybream.txt",
                "-o", out, "--body-sections", sections)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    built = run_cli("build", out, "-o", tmp_path / "coarse.glb")
    assert built.returncode == 0, built.stderr
    assert_valid_gltf(tmp_path / "coarse.glb")


def test_an_outline_too_thin_to_place_a_fin_is_one_line(tmp_path):
    """A 2000 x 64 photo at 3 body sections left the fins' places NaN: a traceback in _grown (fuzz
    finding photo:15:221, issue 26). Levelled by the coarse side view, as the command did, it was
    refused in one line: its pelvic fin (sections 9-12 of 32) was stretched to the tail's ring,
    where the outline is too thin. That fin now spans the section its middle lies in, and even
    that side view measures; levelled by the base as its file gives it, as the command does, too."""
    from fishgen.authoring.photo.image import load_photo
    from fishgen.authoring.photo.run import analyse
    from fishgen.authoring.photo.sideview import with_counts
    from fishgen.authoring.photo.silhouette import silhouette
    from fishgen.species.parser import load_species
    from tests.conftest import ROOT

    folder = ROOT / "tests" / "fixtures" / "thin_photo"
    mask = silhouette(load_photo(folder / "photo.png")).mask
    base = load_species(folder / "base.txt")
    coarse = with_counts(base, 3, 12)
    assert (coarse.pelvic.start_section, coarse.pelvic.end_section) == (0, 1)
    measured = analyse(mask, coarse)
    assert measured.fins and all(np.isfinite(np.asarray(fin.points)).all() for fin in measured.fins.values())
    r = run_cli("texture", folder / "photo.png", "-s", folder / "base.txt", "-o", tmp_path / "new.txt",
                "--body-sections", "3", "--circle-sections", "12")
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 0 and "Traceback" not in r.stderr and lines[-1].startswith("silhouette IoU")
    assert all(line.startswith("note: ") for line in lines[:-1])


def test_more_body_sections_than_the_photo_has_pixels_are_refused_at_once(tmp_path):
    """--body-sections 256 on a fish 64 px long took 31 s with --fit-shape (fuzz finding photo:13:239):
    two pixels a section at most, said before any work."""
    from tests.conftest import ROOT

    folder = ROOT / "tests" / "fixtures" / "small_photo"
    r = run_cli("texture", folder / "photo.png", "-s", folder / "base.txt", "-o", tmp_path / "new.txt",
                "--body-sections", "256", "--fit-shape")
    said = re.search(r"expected --body-sections of at most (\d+) for a fish (\d+) px long", r.stderr)
    assert r.returncode == 2 and said, r.stderr
    most, length = int(said[1]), int(said[2])
    assert 60 <= length <= 70 and most == length // 2          # the fixture's fish, fin tips and all
    assert not (tmp_path / "new.txt").exists()


def _sections_asked_of_an_oval(tmp_path, size: tuple[int, int], oval: tuple[int, int, int, int]):
    """`fishgen texture --body-sections 200` of a photo of ``size`` showing one golden ``oval``."""
    photo = tmp_path / "big.png"
    image = Image.new("RGBA", size, (0, 0, 0, 0))
    ImageDraw.Draw(image).ellipse(oval, fill=(200, 150, 50, 255))
    image.save(photo)
    return run_cli("texture", photo, "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "new.txt",
                   "--body-sections", "200")


def test_a_big_photo_s_section_limit_names_the_copy_it_is_measured_on(tmp_path):
    """A 4800 px photo of a small fish is measured on a 2048 px copy: the limit is that copy's, and
    says so."""
    r = _sections_asked_of_an_oval(tmp_path, (4800, 2400), (2100, 1100, 2700, 1300))
    said = re.search(r"at most (\d+) for a fish (\d+) px long in the 2048 x 1024 copy it is measured on",
                     r.stderr)
    assert r.returncode == 2 and said, r.stderr
    assert 254 <= int(said[2]) <= 258 and int(said[1]) == int(said[2]) // 2


def test_body_sections_a_big_photo_holds_are_taken_from_the_larger_copy(tmp_path):
    """A 1200 px fish in a 4000 px photo is 300 px long in the 1024 px copy: --body-sections 200 asks
    for more pixels than that, and the 2048 px copy (600 px of fish) has them, as before."""
    r = _sections_asked_of_an_oval(tmp_path, (4000, 2000), (1400, 850, 2600, 1150))
    assert r.returncode == 0, r.stderr


def test_focal_length_measures_the_rebuilt_fish_in_that_perspective(tmp_path, cli, bream_photo):
    """--focal-length: the rebuilt fish is rendered as that lens saw it. The photo here is an
    orthographic render, so a wide angle's view of the rebuilt fish is less like it than a side-on
    one; 0 mm is a one-line usage error."""
    path, _ = bream_photo

    def figure(*extra):
        out = tmp_path / f"x{len(extra)}.txt"
        r = cli("texture", path, "-s", PARAMS / "bonybream.txt", "-o", out, *extra)
        assert r.returncode == 0, r.stderr
        return float(re.search(r"silhouette IoU of the rebuilt fish: ([0-9.]+)", r.stdout).group(1))

    assert figure("--focal-length", "18") < figure() - 0.01
    bad = cli("texture", path, "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "y.txt",
              "--focal-length", "0")
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1, bad.stderr
    assert "--focal-length" in bad.stderr


@pytest.mark.parametrize("args,twice", [   # (--compare or --fxl-out over -o: refused by their extensions)
    (["-o", "out/c.txt", "--compare", "out/c.png"], "out/c.png"),        # the new species' texture
    (["-o", "out/h.txt", "--compare", "out/h_mask.png"], "out/h_mask.png"),  # and its mask
])
def test_outputs_that_name_one_file_are_refused_before_fitting(tmp_path, args, twice):
    """The comparison picture or the .FXL file over the species file, its texture or its mask:
    the later write replaced the earlier, exit 0."""
    result = run_cli("texture", PARAMS / "photos" / "bonybream-side.png", "-s", PARAMS / "bonybream.txt",
                     *args, cwd=tmp_path)
    assert result.returncode == 2 and result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
    assert f"found {twice} twice" in result.stderr and list(tmp_path.iterdir()) == []


def test_an_output_over_the_base_species_texture_is_refused(tmp_path):
    import shutil

    shutil.copy(PARAMS / "bonybream.txt", tmp_path)
    for name in ("bonybream.png", "bonybream_mask.png"):
        shutil.copy(PARAMS.parent / "textures" / name, tmp_path)
    before = (tmp_path / "bonybream.png").read_bytes()
    result = run_cli("texture", PARAMS / "photos" / "bonybream-side.png", "-s", "bonybream.txt", "-o",
                     "new.txt", "--compare", "bonybream.png", cwd=tmp_path)
    assert result.returncode == 2 and "not one of the command's inputs" in result.stderr, result.stderr
    assert (tmp_path / "bonybream.png").read_bytes() == before and not (tmp_path / "new.txt").exists()


def test_quiet_silences_the_summary_and_without_it_the_summary_is_on_stdout(tmp_path, cli, bream_photo):
    """The silhouette's source and IoU went to stderr, where -q left them."""
    path, _ = bream_photo
    loud = cli("texture", path, "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "a.txt")
    assert loud.returncode == 0 and loud.stderr == "", loud.stderr
    assert loud.stdout.startswith("silhouette from the alpha")
    assert "silhouette IoU of the rebuilt fish" in loud.stdout
    quiet = cli("texture", path, "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "b.txt", "-q")
    assert (quiet.returncode, quiet.stdout, quiet.stderr) == (0, "", "")


def test_o_names_the_species_file_exactly_and_its_textures_beside_it(tmp_path, cli, bream_photo):
    """QA: the README's `-o out/bream-fit.txt` wrote bream_fit.png, `-o "out/ünï 🐟.txt"` n.png."""
    path, _ = bream_photo
    r = cli("texture", path, "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "bream-fit.txt")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bream-fit.png", "bream-fit.txt",
                                                          "bream-fit_mask.png"]
    out = tmp_path / "u" / "ünï 🐟.txt"
    r = cli("texture", path, "-s", PARAMS / "bonybream.txt", "-o", out)
    assert r.returncode == 0, r.stderr
    assert r.stderr.startswith("note: textures named ünï_🐟.png and ünï_🐟_mask.png")
    assert sorted(p.name for p in out.parent.iterdir()) == ["ünï 🐟.txt", "ünï_🐟.png", "ünï_🐟_mask.png"]
    assert cli("build", out, "-o", tmp_path / "u.glb").returncode == 0


def test_a_derived_texture_name_that_is_another_output_is_refused_before_any_work(tmp_path, cli):
    r = cli("texture", PARAMS / "photos" / "bonybream-side.png", "-s", PARAMS / "bonybream.txt",
            "-o", tmp_path / "a b.txt", "--compare", tmp_path / "a_b.png")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "a_b.png" in r.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("option,name,said", [
    ("--compare", "cmp.jpg", "--compare ending in .png, found '.jpg'"),
    ("--compare", "cmp", "--compare ending in .png, found 'no extension'"),
    ("--fxl-out", "pts.png", "--fxl-out ending in .fxl, found '.png'")])
def test_a_side_output_named_for_another_format_is_refused(tmp_path, cli, bream_photo, option, name, said):
    """--compare wrote PNG bytes into cmp.jpg, and --fxl-out Fixel text into pts.png."""
    photo, _ = bream_photo
    r = cli("texture", photo, "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "n.txt", option,
            tmp_path / name)
    assert r.returncode == 2 and said in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert not any(tmp_path.iterdir())


def test_a_folder_where_a_texture_goes_is_named_and_refused_before_the_work(tmp_path, cli, bream_photo):
    """It was said after the measuring, as the photo's fault: `photo.png: …, found a folder at d.png`."""
    photo, _ = bream_photo
    (tmp_path / "d.png").mkdir()
    r = cli("texture", photo, "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "d.txt")
    said = f"{tmp_path / 'd.png'}: expected an output file, found a folder\n"
    assert r.returncode == 2 and r.stderr == said


def test_a_photo_in_perspective_is_told_to_give_its_focal_length(tmp_path, cli):
    """fishgen preview's own side view is a 50 mm one: ThreadfinGoldie on its own geometry read 0.730
    and was told only to try --fit-shape; told the lens it reads 0.868."""
    photo = tmp_path / "goldie.png"
    assert cli("preview", PARAMS / "threadfingoldie.txt", "--view", "side", "-o", photo).returncode == 0
    plain = cli("texture", photo, "-s", PARAMS / "threadfingoldie.txt", "-o", tmp_path / "a.txt")
    assert plain.returncode == 0
    assert "try --fit-shape; if it was taken close up, give --focal-length" in plain.stderr
    told = cli("texture", photo, "-s", PARAMS / "threadfingoldie.txt", "-o", tmp_path / "b.txt",
               "--focal-length", "50")
    figure = float(re.search(r"silhouette IoU of the rebuilt fish: ([0-9.]+)", told.stdout).group(1))
    assert figure >= 0.85 and "--focal-length" not in told.stderr


def test_a_base_species_is_read_for_its_geometry_alone(tmp_path, cli, bream_photo):
    """A base copied without its textures failed every run (`base.txt:32: expected an existing
    texture file`), though texture never reads them."""
    import shutil

    photo, _ = bream_photo
    shutil.copy(PARAMS / "bonybream.txt", tmp_path / "base.txt")
    r = cli("texture", photo, "-s", tmp_path / "base.txt", "-o", tmp_path / "new.txt")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["base.txt", "new.png", "new.txt", "new_mask.png"]


@pytest.mark.parametrize("option", ["--body-sections", "--circle-sections"])
def test_a_level_photo_stays_level_at_any_level_of_detail(tmp_path, cli, bream_photo, option):
    """The photo's level is the photo's: at 3 body sections the blocky tail's drop turned a level
    photo by 6 degrees (and the rebuilt fish read 0.56 where it reads 0.72)."""
    photo, _ = bream_photo
    plain = cli("texture", photo, "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "a.txt")
    coarse = cli("texture", photo, "-s", PARAMS / "bonybream.txt", "-o", tmp_path / "b.txt", option, "3")
    assert plain.returncode == coarse.returncode == 0
    assert "turned" not in plain.stdout and "turned" not in coarse.stdout, coarse.stdout


def test_more_body_sections_keep_the_fins_shape(tmp_path, cli, bream_photo):
    """`--body-sections 96` shrank ThreadfinGoldie's dorsal and anal fins to spikes (IoU 0.882; 0.631
    at 256): a fin's proportion is per section, and it was copied unchanged (QA pass 10). The
    levels of detail already converted it."""
    import re

    from fishgen.species.parser import load_species
    from tests.authoring.photos import render_photo

    photo = tmp_path / "goldie.png"
    render_photo(load_species(PARAMS / "threadfingoldie.txt"), SMALL).save(photo)
    figures = []
    for sections in ("24", "96"):
        r = cli("texture", photo, "-s", PARAMS / "threadfingoldie.txt", "-o", tmp_path / f"g{sections}.txt",
                "--body-sections", sections)
        assert r.returncode == 0, r.stderr
        figures.append(float(re.search(r"silhouette IoU of the rebuilt fish: ([0-9.]+)", r.stdout)[1]))
    assert figures[1] > 0.95 and figures[1] > figures[0] - 0.03, figures


def test_a_greyscale_photo_that_misfits_says_so_not_that_the_base_is_wrong(tmp_path, cli):
    """A grey copy of a fish over water of about its head's grey: the nose is lost to the backdrop,
    and the advice blamed the base's geometry ("try --fit-shape") on the base's own photo (QA pass
    10); --mask is what helps."""
    from PIL import Image

    photo = tmp_path / "grey.png"
    r = cli("preview", PARAMS / "threadfingoldie.txt", "--view", "side", "--ortho", "-o", tmp_path / "c.png")
    assert r.returncode == 0, r.stderr
    Image.open(tmp_path / "c.png").convert("L").save(photo)
    r = cli("texture", photo, "-s", PARAMS / "threadfingoldie.txt", "-o", tmp_path / "g.txt")
    assert r.returncode == 0, r.stderr
    iou = float(r.stdout.split("silhouette IoU of the rebuilt fish: ")[1].split()[0])
    if iou < 0.85:
        assert "a greyscale photo" in r.stderr and "give --mask" in r.stderr and "--fit-shape" not in r.stderr
    else:   # a renderer that draws this fish apart from its water: nothing to advise
        assert "greyscale" not in r.stderr


@pytest.mark.skipif(platform.machine() not in ("x86_64", "AMD64"), reason="OpenBLAS's x86-64 kernels")
def test_the_species_file_is_the_same_whichever_blas_kernel_maps_the_points(tmp_path):
    """The texture points pass through products BLAS computes, whose kernel follows the CPU:
    OpenBLAS's for SSE3 (Prescott, which any x86-64 runs) changed one point's last bit."""
    def species(folder: str, kernel: str | None) -> bytes:
        out = tmp_path / folder / "fish.txt"
        out.parent.mkdir()
        done = run_cli_process("-q", "texture", PARAMS / "photos" / "bonybream-side.png",
                               "-s", PARAMS / "centroberyx.txt", "-o", out, env={"OPENBLAS_CORETYPE": kernel})
        assert done.returncode == 0, done.stderr
        return out.read_bytes()

    assert species("default", None) == species("sse3", "Prescott")
