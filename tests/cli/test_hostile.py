"""Hostile inputs the fuzzing of issue 8 found, one test per class: one line on stderr, exit 2,
no traceback, no output, bounded memory."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from tests.conftest import PARAMS, ROOT, run_cli

BONY = (PARAMS / "bonybream.txt").read_text()


def species_file(tmp_path, name, text):
    """A species file in tmp_path/params with BonyBream's textures copied into tmp_path/textures."""
    (tmp_path / "params").mkdir(exist_ok=True)
    (tmp_path / "textures").mkdir(exist_ok=True)
    for png in (ROOT / "textures").glob("bonybream*.png"):
        (tmp_path / "textures" / png.name).write_bytes(png.read_bytes())
    path = tmp_path / "params" / name
    path.write_text(text)
    return path


def one_line_error(result, *fragments):
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr and result.stderr.count("\n") == 1, result.stderr
    for fragment in fragments:
        assert fragment in result.stderr, result.stderr


@pytest.mark.parametrize("step", ["1e-320", "1e-300", "0.0000001"])
def test_absurd_fin_step_size_is_refused_at_its_line(tmp_path, step):
    species = species_file(tmp_path, "slow.txt", BONY.replace("3.0 10.0 1.0\n", f"3.0 10.0 {step}\n"))
    line = next(n for n, text in enumerate(species.read_text().splitlines(), 1) if text.endswith(step))
    result = run_cli("build", species, "-o", tmp_path / "x.glb")
    one_line_error(result, f"slow.txt:{line}: expected a fin cycle")
    assert not (tmp_path / "x.glb").exists()


def test_one_bad_species_does_not_abort_the_others(tmp_path):
    bad = species_file(tmp_path, "bad.txt", BONY.replace("3.0 10.0 1.0\n", "3.0 10.0 1e-320\n"))
    result = run_cli("build", bad, PARAMS / "centroberyx.txt", "-o", f"{tmp_path}/out/")
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert (tmp_path / "out" / "centroberyx.glb").is_file() and not (tmp_path / "out" / "bad.glb").exists()


@pytest.mark.parametrize("option", [["--fps", "1e-40"], ["--fps", "0"], ["--fps", "inf"], ["--fps", "nan"],
                                    ["--length", "1e-300"], ["--length", "inf"]])
def test_numeric_options_have_sane_ranges(tmp_path, option):
    result = run_cli("build", PARAMS / "bonybream.txt", "-o", tmp_path / "x.glb", *option)
    one_line_error(result, f"Invalid value for '{option[0]}'")
    assert list(tmp_path.iterdir()) == []


def test_no_output_ever_holds_a_non_finite_number():
    import numpy as np

    from fishgen.errors import FishgenError
    from fishgen.exchange.gltf import glb_bytes
    from fishgen.scene.model import Mesh, Node, Primitive, Scene

    bad_node = Scene()
    bad_node.add_node(Node("n", translation=(float("inf"), 0.0, 0.0)))
    points = Primitive({"POSITION": np.array([[0, 0, np.nan]], np.float32)}, mode="POINTS")
    bad_array = Scene(meshes=[Mesh("m", [points])])
    bad_array.add_node(Node("n", mesh=0))
    for scene in (bad_node, bad_array):
        with pytest.raises(FishgenError, match="expected finite numbers"):
            glb_bytes(scene)


@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_a_special_file_at_the_target_is_refused_not_replaced(tmp_path, kind):
    if kind == "fifo":
        target = tmp_path / "pipe.glb"
        os.mkfifo(target)
    else:
        target = tmp_path / "null.glb"
        if os.geteuid() != 0:
            pytest.skip("making a device node needs root")  # CI runs as root
        os.mknod(target, 0o666 | 0o020000, os.makedev(1, 3))  # a character device like /dev/null
    before = os.stat(target)
    for args in (["build", PARAMS / "bonybream.txt", "-o", target],
                 ["clouds", PARAMS / "clouds" / "table_4_2.awn", "-o", target]):
        one_line_error(run_cli(*args), "expected a regular file or no file as the output")
        after = os.stat(target)
        assert (after.st_mode, after.st_ino) == (before.st_mode, before.st_ino)
    assert sorted(p.name for p in tmp_path.iterdir()) == [target.name]


@pytest.mark.parametrize("name,content", [("trunc.glb", None), ("garbage.ply", b"garbage\n"),
                                          ("garbage.obj", b"v 1 2\nf 1 2 3\n")])
def test_view_parses_what_it_would_embed(tmp_path, name, content):
    path = tmp_path / name
    if content is None:
        full = tmp_path / "full.glb"
        assert run_cli("build", PARAMS / "bonybream.txt", "-o", full).returncode == 0
        content = full.read_bytes()[:100]
        full.unlink()
    path.write_bytes(content)
    result = run_cli("view", path, "--no-serve")
    one_line_error(result, str(path))
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]


def test_species_file_may_start_with_a_byte_order_mark(tmp_path):
    species = species_file(tmp_path, "bom.txt", "")
    species.write_bytes(b"\xef\xbb\xbf" + BONY.encode())
    result = run_cli("build", species, "-o", tmp_path / "x.glb")
    assert result.returncode == 0, result.stderr


def test_a_huge_line_is_refused_before_it_is_split(tmp_path):
    lines = BONY.splitlines()
    at = next(k for k, text in enumerate(lines) if text.startswith("FishShape"))
    lines[at] += " 0.5 0.3" * 2_000_000
    species = tmp_path / "huge.txt"
    species.write_text("\n".join(lines))
    code = ("import resource, sys; from fishgen.cli import main; "
            f"resource.setrlimit(resource.RLIMIT_AS, ({1 << 30}, {1 << 30})); "
            f"main(['build', {str(species)!r}, '-o', {str(tmp_path / 'x.glb')!r}])")
    result = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                            timeout=60)
    one_line_error(result, f"huge.txt:{at + 1}: expected the shape record", "16,000,0")


def test_symlinked_textures_folder_is_not_followed_out_unless_named(tmp_path):
    (tmp_path / "params").mkdir()
    (tmp_path / "params" / "b.txt").write_text(BONY)
    (tmp_path / "textures").symlink_to(ROOT / "textures")  # leads outside tmp_path
    result = run_cli("build", tmp_path / "params" / "b.txt", "-o", tmp_path / "x.glb")
    one_line_error(result, "expected an existing texture file, found 'bonybream.png' missing")
    named = run_cli("build", tmp_path / "params" / "b.txt", "-o", tmp_path / "x.glb",
                    "--textures", tmp_path / "textures")
    assert named.returncode == 0, named.stderr


def test_preview_of_a_tiny_cube_file_of_millions_of_particles_is_subsampled(tmp_path):
    cubes = tmp_path / "big.awn"
    cubes.write_text("20000000\n1\n20000000, 10, 10, 10, 0, 0, 0, 1\n")
    code = ("import resource; from fishgen.cli import main; "
            f"resource.setrlimit(resource.RLIMIT_AS, ({3 << 30}, {3 << 30})); "  # EGL reserves address space
            f"main(['preview', {str(cubes)!r}, '-o', {str(tmp_path / 'p.png')!r}, '--size', '160x120'])")
    result = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stderr == f"{cubes}: previewing 100,000 of its 20,000,000 particles\n"
    assert (tmp_path / "p.png").is_file()


def test_a_long_swim_loop_gif_keeps_frame_times_within_gif_limits(tmp_path):
    # a caudal swing of 23 degrees: a seamless loop of 18.4 s, sampled for 4 s or spread over 600 s
    species = species_file(tmp_path, "long.txt", BONY.replace("3.0 10.0 1.0\n", "3.0 23.0 1.0\n"))
    for extra in ([], ["--frames", "4"], ["--frames", "4", "--duration", "600"]):
        result = run_cli("preview", species, "-o", tmp_path / "l.gif", "--size", "64x48", *extra)
        assert result.returncode == 0, result.stderr
    # GIF frames last at most 655.35 s: a loop longer than 600 s is refused, not handed to Pillow
    long_frame = run_cli("preview", species, "-o", tmp_path / "l.gif", "--frames", "1", "--duration", "700")
    one_line_error(long_frame, "Invalid value for '--duration'")
