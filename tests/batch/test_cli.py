"""`fishgen batch` as a pipeline sees it: one line per job, --quiet/--verbose, --json errors, the report."""
from __future__ import annotations

import json
import shutil

import pytest

from fishgen.batch.manifest import derived_seed
from tests.batch.conftest import batch, hashes, statuses
from tests.conftest import PARAMS, ROOT, run_cli


def test_one_plain_line_per_job_and_a_summary_when_not_on_a_terminal(shipped):
    run = batch(shipped / "params" / "assets.toml", "-j", "2")
    lines = run.stdout.splitlines()
    assert run.returncode == 0 and len(lines) == 10 and run.stderr == ""
    assert all(line.startswith("built    ") and line.endswith(" s)") for line in lines[:9])
    assert lines[9].endswith("9 jobs, 9 built, 0 skipped, 0 failed in " + lines[9].split(" in ")[1])


def test_quiet_prints_nothing_and_verbose_says_why_each_job_ran(shipped):
    manifest = shipped / "params" / "assets.toml"
    quiet = batch(manifest, "-j", "2", "--quiet")
    assert quiet.returncode == 0 and quiet.stdout == "" and quiet.stderr == ""
    species = shipped / "params" / "pineapplefish.txt"
    species.write_text(species.read_text() + "// edited\n")
    verbose = batch(manifest, "--verbose")
    assert "built    fish/pineapplefish.glb" in verbose.stdout
    assert "../../params/pineapplefish.txt changed" in verbose.stdout
    assert "skipped  fish/bonybream.glb" in verbose.stdout and "fishgen batch: done in" in verbose.stderr


def test_the_report_has_each_jobs_inputs_options_output_hashes_time_status_and_error(shipped):
    shutil.copy(ROOT / "tests" / "fixtures" / "appendix_a_as_printed.txt", shipped / "params" / "bad.txt")
    manifest = shipped / "params" / "assets.toml"
    manifest.write_text(manifest.read_text() + '\n[[build]]\ninput = "bad.txt"\noutput = "fish/bad.glb"\n')
    run = batch(manifest, "-j", "2", "--report", shipped / "report.json")
    assert run.returncode == 2
    report = json.loads((shipped / "report.json").read_text())
    assert report["counts"] == {"built": 9, "skipped": 0, "failed": 1, "not run": 0}
    jobs = {job["name"]: job for job in report["jobs"]}
    out = shipped / "out" / "assets"
    fish = jobs["fish/bonybream.glb"]
    assert fish["status"] == "built" and fish["kind"] == "build" and fish["seconds"] > 0
    assert fish["output_sha256"] == hashes(out)["fish/bonybream.glb"]
    assert fish["options"] == {"fins": None, "fps": 30.0, "length": None, "speed": None, "swim": "body",
                               "textures": None, "lods": None, "merge": False, "clips": ["swim"],
                               "compact": False}
    assert set(fish["inputs"]) == {"../../params/bonybream.txt", "../../textures/bonybream.png",
                                   "../../textures/bonybream_mask.png"}
    assert all(len(digest) == 64 for digest in fish["inputs"].values())
    assert jobs["clouds/table_4_3.glb"]["options"]["seed"] == derived_seed("clouds/table_4_3.glb")
    bad = jobs["fish/bad.glb"]
    assert bad["status"] == "failed" and bad["output_sha256"] is None
    assert bad["error"] == {"message": bad["error"]["message"], "file": str(shipped / "params" / "bad.txt"),
                            "line": 2, "kind": "input"}
    batch(manifest, "--report", shipped / "report.json")
    assert json.loads((shipped / "report.json").read_text())["counts"]["skipped"] == 9


def test_json_errors_one_object_per_failed_job_and_one_for_the_batch(shipped):
    shutil.copy(ROOT / "tests" / "fixtures" / "appendix_a_as_printed.txt", shipped / "params" / "bad.txt")
    manifest = shipped / "params" / "m.toml"
    manifest.write_text('[[build]]\ninput = "bad.txt"\noutput = "bad.glb"\n')
    run = batch(manifest, "--out", shipped / "o", "--json")
    errors = [json.loads(line) for line in run.stderr.splitlines()]
    assert run.returncode == 2 and len(errors) == 2
    assert errors[0]["job"] == "bad.glb" and errors[0]["line"] == 2 and errors[0]["exit"] == 2
    assert errors[0]["file"] == str(shipped / "params" / "bad.txt") and errors[0]["kind"] == "input"
    assert errors[1]["error"] == "fishgen: 1 of 1 jobs failed (each said why above)"
    assert errors[1]["exit"] == 2
    manifest.write_text('[[build]]\ninput = "bad.txt"\noutput = "bad.glb"\nfins = 3\n')
    wrong = batch(manifest, "--json")
    error = json.loads(wrong.stderr)
    assert wrong.returncode == 2 and error["file"] == str(manifest) and error["line"] == 4


def test_a_folder_builds_every_species_and_cube_file_with_default_options(shipped, gltf_validator):
    run = batch(shipped / "params", "--out", shipped / "all", "-j", "2")
    assert run.returncode == 0, run.stderr
    names = set(statuses(run.stdout))
    assert names == {"bonybream.glb", "centroberyx.glb", "pineapplefish.glb", "threadfingoldie.glb",
                     "clouds/table_4_2.glb", "clouds/table_4_3.glb", "clouds/table_4_4.glb",
                     "clouds/sky.glb"}
    gltf_validator(*(shipped / "all" / name for name in sorted(names)))
    no_out = batch(shipped / "params")
    assert no_out.returncode == 2 and "expected --out FOLDER" in no_out.stderr


def test_two_batches_may_not_write_one_out_folder_at_once(shipped):
    import fcntl

    out = shipped / "o"
    out.mkdir()
    with open(out / ".fishgen-batch.lock", "a+b") as lock:
        fcntl.flock(lock.fileno(), fcntl.LOCK_EX)
        run = batch(shipped / "params" / "assets.toml", "--out", out)
    # the system's refusal (exit 1, as a port in use): nothing wrong with the input, run it again later
    assert run.returncode == 1 and "found one running" in run.stderr and not (out / "fish").exists()


def test_a_full_disk_says_one_line_per_failed_job_and_one_summary(shipped, monkeypatch):
    """Issue 32: the record and the report that a full disk refused were lines of their own, and the
    report's failure hid the summary; now they end the batch's one summary error."""
    import errno
    import os

    manifest = shipped / "params" / "two.toml"
    manifest.write_text('out = "../out"\n[[clouds]]\ninput = "clouds/table_4_3.awn"\noutput = "a.ply"\n'
                        '[[clouds]]\ninput = "clouds/table_4_4.awn"\noutput = "b.ply"\n')

    def full(fd: int) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", full)  # every durable write (-j 1: this process's) meets a full disk
    run = batch(manifest, "-j", "1", "--report", shipped / "report.json")
    out = shipped / "out"
    assert run.returncode == 1, run.stderr
    assert run.stderr.splitlines() == [
        f"fishgen: cannot write {out / 'a.ply'}: No space left on device",
        f"fishgen: cannot write {out / 'b.ply'}: No space left on device",
        f"fishgen: 2 of 2 jobs failed (each said why above); cannot write {shipped / 'report.json'}: "
        f"No space left on device"]   # no job built: no record to write, where there was none
    assert run.stdout.startswith(f"{out}: 2 jobs, 0 built, 0 skipped, 2 failed in ")
    assert [p.name for p in out.rglob("*") if p.is_file()] == [".fishgen-batch.lock"]


@pytest.mark.parametrize("report", ["params/bonybream.txt", "textures/bonybream.png", "params/assets.toml",
                                    "out/assets/fish/bonybream.glb", "out/assets/clouds/sky.bin"])
def test_a_report_that_is_a_jobs_input_or_output_is_refused_before_any_job_runs(shipped, report):
    """--report over a job's species file, its texture, the manifest itself or a job's output (its
    side files too) replaced that file with JSON; the manifest was refused only once the jobs ran."""
    manifest = shipped / "params" / "assets.toml"
    manifest.write_text(manifest.read_text() + '\n[[clouds]]\ninput = "clouds/table_4_2.awn"\n'
                        'output = "clouds/sky.gltf"\n')
    target = shipped / report
    before = target.read_bytes() if target.exists() else None
    run = batch(manifest, "--report", target)
    assert run.returncode == 2 and run.stdout == "" and run.stderr.count("\n") == 1, run.stderr
    assert "Traceback" not in run.stderr and str(target) in run.stderr
    assert (target.read_bytes() if target.exists() else None) == before
    assert not (shipped / "out").exists()


def _two_pictures(folder):
    for name, picture in (("b.png", "billow.png"), ("a_b.png", "cumulus.png")):
        shutil.copy(ROOT / "textures" / "clouds" / picture, folder / name)
    (folder / "y.awa").write_text("1\n1\n1, 1,1,1, 0,0,0, 1, b.png\n")   # a.gltf of it writes a_b.png


def test_a_job_whose_side_file_would_replace_another_jobs_input_fails_and_the_input_is_kept(tmp_path):
    """a.gltf wrote its texture cloud's picture as a_b.png over the cumulus picture another job's
    texture cloud reads (exit 0, 2 built). Its writers now refuse it as they refuse its own inputs:
    that job fails in one line, leaving nothing, and the other builds."""
    _two_pictures(tmp_path)
    (tmp_path / "x.awa").write_text("1\n1\n1, 1,1,1, 0,0,0, 1, a_b.png\n")
    manifest = tmp_path / "m.toml"
    manifest.write_text('out = "."\n[[clouds]]\ninput = "x.awa"\noutput = "x.glb"\n'
                        '[[clouds]]\ninput = "y.awa"\noutput = "a.gltf"\n')
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    for workers in ("1", "2"):
        run = batch(manifest, "-j", workers)
        assert run.returncode == 2, run.stderr
        assert run.stderr.splitlines() == [
            f"fishgen batch: a.gltf: expected an output that is not one of the command's inputs, found "
            f"'{tmp_path / 'a_b.png'}', which is the input '{tmp_path / 'a_b.png'}'",
            "fishgen: 1 of 2 jobs failed (each said why above)"]
        assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.name in before} == before
        assert not (tmp_path / "a.gltf").exists() and not (tmp_path / "a.bin").exists()
        assert (tmp_path / "x.glb").is_file()


def test_a_school_scenes_textures_are_guarded_too(tmp_path):
    """A scene file's species' texture was not among the files a batch knew its jobs read."""
    _two_pictures(tmp_path)
    text = (PARAMS / "bonybream.txt").read_text()
    (tmp_path / "bony.txt").write_text(text.replace("bonybream.png bonybream_mask.png", "a_b.png a_m.png"))
    shutil.copy(ROOT / "textures" / "bonybream_mask.png", tmp_path / "a_m.png")
    (tmp_path / "sch.toml").write_text('[[species]]\nfile = "bony.txt"\ncount = 3\n')
    manifest = tmp_path / "m.toml"
    manifest.write_text('out = "."\n[[school]]\ninput = "sch.toml"\noutput = "s.glb"\nframes = 10\n'
                        '[[clouds]]\ninput = "y.awa"\noutput = "a.gltf"\n')
    skin = (tmp_path / "a_b.png").read_bytes()
    run = batch(manifest, "-j", "1")
    assert run.returncode == 2 and "a.gltf: expected an output that is not one of" in run.stderr
    assert (tmp_path / "a_b.png").read_bytes() == skin and (tmp_path / "s.glb").is_file()


def test_a_side_file_pattern_alone_refuses_nothing(shipped):
    """bonybream.gltf writes bonybream_skin.png: the species' own bonybream_mask.png, which the
    pattern bonybream_*.png would match, is no reason to refuse a batch that reads it."""
    folder = shipped / "params"
    for name in ("bonybream.png", "bonybream_mask.png"):
        shutil.copy(shipped / "textures" / name, folder / name)
    manifest = folder / "m.toml"
    manifest.write_text('out = "."\n[[build]]\ninput = "bonybream.txt"\noutput = "bonybream.gltf"\n'
                        '[[school]]\ninput = "bonybream.txt"\noutput = "school.glb"\n'
                        'count = 3\nframes = 10\n')
    pictures = {name: (folder / name).read_bytes() for name in ("bonybream.png", "bonybream_mask.png")}
    run = batch(manifest, "-j", "1")
    assert run.returncode == 0, run.stderr
    assert {name: (folder / name).read_bytes() for name in pictures} == pictures
    assert (folder / "bonybream_skin.png").is_file()


@pytest.mark.parametrize("given, command", [("reef.toml", "school"), ("bonybream.txt", "build"),
                                            ("clouds/table_4_3.awn", "clouds")])
def test_another_commands_input_given_to_batch_names_that_command(tmp_path, given, command):
    """A school scene given to batch read `expected one of out, [[build]], ..., found 'model'`, a
    species file `expected TOML`; as `build` does for a manifest, they now name their command."""
    result = run_cli("batch", PARAMS / given, "--out", tmp_path / "out")
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert result.stderr.endswith(f"; use `fishgen {command}` for it\n")
    assert not (tmp_path / "out").exists()


def test_a_manifest_named_as_another_format_still_runs(tmp_path):
    """The hint comes only for a file that is not a manifest: `jobs.txt` holding jobs is one."""
    (tmp_path / "jobs.txt").write_text(f'[[build]]\ninput = "{PARAMS / "bonybream.txt"}"\noutput = "b.glb"\n')
    result = run_cli("batch", tmp_path / "jobs.txt", "--out", tmp_path / "out")
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "out" / "b.glb").is_file()


def test_a_jobs_error_names_its_file_from_where_the_batch_was_run(tmp_path):
    """A missing input read '/tmp/.../params/nope.txt: ...': the job's inputs are resolved, and their
    errors showed the resolved path where every other message shows the path as a user names it."""
    (tmp_path / "params").mkdir()
    (tmp_path / "params" / "t.toml").write_text('[[school]]\ninput = "nope.txt"\noutput = "a.glb"\n')
    result = run_cli("batch", "params/t.toml", "--out", "out", cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert result.stderr.splitlines()[0] == "params/nope.txt: expected a species file, found no such file"


@pytest.mark.parametrize("name", [".fishgen-batch.json", ".fishgen-batch.lock"])
def test_the_report_may_not_be_the_batch_s_own_record_or_lock(shipped, name):
    """The record was replaced by the report (every job rebuilt on the next run), or the lock by a
    new file while the batch held the old one."""
    out = shipped / "o"
    run = batch(shipped / "params" / "assets.toml", "--out", out, "--report", out / name)
    assert run.returncode == 2 and f"expected a report that is not the batch's own {name}" in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and not (out / "fish").exists()


def test_a_report_through_a_symlink_loop_is_a_line_not_a_traceback(shipped):
    """Path.resolve() raises RuntimeError on a loop (Python 3.11): the record-or-lock check used it.
    Said before any job runs, as a fly's report is before the flight."""
    loop = shipped / "self"
    loop.symlink_to(loop)
    run = batch(shipped / "params" / "clouds", "--out", shipped / "o", "--report", loop / "r.json")
    assert "Traceback" not in run.stderr and run.returncode == 1
    said = f"fishgen: cannot write {loop / 'r.json'}: expected a folder at {loop}, found a broken symbolic " \
           "link"
    assert run.stderr.strip().splitlines() == [said] and not (shipped / "o").exists()


def test_out_naming_a_file_is_the_systems_refusal_as_for_any_outputs_folder(shipped, tmp_path):
    """--out FILE was click's usage error (2); a file where an output's folder should be is status 1
    everywhere else (the README's table), as it is here now, and nothing is written."""
    taken = tmp_path / "afile"
    taken.write_bytes(b"mine")
    run = batch(shipped / "params" / "assets.toml", "--out", taken)
    assert run.returncode == 1
    assert run.stderr == f"fishgen: cannot write {taken}: expected a folder at {taken}, found a file\n"
    assert taken.read_bytes() == b"mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "params", "textures"]


def test_a_batch_whose_every_job_fails_writes_no_record(shipped):
    """It wrote an empty record where there was none (the eleventh QA pass); the lock, which
    keeps two batches out of one folder, stays, as after every batch."""
    manifest = shipped / "params" / "m.toml"
    manifest.write_text('[[clouds]]\ninput = "clouds/table_4_3.awn"\noutput = "x.glb"\nmax-particles = 10\n')
    out = shipped / "o"
    run = batch(manifest, "--out", out)
    assert run.returncode == 2, run.stderr
    assert [p.name for p in out.iterdir()] == [".fishgen-batch.lock"]


def test_a_batch_whose_reader_has_gone_runs_every_job(tmp_path, shipped):
    """`fishgen batch … -j 1 | true` stopped after its first job (QA pass 14)."""
    from tests.cli.test_school import closed_stdout

    result = closed_stdout("batch", shipped / "params" / "assets.toml", "--out", tmp_path / "out", "-j", "1")
    assert result.returncode == 0 and result.stderr == "", result.stderr
    assert len([p for p in (tmp_path / "out").rglob("*.glb")]) >= 9


def test_a_jobs_warning_is_said_once(shipped):
    """A school over Godot 3's 1,024 animated weights is said once: by its job as it ran, and not
    again after the batch, from the batch's own list of what it wrote (it was, twice a job)."""
    manifest = shipped / "params" / "m.toml"
    manifest.write_text('out = "../out"\n[[school]]\ninput = "bonybream.txt"\noutput = "s.glb"\n'
                        'count = 150\nframes = 10\n')
    run = batch(manifest, "-j", "1", "--quiet")
    assert run.returncode == 0, run.stderr
    lines = run.stderr.splitlines()
    assert len(lines) == 1 and "s.glb: animates 5,400 blend-shape weights; Godot 3 plays at most" in lines[0]


def test_o_names_the_out_folder_as_every_other_command_s_output_does(tmp_path):
    """`fishgen batch m.toml -o DIR` was "No such option '-o'" with no hint (QA pass 21)."""
    (tmp_path / "c.awn").write_text("20\n1\n20, 2,2,2, 0,0,0, 0.5\n")
    manifest = tmp_path / "m.toml"
    manifest.write_text('[[clouds]]\ninput = "c.awn"\noutput = "c.ply"\n')
    run = batch(manifest, "-o", tmp_path / "there", "-j", "1")
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "there" / "c.ply").is_file() and not (tmp_path / "out").exists()


def test_a_missing_manifest_is_a_bad_input_as_every_command_s_missing_input_is(tmp_path):
    """It was click's own `Invalid value for 'MANIFEST.toml|DIR': Path … does not exist.`, a usage
    error with no file under --json, where every other command says FILE: … no such file (QA pass 21)."""
    missing = tmp_path / "nope.toml"
    run = batch(missing)
    assert (run.returncode, run.stderr) == (2, f"{missing}: expected a batch manifest or a folder, found no "
                                               "such file\n")
    as_json = json.loads(batch(missing, "--json").stderr)
    assert (as_json["kind"], as_json["file"]) == ("input", str(missing))


def test_an_empty_manifest_name_is_a_usage_error_not_the_working_folder(tmp_path):
    """`Path("")` is the working folder: `batch ""` (a script's unset variable) batched everything
    under it once click's own check that the manifest exists had gone (a review)."""
    (tmp_path / "a.txt").write_text("not a species\n")
    run = batch("", "-o", tmp_path / "out", cwd=tmp_path)
    assert run.returncode == 2 and run.stderr.startswith("fishgen batch: ") and "empty" in run.stderr
    assert not (tmp_path / "out").exists()


def test_a_manifest_that_is_no_regular_file_is_not_said_to_be_missing():
    run = batch("/dev/null")
    assert (run.returncode, run.stderr) == (2, "/dev/null: expected a batch manifest or a folder, found a "
                                               "special file\n")
