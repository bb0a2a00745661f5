"""`fishgen school` from the command line: the issue's exact form, outputs, determinism, errors."""
from __future__ import annotations

import json
import os
import platform
import subprocess
import sys

import numpy as np
import pygltflib
import pytest

from tests.conftest import PARAMS, ROOT, assert_valid_gltf, run_cli, run_cli_process


def test_the_exact_form_writes_a_valid_animated_school(tmp_path):
    out = tmp_path / "school.glb"
    # 28 fish: within what Godot 3 plays, so nothing is said on stderr
    result = run_cli("school", PARAMS / "bonybream.txt", "-o", out, "--count", "28", "--frames", "120",
                     "--seed", "5")
    assert result.returncode == 0, result.stderr
    assert result.stderr == "" and "28 bonybream; 120 frames" in result.stdout.splitlines()[0]
    table = result.stdout.splitlines()[1:]       # the one-screen summary: measure, mean, worst
    assert 6 <= len(table) <= 24 and table[0].split()[-2:] == ["mean", "worst"]
    overlaps = next(line for line in table if line.startswith("overlapping pairs"))
    assert overlaps.split()[-2:] == ["0", "0"]
    assert_valid_gltf(out)
    doc = pygltflib.GLTF2().load(str(out))
    assert len(doc.scenes[0].nodes) == 28 and [a.name for a in doc.animations] == ["school"]
    assert len(doc.meshes) == 9                                           # one mesh per part, shared
    again = tmp_path / "again.glb"
    run_cli("school", PARAMS / "bonybream.txt", "-o", again,
            "--count", "28", "--frames", "120", "--seed", "5")
    assert again.read_bytes() == out.read_bytes()


def test_scene_file_with_tracks_metrics_and_plot(tmp_path):
    out = tmp_path / "reef.glb"
    result = run_cli("school", PARAMS / "reef.toml", "-o", out, "--frames", "60", "--count", "8",
                     "--tracks", tmp_path / "t.npz", "--metrics", tmp_path / "m.json",
                     "--plot", tmp_path / "p.png", "--preroll", "0.5")
    assert result.returncode == 0, result.stderr
    assert_valid_gltf(out)
    tracks = np.load(tmp_path / "t.npz")
    assert (len(tracks["frame"]) == 60 * 16
            and list(tracks["species_names"]) == ["bonybream", "threadfingoldie"])
    assert np.isfinite(tracks["x"]).all() and set(np.unique(tracks["species"])) == {0, 1}
    metrics = json.loads((tmp_path / "m.json").read_text())
    assert len(metrics["per_frame"]["polarization"]) == 60 and "predator_distance" in metrics["per_frame"]
    assert (metrics["preroll_frames"], metrics["warmup_frames"]) == (15, 0)    # what came before frame 0
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_csv_tracks_have_the_documented_columns(tmp_path):
    result = run_cli("school", PARAMS / "pineapplefish.txt", "-o", tmp_path / "s.glb", "--count", "5",
                     "--frames", "10", "--tracks", tmp_path / "t.csv")
    assert result.returncode == 0, result.stderr
    lines = (tmp_path / "t.csv").read_text().splitlines()
    assert lines[0] == "frame,time,fish,species,x,y,z,qx,qy,qz,qw,vx,vy,vz" and len(lines) == 1 + 50


def test_formats_that_cannot_hold_a_school_say_what_to_use(tmp_path):
    result = run_cli("school", PARAMS / "bonybream.txt", "-o", tmp_path / "s.obj")
    assert result.returncode == 2 and result.stderr.count("\n") == 1
    assert "holds node animation, found .obj" in result.stderr
    assert "use .glb or .gltf or .usdc or .usda or .usdz instead" in result.stderr


def test_absurd_sizes_are_refused_before_anything_is_built(tmp_path):
    result = run_cli("school", PARAMS / "bonybream.txt", "-o", tmp_path / "s.glb", "--count", "100000",
                     "--frames", "100000")
    assert result.returncode == 2 and "at most 100,000 fish and 200,000,000 fish x frames" in result.stderr
    for option in (["--count", "1000000000"], ["--frames", "1000000000"]):
        result = run_cli("school", PARAMS / "bonybream.txt", "-o", tmp_path / "s.glb", *option)
        assert result.returncode == 2 and "Invalid value" in result.stderr and result.stderr.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_a_scene_file_given_to_build_names_the_school_command(tmp_path):
    result = run_cli("build", PARAMS / "reef.toml", "-o", tmp_path / "x.glb")
    assert result.returncode == 2 and "use `fishgen school` for it" in result.stderr


def test_metrics_are_strict_json_even_when_a_measure_has_no_value(tmp_path):
    """Issue 26, fault 2: a one-fish school has no nearest neighbour; the file held NaN."""
    import json

    out = tmp_path / "one.json"
    result = run_cli("school", PARAMS / "bonybream.txt", "--count", "1", "--frames", "20",
                     "-o", tmp_path / "one.glb", "--metrics", out)
    assert result.returncode == 0, result.stderr

    def refuse(constant):
        raise ValueError(f"not strict JSON: {constant}")

    doc = json.loads(out.read_text(), parse_constant=refuse)
    assert doc["summary"]["nearest_neighbour"] is None  # no neighbour: no distance, said as null


def summary_row(stdout: str, name: str) -> tuple[float, float]:
    """(mean, worst) of one row of the summary table."""
    line = next(line for line in stdout.splitlines() if line.startswith(name))
    mean, worst = line.split()[-2:]
    return float(mean), float(worst)


def test_the_shipped_bait_ball_mills_as_one_torus(tmp_path):
    out = tmp_path / "ball.glb"
    result = run_cli("school", PARAMS / "bait-ball.toml", "-o", out, "--frames", "180")
    assert result.returncode == 0, result.stderr
    assert "200 bonybream" in result.stdout and "couzin" in result.stdout
    assert summary_row(result.stdout, "rotation")[0] > 0.8
    assert summary_row(result.stdout, "polarization")[0] < 0.3
    assert summary_row(result.stdout, "separate groups")[1] <= 2
    assert_valid_gltf(out)
    extras = pygltflib.GLTF2().load(str(out)).scenes[0].extras
    # formed before the first frame: 20 of the paper's seconds at its speed, 3 body lengths/s
    assert extras["fishgen_school"] == {"model": "couzin", "warmup": 0.0, "preroll": 20.0, "fps": 30.0,
                                        "frames": 180}
    assert "after 20 s pre-roll" in result.stdout


def test_school_options_reach_the_run_as_the_scene_file_keys_do(tmp_path):
    """--speed, --length, --bounds, --warmup, --preset and the variety options, on the command line."""
    out = tmp_path / "s.glb"
    result = run_cli("school", PARAMS / "bonybream.txt", "-o", out, "--count", "12", "--frames", "60",
                     "--speed", "2", "--length", "0.5", "--bounds", "-3,-1,-3,3,1,3", "--warmup", "1",
                     "--preset", "highly parallel", "--tints", "3", "--size-variety", "0")
    assert result.returncode == 0, result.stderr
    # at 2 body lengths/s the paper's 20 s (at 3) are 30 s; a warm-up given still counts after them
    assert "couzin" in result.stdout.splitlines()[0]
    assert "after 30 s pre-roll and 1.0 s warm-up" in result.stdout
    assert_valid_gltf(out)
    doc = pygltflib.GLTF2().load(str(out))
    assert doc.scenes[0].extras["fishgen_school"]["warmup"] == 1.0
    # three tints, of which these 12 fish (seed 0) wear two: every part in each worn one
    assert len(doc.meshes) == 9 * 2 and sum("_tint2" in m.name for m in doc.meshes) == 9
    scales = {tuple(doc.nodes[n].scale or (1, 1, 1)) for n in doc.scenes[0].nodes}
    assert len(scales) == 1                                              # no size variety
    refused = run_cli("school", PARAMS / "bonybream.txt", "-o", out, "--model", "pso", "--preset", "torus")
    assert refused.returncode == 2 and "expected --preset with the couzin model" in refused.stderr
    bad = run_cli("school", PARAMS / "bonybream.txt", "-o", out, "--bounds", "0,0,0,0,1,1")
    assert bad.returncode == 2 and "X0,Y0,Z0,X1,Y1,Z1" in bad.stderr


def test_compact_stores_the_school_keys_as_16_bit_integers_and_the_file_shrinks(tmp_path):
    plain, compact = tmp_path / "plain.glb", tmp_path / "compact.glb"
    for out, flags in ((plain, ()), (compact, ("--compact",))):
        result = run_cli("school", PARAMS / "bonybream.txt", "--count", "20", "--frames", "60",
                         "-o", out, *flags)
        assert result.returncode == 0, result.stderr
    assert_valid_gltf(compact)
    doc = pygltflib.GLTF2().load(str(compact))
    outputs = {doc.accessors[doc.animations[0].samplers[c.sampler].output].componentType
               for c in doc.animations[0].channels if c.target.path in ("rotation", "weights")}
    assert outputs <= {pygltflib.SHORT, pygltflib.UNSIGNED_SHORT} and outputs
    # small here: the meshes weigh most (-35 % at 1,000 fish)
    assert compact.stat().st_size < plain.stat().st_size


@pytest.mark.parametrize("count,frames", [(100_000, 2), (3_000, 3_000)])
def test_a_school_too_big_for_the_memory_allowed_is_refused_before_it_starts(tmp_path, count, frames):
    """Under a 1.5 GiB address-space limit these ended in MemoryError tracebacks (issue 26, fault 1)."""
    import resource
    import subprocess
    import sys

    def cap() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (3 * 2**29, 3 * 2**29))

    run = subprocess.run([sys.executable, "-m", "fishgen", "school", str(PARAMS / "bonybream.txt"), "--count",
                          str(count), "--frames", str(frames), "-o", str(tmp_path / "big.glb")],
                         capture_output=True, text=True, preexec_fn=cap, timeout=120)
    assert run.returncode == 2 and "Traceback" not in run.stderr, run.stderr
    assert ("fits in 1.5 GiB (this process's address-space limit)" in run.stderr
            and "needs about" in run.stderr)
    assert not (tmp_path / "big.glb").exists()


def test_the_memory_estimate_is_above_what_a_run_peaks_at():
    """The estimate errs high: measured peaks (VmPeak, BonyBream with the body wave) stay below it."""
    from fishgen.school.memory import estimate

    measured = {(1_000, 1_000): 563, (3_000, 300): 589, (10_000, 100): 964, (20_000, 10): 1076,
                (2_000, 2_000): 1134, (5_000, 300): 910}
    for (fish, frames), mib in measured.items():
        assert mib * 2**20 < estimate(fish, frames) < 1.4 * mib * 2**20


def test_the_memory_estimate_with_tracks_is_above_what_a_run_peaks_at():
    """--tracks adds 150-200 bytes a fish-frame (VmPeak, BonyBream, .npz)."""
    from fishgen.school.memory import estimate

    measured = {(1_000, 1_000): 716, (2_000, 1_000): 1139, (2_000, 2_000): 1718, (5_000, 300): 1150}
    for (fish, frames), mib in measured.items():
        assert mib * 2**20 < estimate(fish, frames, tracks=True) < 1.4 * mib * 2**20


def test_tracks_count_in_the_memory_a_school_is_refused_for(tmp_path, monkeypatch):
    """Under a limit the run fits without --tracks, writing the tracks ended in a MemoryError."""
    from fishgen.school import memory

    fish, frames = 200, 300
    between = (memory.estimate(fish, frames) + memory.BASE + memory.PER_FISH * fish
               + (memory.PER_FISH_FRAME + 150) * fish * frames) // 2
    monkeypatch.setattr(memory, "allowed", lambda: (between, "this process's address-space limit"))
    args = ("school", PARAMS / "bonybream.txt", "--count", str(fish), "--frames", str(frames))
    result = run_cli(*args, "-o", tmp_path / "s.glb", "--tracks", tmp_path / "t.npz")
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert "which needs about" in result.stderr and "with --tracks: use fewer fish or frames" in result.stderr
    assert not (tmp_path / "s.glb").exists() and not (tmp_path / "t.npz").exists()


def test_lods_and_merge_give_every_fish_the_engine_layout_over_shared_meshes(tmp_path):
    """`fishgen school --lods ... --merge` (issue 24): each fish is its species' node tree, its
    levels tied by MSFT_lod, two draw calls a fish, the meshes shared by every fish."""
    out = tmp_path / "school.glb"
    result = run_cli("school", PARAMS / "bonybream.txt", "--count", "6", "--frames", "30",
                     "--lods", "16x12,8x6", "--merge", "-o", out)
    assert result.returncode == 0, result.stderr
    assert_valid_gltf(out)
    doc = pygltflib.GLTF2().load(str(out))
    assert len(doc.meshes) == 2 and len(doc.scenes) == 2                  # one mesh a level, levels apart
    drawn = [n for n in doc.nodes if n.mesh is not None]
    lod0 = [n for n in drawn if (n.extensions or {}).get("MSFT_lod")]
    assert len(lod0) == 6 and all(len(n.extensions["MSFT_lod"]["ids"]) == 1 for n in lod0)
    assert sum(len(doc.meshes[n.mesh].primitives) for n in lod0) == 6 * 2  # two draw calls a fish
    assert len(doc.skins) == 6 * 2                                      # each fish its own joints per level
    refused = run_cli("school", PARAMS / "bonybream.txt", "--merge", "--tints", "3", "-o", out)
    assert refused.returncode == 2 and "expected --tints 1 with --lods or --merge" in refused.stderr


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full, a device that is always full")
def test_a_summary_that_cannot_be_printed_fails_the_run_and_leaves_no_file(tmp_path):
    with open("/dev/full", "w") as full:
        result = subprocess.run([sys.executable, "-m", "fishgen", "school", str(PARAMS / "bonybream.txt"),
                                 "-o", str(tmp_path / "new" / "s.glb"), "--count", "3", "--frames", "10",
                                 "--metrics", str(tmp_path / "m.json")],
                                cwd=ROOT, stdout=full, stderr=subprocess.PIPE, text=True)
    assert result.returncode == 1
    assert result.stderr == "fishgen: cannot write to stdout: No space left on device\n"
    assert list(tmp_path.iterdir()) == []  # nor the folder made for the glb


def closed_stdout(*args, cwd=ROOT) -> subprocess.CompletedProcess:
    """The command with its stdout a pipe whose reader has gone before it prints (`| true`)."""
    read, write = os.pipe()
    os.close(read)
    try:
        return subprocess.run([sys.executable, "-m", "fishgen", *map(str, args)], cwd=cwd, stdout=write,
                              stderr=subprocess.PIPE, text=True)
    finally:
        os.close(write)


def test_a_reader_that_has_gone_stops_the_printing_not_the_run(tmp_path):
    """`fishgen school … | true` exited 1 in silence and its glb never landed (QA pass 14): click
    exits 1 on a broken pipe, and a school lands its files only once its summary is out."""
    result = closed_stdout("school", PARAMS / "bonybream.txt", "-o", tmp_path / "s.glb", "--count", "3",
                           "--frames", "10")
    assert result.returncode == 0 and result.stderr == "", result.stderr
    assert (tmp_path / "s.glb").stat().st_size > 0


def test_two_outputs_naming_one_file_are_refused_and_nothing_is_written(tmp_path):
    # A .gltf writes its texture beside it; a plot of the same name would silently replace it.
    result = run_cli("school", PARAMS / "bonybream.txt", "-o", tmp_path / "s.gltf", "--count", "3",
                     "--frames", "10", "--plot", tmp_path / "s_skin.png")
    assert result.returncode == 2, result.stderr
    assert result.stderr == ("fishgen school: expected every output of one run to be a different file, "
                             f"found {tmp_path / 's_skin.png'} twice\n")
    assert list(tmp_path.iterdir()) == []


def test_an_output_whose_side_files_are_a_species_textures_is_refused(tmp_path):
    """The textures of a school's species are its inputs too: `-o o.gltf` writes o_*.png beside it."""
    from tests.conftest import species_textured_as

    inputs = species_textured_as(tmp_path, "o_skin.png", "o_skin_mask.png")
    result = run_cli("school", "bonybream.txt", "--count", "2", "--frames", "2", "-o", "o.gltf", cwd=tmp_path)
    assert result.returncode == 2 and "not one of the command's inputs" in result.stderr, result.stderr
    assert {p: p.read_bytes() for p in inputs} == inputs and not (tmp_path / "o.gltf").exists()


@pytest.mark.parametrize("folder,found", [(False, "'nothere.txt' missing beside the scene file"),
                                          (True, "'nothere.txt', a folder")])
def test_a_scene_naming_a_missing_species_says_so_at_its_line(tmp_path, folder, found):
    """It was reported as /abs/nothere.txt: ..., without the scene file's line."""
    if folder:
        (tmp_path / "nothere.txt").mkdir()
    (tmp_path / "scene.toml").write_text('frames = 10\n\n[[species]]\nfile = "nothere.txt"\ncount = 3\n')
    result = run_cli("school", "scene.toml", "-o", "s.glb", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr == f"scene.toml:4: expected an existing species file, found {found}\n"


@pytest.mark.parametrize("preset, low, high", [("highly parallel", 0.97, 1.0),
                                               ("dynamic parallel", 0.8, 0.97)])
def test_the_readmes_preset_school_is_in_its_state_from_the_first_frame(tmp_path, preset, low, high):
    """`fishgen school params/bonybream.txt --preset "highly parallel"` as the README runs it. At 1
    body length/s the paper's clock runs 3x slower than ours, and 10 s from a random start read
    polarization 0.78 (worst 0.49, 5 groups): the default pre-roll (60 s) forms the school first,
    and the summary covers the whole clip."""
    out = tmp_path / "parallel.glb"
    result = run_cli("school", PARAMS / "bonybream.txt", "--preset", preset, "-o", out)
    assert result.returncode == 0, result.stderr
    assert "after 60 s pre-roll" in result.stdout
    assert low < summary_row(result.stdout, "polarization")[0] < high
    assert summary_row(result.stdout, "rotation")[0] < 0.2
    assert summary_row(result.stdout, "separate groups") == (1, 1)
    assert_valid_gltf(out)


def test_the_torus_preset_mills_at_the_commands_defaults(tmp_path):
    """`fishgen school params/bonybream.txt --preset torus`: from a random ball in the default region
    it milled for 1 seed of 8 (seed 3: rotation 0.33, 6 groups); it starts as a ring now, and the
    torus rules keep the mill through the pre-roll."""
    result = run_cli("school", PARAMS / "bonybream.txt", "--preset", "torus", "--seed", "3", "--frames", "60",
                     "-o", tmp_path / "torus.glb")
    assert result.returncode == 0, result.stderr
    assert summary_row(result.stdout, "rotation")[0] > 0.8
    assert summary_row(result.stdout, "polarization")[0] < 0.35


@pytest.mark.parametrize("args, milling", [
    (("--preset", "torus"), True),                         # the torus's default: a ring
    (("--preset", "torus", "--layout", "sphere"), False),  # a layout given wins
    (("--preset", "swarm"), False),
    (("--preset", "swarm", "--layout", "ring"), True),
    (("--model", "boids", "--layout", "ring"), True),
])
def test_layout_sets_how_the_fish_start(tmp_path, args, milling):
    """The first frame without a pre-roll is the start layout: a ring heads round itself (rotation
    near 1), a random ball every way (rotation near 0)."""
    metrics = tmp_path / "m.json"
    result = run_cli("school", PARAMS / "bonybream.txt", *args, "--preroll", "0", "--frames", "2",
                     "-o", tmp_path / "s.glb", "--metrics", metrics)
    assert result.returncode == 0, result.stderr
    rotation = json.loads(metrics.read_text())["per_frame"]["rotation"][0][0]
    assert (rotation > 0.9) if milling else (rotation < 0.5), rotation


def test_a_species_listed_twice_is_two_schools_told_apart(tmp_path):
    """Two [[species]] of one file: the summary's rows and the tracks' names read bonybream and
    bonybream (2); before, both rows read bonybream."""
    from tests.conftest import species_textured_as

    species_textured_as(tmp_path, "bonybream.png", "bonybream_mask.png")
    scene = tmp_path / "d.toml"
    scene.write_text('[[species]]\nfile = "bonybream.txt"\ncount = 4\n'
                     '[[species]]\nfile = "bonybream.txt"\ncount = 3\n')
    result = run_cli("school", scene, "--frames", "12", "-o", tmp_path / "o.glb",
                     "--tracks", tmp_path / "t.npz")
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(f"{tmp_path / 'o.glb'}: 4 bonybream, 3 bonybream (2);")
    assert summary_row(result.stdout, "polarization (1 = parallel), bonybream (2)")
    assert list(np.load(tmp_path / "t.npz")["species_names"]) == ["bonybream", "bonybream (2)"]


def test_a_warm_up_as_long_as_the_run_is_said_in_a_note(tmp_path):
    out = tmp_path / "e.glb"
    long = run_cli("school", PARAMS / "bonybream.txt", "--count", "3", "--frames", "10", "--warmup", "5",
                   "-o", out)
    assert long.returncode == 0 and "after 0.3 s warm-up" in long.stdout
    assert long.stderr == (f"{out}: a warm-up of 5 s is as long as the run or longer (0.3 s): the summary "
                           "measures its last frame only\n")
    short = run_cli("school", PARAMS / "bonybream.txt", "--count", "3", "--frames", "10", "--warmup", "0.2",
                    "-o", out)
    assert short.returncode == 0 and short.stderr == ""


def test_bounds_too_small_for_the_fish_are_said_in_a_note(tmp_path):
    """Less than a body length cubed for each fish: the school runs, and a note says it crowds."""
    out = tmp_path / "c.glb"
    tight = run_cli("school", PARAMS / "bonybream.txt", "--count", "28", "--frames", "10",
                    "--bounds", "0,0,0,0.2,0.2,0.2", "-o", out)
    assert tight.returncode == 0, tight.stderr
    assert tight.stderr.startswith(f"{out}: the bounds hold 0.008 m³, less than a body length cubed for each "
                                   "fish (") and tight.stderr.endswith("give wider --bounds\n")
    assert tight.stderr.count("\n") == 1
    roomy = run_cli("school", PARAMS / "bonybream.txt", "--count", "28", "--frames", "10", "-o", out)
    assert roomy.returncode == 0 and roomy.stderr == ""


@pytest.mark.parametrize("name, beside", [("s.glb", ""), ("s.gltf", " (+2 files)"), ("s.usda", " (+1 file)")])
def test_the_summary_counts_the_files_written_beside_the_school(tmp_path, name, beside):
    """A USD school wrote its fish's texture beside it and did not say so, as `build` does."""
    result = run_cli("school", PARAMS / "bonybream.txt", "--count", "3", "--frames", "5",
                     "-o", tmp_path / name, "--metrics", tmp_path / "m.json")
    assert result.returncode == 0, result.stderr
    first = result.stdout.splitlines()[0]
    assert first.endswith(" MB" + beside), first


def test_prototypes_are_refused_for_an_output_without_them(tmp_path):
    """`--prototypes` was taken and ignored for a .glb, whose fish share meshes, not prototypes."""
    result = run_cli("school", PARAMS / "bonybream.txt", "--count", "3", "--frames", "5", "--prototypes", "2",
                     "-o", tmp_path / "s.glb")
    assert result.returncode == 2 and result.stderr == (
        f"fishgen school: expected --prototypes with a USD output (.usdc, .usda, .usdz), found -o "
        f"'{tmp_path / 's.glb'}'\n")
    assert not (tmp_path / "s.glb").exists()


@pytest.mark.skipif(platform.machine() not in ("x86_64", "AMD64"), reason="OpenBLAS's x86-64 kernels")
def test_metrics_are_the_same_whichever_blas_kernel_sums_them(tmp_path):
    """The measures' sums go through BLAS, whose kernel follows the CPU: OpenBLAS's for SSE3
    (Prescott, which any x86-64 runs) changed the summary's last digits."""
    def metrics(name: str, kernel: str | None) -> bytes:
        out = tmp_path / f"{name}.json"
        done = run_cli_process("-q", "school", PARAMS / "bonybream.txt", PARAMS / "threadfingoldie.txt",
                               "--count", "15", "--frames", "60", "-o", tmp_path / f"{name}.glb",
                               "--metrics", out, env={"OPENBLAS_CORETYPE": kernel})
        assert done.returncode == 0, done.stderr
        return out.read_bytes()

    assert metrics("default", None) == metrics("sse3", "Prescott")
