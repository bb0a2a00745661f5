"""`fishgen build` as a user meets it: outputs, one-line errors, nothing lost."""
from __future__ import annotations

import shutil

import pytest

from tests.conftest import PARAMS, ROOT, assert_valid_gltf, run_cli


def test_build_default_species_to_glb(tmp_path):
    out = tmp_path / "bonybream.glb"
    result = run_cli("build", PARAMS / "bonybream.txt", "-o", out)
    assert result.returncode == 0, result.stderr
    assert result.stderr == "" and result.stdout.count("\n") == 1      # one summary line, on stdout
    assert "bonybream" in result.stdout and "swim loop 3.20 s, body wave 1.56 Hz" in result.stdout
    assert_valid_gltf(out)


def test_obj_summary_says_the_animation_is_not_kept(tmp_path):
    result = run_cli("build", PARAMS / "bonybream.txt", "-o", tmp_path / "b.obj")
    assert result.returncode == 0, result.stderr
    assert "swim loop" not in result.stdout
    assert result.stdout.count("rest pose only (OBJ holds no node animation, morph targets, alpha cutoff "
                               "or double-sided faces)") == 1


def test_a_cube_file_says_which_command_builds_it(tmp_path):
    result = run_cli("build", PARAMS / "clouds" / "table_4_3.awn", "-o", tmp_path / "x.glb")
    assert result.returncode == 2 and result.stderr.count("\n") == 1
    assert ("found a .awn file (RekAwan cloud cube file, by its extension); use `fishgen clouds` for it"
            in result.stderr)


def test_help_documents_every_option():
    result = run_cli("build", "--help")
    assert result.returncode == 0
    for option in ("--output", "--fins", "--length", "--fps", "--textures"):
        assert option in result.stdout
    assert "[default: 30]" in result.stdout


def test_top_level_help_is_light():
    import subprocess
    import sys
    code = ("import sys, fishgen.cli as c\n"
            "sys.argv=['fishgen','--help']\n"
            "try: c.main()\nexcept SystemExit: pass\n"
            "print('numpy' in sys.modules, 'trimesh' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert out.stdout.strip().splitlines()[-1] == "False False"


def _species_copy(tmp_path, transform=lambda t: t):
    for tex in ("bonybream.png", "bonybream_mask.png"):
        shutil.copy(ROOT / "textures" / tex, tmp_path / tex)
    path = tmp_path / "fish.txt"
    path.write_text(transform((PARAMS / "bonybream.txt").read_text()))
    return path


@pytest.mark.parametrize("transform,needle", [
    (lambda t: t.replace("0.26 0.1 0.04", "0.26 0.1"), "expected the body scale record"),
    (lambda t: t.replace("bonybream.png bonybream_mask.png", "../../etc/passwd bonybream_mask.png"),
     "expected a texture path inside"),
    (lambda t: t[:2000], "found end of file"),
])
def test_bad_input_one_line_error_no_output_no_clobber(tmp_path, transform, needle):
    species = _species_copy(tmp_path, transform)
    out = tmp_path / "fish.glb"
    out.write_bytes(b"the good file from yesterday")
    result = run_cli("build", species, "-o", out)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr
    assert lines[0].startswith(f"{species}:") and needle in lines[0]
    assert out.read_bytes() == b"the good file from yesterday"
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []


def test_failed_write_leaves_no_partial_file(tmp_path):
    species = _species_copy(tmp_path)
    blocker = tmp_path / "out"
    blocker.write_text("a file where a folder should be")
    result = run_cli("build", species, "-o", blocker / "fish.glb")
    assert result.returncode != 0 and "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_every_format_from_the_command_line(tmp_path):
    for ext in ("glb", "gltf", "obj", "ply"):
        result = run_cli("build", PARAMS / "pineapplefish.txt", "-o", tmp_path / f"p.{ext}",
                         "--fins", "opaque", "--length", "0.2")
        assert result.returncode == 0, result.stderr
    assert_valid_gltf(tmp_path / "p.glb", tmp_path / "p.gltf")


def test_missing_species_file(tmp_path):
    result = run_cli("build", tmp_path / "nope.txt", "-o", tmp_path / "x.glb")
    assert result.returncode == 2 and "expected a species file, found no such file" in result.stderr


def test_batch_builds_every_good_file_and_reports_each_bad_one(tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("nothing like a species\n")
    out = tmp_path / "assets"
    result = run_cli("build", PARAMS / "bonybream.txt", bad, PARAMS / "pineapplefish.txt", "-o", f"{out}/",
                     "--format", "gltf")
    assert result.returncode == 2
    assert sorted(p.name for p in out.glob("*.gltf")) == ["bonybream.gltf", "pineapplefish.gltf"]
    errors = [line for line in result.stderr.splitlines() if line.startswith(str(bad))]
    assert len(errors) == 1 and ":1: expected the header record" in errors[0]
    assert "Traceback" not in result.stderr
    assert_valid_gltf(out / "bonybream.gltf", out / "pineapplefish.gltf")


def test_batch_refuses_two_files_that_would_write_one_output(tmp_path):
    for sub in ("a", "b"):
        (tmp_path / sub).mkdir()
        shutil.copy(PARAMS / "bonybream.txt", tmp_path / sub / "fish.txt")
    result = run_cli("build", tmp_path / "a" / "fish.txt", tmp_path / "b" / "fish.txt",
                     "-o", f"{tmp_path}/out/")
    assert result.returncode == 2 and "distinct names" in result.stderr
    assert not (tmp_path / "out").exists()


def test_batch_refuses_a_file_name_as_its_folder(tmp_path):
    result = run_cli("build", PARAMS / "bonybream.txt", PARAMS / "centroberyx.txt",
                     "-o", tmp_path / "two.glb")
    assert result.returncode == 2 and "expected a folder for 2 species files" in result.stderr
    assert not (tmp_path / "two.glb").exists()


def test_damaged_texture_is_reported_at_the_texture_line_and_the_batch_goes_on(tmp_path):
    species = _species_copy(tmp_path)
    png = (ROOT / "textures" / "bonybream.png").read_bytes()
    (tmp_path / "bonybream.png").write_bytes(png[: len(png) // 3])
    result = run_cli("build", species, PARAMS / "centroberyx.txt", "-o", f"{tmp_path}/batch/")
    assert result.returncode == 2
    line = next(i for i, row in enumerate(species.read_text().splitlines(), 1)
                if row.startswith("bonybream.png"))
    assert (f"{species}:{line}: expected a readable texture image, found 'bonybream.png' damaged"
            in result.stderr)
    assert ((tmp_path / "batch" / "centroberyx.glb").is_file()
            and not (tmp_path / "batch" / "fish.glb").exists())


def test_output_names_that_need_percent_encoding(tmp_path):
    out = tmp_path / "a b#1.gltf"
    assert run_cli("build", PARAMS / "pineapplefish.txt", "-o", out).returncode == 0
    assert_valid_gltf(out)


@pytest.mark.parametrize("name", ["pòisson.ply", "my fish.ply", "pòisson.obj"])
def test_a_textured_mesh_of_any_name_reads_back_with_its_texture(tmp_path, name):
    """`build -o pòisson.ply` was a traceback: the PLY's header named its texture in ASCII."""
    from fishgen.exchange.mesh_reader import read_mesh_file

    out = tmp_path / name
    result = run_cli("build", PARAMS / "bonybream.txt", "-o", out)
    assert result.returncode == 0, result.stderr
    scene = read_mesh_file(out)
    assert scene.images and scene.images[0].rgba().shape[2] == 4


def test_an_existing_folder_is_a_folder_whatever_its_name(tmp_path):
    (tmp_path / "x.glb").mkdir()
    result = run_cli("build", PARAMS / "bonybream.txt", "-o", tmp_path / "x.glb")
    assert result.returncode == 0 and (tmp_path / "x.glb" / "bonybream.glb").is_file()


@pytest.mark.parametrize("output,message", [
    ("fish", "expected an output file with an extension, or a folder "
             "(an existing one, or a name ending in /), found"),
    ("fish.txt", "expected an output ending in .glb, .gltf, .obj, .ply"),
])
def test_o_never_turns_silently_into_a_folder(tmp_path, output, message):
    """Issue 19: `-o out/fish` made a folder `fish/`; a folder must exist or end in /."""
    result = run_cli("build", PARAMS / "bonybream.txt", "-o", tmp_path / output)
    assert result.returncode == 2 and message in result.stderr and result.stderr.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_a_name_ending_in_a_slash_is_a_folder(tmp_path):
    result = run_cli("build", PARAMS / "bonybream.txt", "-o", f"{tmp_path}/fish/")
    assert result.returncode == 0 and (tmp_path / "fish" / "bonybream.glb").is_file()


def test_o_dev_null_is_not_a_regular_file(tmp_path):
    result = run_cli("build", PARAMS / "bonybream.txt", "-o", "/dev/null")
    assert result.returncode == 2 and "expected a regular file or no file as the output" in result.stderr


def test_special_files_are_refused_without_reading(tmp_path):
    result = run_cli("build", "/dev/zero", "-o", tmp_path / "x.glb")
    assert result.returncode == 2 and "expected a regular species file" in result.stderr


def test_a_batch_manifest_given_to_build_points_to_batch(tmp_path):
    """Issue 19: it was taken for a school scene ("use fishgen school")."""
    result = run_cli("build", PARAMS / "assets.toml", "-o", tmp_path / "x.glb")
    assert result.returncode == 2 and result.stderr.count("\n") == 1
    assert "found a batch manifest; use `fishgen batch` for it" in result.stderr


@pytest.mark.parametrize("output", ["o.gltf", "o.obj", "o.ply", "p.gltf"])
def test_an_output_whose_side_files_are_the_species_textures_is_refused(tmp_path, output):
    """A species whose textures are o_skin.png and o_skin_mask.png: `-o o.gltf` (or .obj) wrote its
    own o_skin.png over them, exit 0. The textures a species file names are inputs too."""
    from tests.conftest import species_textured_as

    inputs = species_textured_as(tmp_path, "o_skin.png", "o_skin_mask.png")
    result = run_cli("build", "bonybream.txt", "-o", output, cwd=tmp_path)
    if output == "p.gltf":  # p_skin.png: another name
        assert result.returncode == 0, result.stderr
    else:
        assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
        assert "not one of the command's inputs" in result.stderr and "o_skin" in result.stderr
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in inputs)
    assert {p: p.read_bytes() for p in inputs} == inputs


@pytest.mark.parametrize("output", ["o.gltf", "o.obj", "o.ply"])
def test_an_output_beside_its_species_own_textures_is_built(tmp_path, output):
    """`fishgen species -o o.txt` writes o.png and o_mask.png; `build o.txt -o o.ply` writes only
    o_skin.png beside it, yet was refused because o_mask.png matched o_*.png (QA pass 10)."""
    from tests.conftest import species_textured_as

    inputs = species_textured_as(tmp_path, "o.png", "o_mask.png")
    result = run_cli("build", "bonybream.txt", "-o", output, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "o_skin.png").is_file()
    assert {p: p.read_bytes() for p in inputs} == inputs


def test_a_texture_past_pillows_own_limit_is_one_line(tmp_path):
    from tests.species.test_parser import png_header

    shutil.copy(PARAMS / "bonybream.txt", tmp_path)
    shutil.copy(ROOT / "textures" / "bonybream_mask.png", tmp_path)
    (tmp_path / "bonybream.png").write_bytes(png_header(100_000, 100_000))
    result = run_cli("build", tmp_path / "bonybream.txt", "-o", tmp_path / "b.glb")
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert "expected a texture of at most 8192 pixels a side, found 'bonybream.png' of 10,000,000,000" \
        in result.stderr


def test_with_several_inputs_one_refused_output_is_a_usage_line_naming_the_command(tmp_path):
    """Each input's refusal reads as every usage error does, `fishgen build: ...`, and the other
    inputs are built (the line had no command before it)."""
    from tests.conftest import species_textured_as

    inputs = species_textured_as(tmp_path, "bonybream_skin.png", "bonybream_skin_mask.png")
    result = run_cli("build", "bonybream.txt", PARAMS / "pineapplefish.txt", "-o", "./", "--format", "gltf",
                     cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.startswith("fishgen build: expected an output that is not one of the command's "
                                    "inputs, found 'bonybream.gltf'") and result.stderr.count("\n") == 1
    assert (tmp_path / "pineapplefish.gltf").is_file() and not (tmp_path / "bonybream.gltf").exists()
    assert {p: p.read_bytes() for p in inputs} == inputs


def test_the_summary_names_the_fins_a_coarse_level_drops(tmp_path):
    from click.testing import CliRunner

    from fishgen.cli import cli

    ran = CliRunner().invoke(cli, ["build", str(PARAMS / "bonybream.txt"), "--lods", "32x24,16x12,8x6",
                                   "-o", str(tmp_path / "b.glb")])
    assert ran.exit_code == 0
    assert "levels 32x24 (1518), 16x12 (376), 8x6 (92; no adipose or anal fins)" in ran.output


@pytest.mark.parametrize("lods, output", [("8x6", "b.glb"), ("8x6", "b.ply")])
def test_the_summary_names_the_fins_of_the_one_level_written(tmp_path, lods, output):
    """`--lods 8x6` alone (or first, to a format of one level) dropped two fins unsaid (QA pass 10)."""
    from click.testing import CliRunner

    from fishgen.cli import cli

    ran = CliRunner().invoke(cli, ["build", str(PARAMS / "bonybream.txt"), "--lods", lods,
                                   "-o", str(tmp_path / output)])
    assert ran.exit_code == 0, ran.output
    assert "8x6 (no adipose or anal fins)" in ran.output


def test_one_input_never_overwrites_a_texture_another_input_names(tmp_path):
    """b.txt's skin is a_skin.png, which building a.txt to a.gltf writes: `build a.txt b.txt` replaced
    it and built b with a's skin, exit 0 (review of QA pass 10's fixes). a is refused, b is built."""
    text = (PARAMS / "bonybream.txt").read_text()
    assert text.count("bonybream.png bonybream_mask.png") == 1
    (tmp_path / "a.txt").write_text(text.replace("bonybream.png bonybream_mask.png", "ta.png tam.png"))
    (tmp_path / "b.txt").write_text(text.replace("bonybream.png bonybream_mask.png", "a_skin.png tbm.png"))
    for name, source in (("ta.png", "bonybream.png"), ("tam.png", "bonybream_mask.png"),
                         ("a_skin.png", "bonybream.png"), ("tbm.png", "bonybream_mask.png")):
        shutil.copy(ROOT / "textures" / source, tmp_path / name)
    before = (tmp_path / "a_skin.png").read_bytes()
    result = run_cli("build", "a.txt", "b.txt", "-o", "./", "--format", "gltf", cwd=tmp_path)
    assert result.returncode == 2 and "a_skin" in result.stderr, result.stderr
    assert (tmp_path / "a_skin.png").read_bytes() == before
    assert (tmp_path / "b.gltf").is_file() and not (tmp_path / "a.gltf").exists()


def test_a_texture_whose_exif_block_is_damaged_builds_and_says_nothing(tmp_path):
    """A JPEG texture with a damaged EXIF block: Pillow warns each time it opens the file, two lines
    naming its own source (five times for one preview); fishgen reads nothing there, so nothing is
    said (a subprocess: Python itself prints the warning)."""
    from PIL import Image

    from tests.conftest import run_cli_process

    species = _species_copy(tmp_path)
    with Image.open(ROOT / "textures" / "bonybream.png") as img:
        img.convert("RGB").save(tmp_path / "skin.jpg", exif=b"Exif\x00\x00II*\x00\xff\xff\xff\x7f")
    species.write_text(species.read_text().replace("bonybream.png bonybream_mask.png",
                                                   "skin.jpg bonybream_mask.png"))
    for args in (("build", species, "-o", tmp_path / "f.glb"),
                 ("preview", species, "-o", tmp_path / "f.png")):
        done = run_cli_process(*args)
        assert done.returncode == 0 and done.stderr == "", done.stderr
