"""Where jobs run: the same bytes from -j 1, -j 2 and Dask; a bad job fails alone; a killed batch
leaves whole files and a consistent record, and the next run finishes only what is missing."""
from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from fishgen.batch.jobs import Result
from fishgen.batch.manifest import Job
from fishgen.batch.runner import MAX_CHUNK, chunk_size
from fishgen.errors import FishgenError
from tests.batch.conftest import batch, hashes, record, statuses
from tests.conftest import ROOT, run_cli

BAD = ROOT / "tests" / "fixtures" / "appendix_a_as_printed.txt"  # fails at its line 2


def test_the_example_gives_identical_bytes_with_one_or_two_processes(shipped):
    manifest = shipped / "params" / "assets.toml"
    one, two = shipped / "j1", shipped / "j2"
    assert batch(manifest, "--out", one, "-j", "1").returncode == 0
    assert batch(manifest, "--out", two, "-j", "2").returncode == 0
    assert hashes(one) == hashes(two) and len(hashes(one)) == 9


def bad_and_good(shipped, fail_fast: bool = False):
    shutil.copy(BAD, shipped / "params" / "bad.txt")
    manifest = shipped / "params" / "mixed.toml"
    manifest.write_text('out = "../out/mixed"\n'
                        '[[build]]\ninput = "bad.txt"\noutput = "bad.glb"\n'
                        '[[build]]\ninput = "bonybream.txt"\noutput = "good.glb"\n'
                        '[[clouds]]\ninput = "clouds/table_4_2.awn"\noutput = "cloud.ply"\n')
    return manifest, shipped / "out" / "mixed"


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_a_bad_input_fails_only_its_own_job_with_its_line(shipped, jobs):
    manifest, out = bad_and_good(shipped)
    run = batch(manifest, "-j", jobs, "--report", shipped / "report.json")
    assert run.returncode == 2
    assert f"{shipped / 'params' / 'bad.txt'}:2: expected the header record" in run.stderr
    assert "Traceback" not in run.stderr
    assert statuses(run.stdout) == {"good.glb": "built", "cloud.ply": "built"}
    assert set(hashes(out)) == {"good.glb", "cloud.ply"} and set(record(out)) == {"good.glb", "cloud.ply"}
    jobs_report = {j["name"]: j for j in json.loads((shipped / "report.json").read_text())["jobs"]}
    assert jobs_report["bad.glb"]["status"] == "failed"
    assert jobs_report["bad.glb"]["error"]["line"] == 2 and jobs_report["bad.glb"]["error"]["kind"] == "input"
    # Only the failed job runs again.
    again = batch(manifest)
    assert again.returncode == 2 and statuses(again.stdout) == {"good.glb": "skipped", "cloud.ply": "skipped"}


def test_fail_fast_starts_nothing_after_the_first_failure(shipped):
    manifest, out = bad_and_good(shipped)
    run = batch(manifest, "-j", "1", "--fail-fast")
    assert run.returncode == 2 and "2 not run" in run.stdout
    assert not out.joinpath("good.glb").exists()


def test_fail_fast_with_a_pool_stops_every_worker_at_its_next_job(shipped):
    manifest, out = bad_and_good(shipped)
    manifest.write_text(manifest.read_text() + "".join(
        f'[[build]]\ninput = "bonybream.txt"\noutput = "more{i:02d}.glb"\n' for i in range(40)))
    run = batch(manifest, "-j", "2", "--fail-fast")
    assert run.returncode == 2
    built = statuses(run.stdout)
    # the bad job is the first of the first chunk: the other worker finishes the job it is on
    assert len(built) <= 4 and f"{43 - 1 - len(built)} not run" in run.stdout


@pytest.mark.parametrize("jobs,workers", [(100, 2), (1000, 8), (7, 2), (3, 4)])
def test_a_pool_hands_out_chunks_that_shrink_to_single_jobs_at_the_end(jobs, workers):
    sizes, left = [], jobs
    while left:
        sizes.append(chunk_size(left, workers))
        left -= sizes[-1]
    assert sum(sizes) == jobs and max(sizes) <= MAX_CHUNK and sizes == sorted(sizes, reverse=True)
    assert sizes[-2 * workers:] == [1] * min(2 * workers, len(sizes))  # the workers finish together
    if jobs >= 100:
        assert len(sizes) <= jobs / 3  # a round trip per chunk, not per job


class SlowToSend:
    """A result that takes a second to pickle: its worker's failure is known to the other workers
    (the shared --fail-fast flag) a second before it reaches the command."""

    def __reduce__(self):
        time.sleep(1.0)
        return (str, ("slow",))


def fake_run_job(job: Job, work) -> Result:
    """Jobs named for what they do to their worker, for the pool's tests (forked workers inherit it)."""
    import fishgen.batch.jobs as jobs

    deaths = sorted(job.output.parent.glob(f"{job.name}.died*"))
    if job.name.startswith("kills-always") or (job.name.startswith("kills-twice") and len(deaths) < 2):
        job.output.with_suffix(f".died{len(deaths)}").touch()
        os.kill(os.getpid(), signal.SIGKILL)
    started = job.output.parent / "kills-on-failure.started"
    if job.name.startswith("kills-on-failure"):  # stands for a worker lost at the wrong moment
        started.touch()
        waited = time.monotonic()
        while not jobs._failure_flag.value and time.monotonic() - waited < 0.5:
            time.sleep(0.001)
        os.kill(os.getpid(), signal.SIGKILL)
    if job.name.startswith("bad"):
        waited = time.monotonic()
        while "slow" in job.name and not started.exists() and time.monotonic() - waited < 2:
            time.sleep(0.001)  # fails once the other worker is on kills-on-failure
        return Result(job.name, "failed", error=FishgenError("bad"),
                      notes=[SlowToSend()] if "slow" in job.name else [])
    time.sleep(0.01)
    return Result(job.name, "built")


def fake_pool(tmp_path, monkeypatch, names: list[str], fail_fast: bool = False) -> dict[str, list]:
    """Run fake jobs through the local pool of 2 workers; every call of `done`, by job name."""
    import threading

    import fishgen.batch.jobs as jobs
    from fishgen.batch.runner import _pool
    from fishgen.commands.batch import run_job  # picklable; the fake run_job never calls it

    if threading.active_count() > 1 or not sys.platform.startswith("linux"):
        pytest.skip("the workers must be forked to inherit the fake jobs")
    monkeypatch.setattr(jobs, "run_job", fake_run_job)
    reported: dict[str, list] = {}

    def done(job, result) -> bool:
        reported.setdefault(job.name, []).append((result.status,
                                                  result.error.message if result.error else None))
        return fail_fast and result.status == "failed"

    _pool([Job("build", name, (), tmp_path / f"{name}.glb") for name in names], run_job, done, 2, fail_fast)
    return reported


def test_a_job_that_kills_its_worker_fails_alone_and_the_jobs_queued_beside_it_are_built(
        tmp_path, monkeypatch):
    names = [f"fish{i:02d}" for i in range(30)]
    names[3:3] = ["kills-always"]
    # dies in a chunk, then once more alone: an outside kill (an OOM killer) is forgiven once
    names[20:20] = ["kills-twice"]
    reported = fake_pool(tmp_path, monkeypatch, names)
    assert all(len(calls) == 1 for calls in reported.values()) and set(reported) == set(names)
    assert reported.pop("kills-always") == [("failed", "a worker process died twice while building it on its "
                                                         "own (killed, or out of memory)")]
    assert {calls[0] for calls in reported.values()} == {("built", None)}


def test_fail_fast_reports_a_failure_whose_pool_broke_before_it_came_back(tmp_path, monkeypatch):
    # bad-slow fails and the flag is up; its worker is terminated with the broken pool before its
    # result arrives, so it runs again in the next pool, which must not start with the flag up
    names = ["bad-slow", "kills-on-failure"] + [f"fish{i:02d}" for i in range(8)]
    reported = fake_pool(tmp_path, monkeypatch, names, fail_fast=True)
    assert all(len(calls) == 1 for calls in reported.values())
    assert [name for name, calls in reported.items() if calls[0][0] == "failed"]  # the batch fails


@pytest.mark.parametrize("kind", ["build", "school", "clouds"])
def test_a_worker_starts_with_every_module_its_jobs_import(shipped, kind):
    """What the pool imports before it forks (or its forkserver preloads) is all a job needs:
    no worker imports fishgen, numpy, Pillow or scipy itself."""
    code = f"""
import importlib, sys
from pathlib import Path
from fishgen.batch.manifest import load_manifest
from fishgen.batch.jobs import run_job
from fishgen.commands.batch import job_kinds, preload, run_job as work
job = next(j for j in load_manifest(Path("assets.toml"), kinds=job_kinds()).jobs if j.kind == {kind!r})
for module in ["fishgen.batch.jobs", *preload({{{kind!r}}})]:
    importlib.import_module(module)
before = set(sys.modules)
assert run_job(job, work).status == "built"
print(sorted(m for m in set(sys.modules) - before if m.split(".")[0] in ("fishgen", "numpy", "PIL", "scipy")))
"""
    run = subprocess.run([sys.executable, "-c", code], cwd=shipped / "params", capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "[]"


#: Builds in the interrupted batches: enough that a run is still going when its fifth record is
#: written (about 25 a second on 2 cores), few enough that the run finishing it stays short.
MANY = 64


def many_builds(shipped, count: int = MANY):
    """``count`` builds of one species to different names: every output has the same bytes."""
    manifest = shipped / "params" / "many.toml"
    manifest.write_text('out = "../out/many"\n' + "".join(
        f'[[build]]\ninput = "bonybream.txt"\noutput = "fish{i:03d}.glb"\n' for i in range(count)))
    return manifest, shipped / "out" / "many"


def start_batch_until_recorded(manifest: Path, out: Path, jobs: int = 5) -> subprocess.Popen:
    """`fishgen batch MANIFEST -j 2` in the background, returned once its record holds `jobs`
    entries (or it ended, or a minute passed)."""
    proc = subprocess.Popen([sys.executable, "-m", "fishgen", "batch", str(manifest), "-j", "2"], cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and proc.poll() is None:
        try:
            if len(record(out)) >= jobs:
                break
        except (OSError, ValueError):  # not written yet, or caught mid-rename
            pass
        time.sleep(0.01)
    return proc


@pytest.mark.parametrize("signum,status", [(signal.SIGTERM, 143), (signal.SIGINT, 130), (signal.SIGKILL, -9)])
def test_a_batch_killed_midway_leaves_whole_files_and_the_next_run_finishes_it(shipped, signum, status):
    manifest, out = many_builds(shipped)
    assert run_cli("build", manifest.parent / "bonybream.txt", "-o", shipped / "one.glb").returncode == 0
    whole = hashes(shipped)["one.glb"]
    proc = start_batch_until_recorded(manifest, out)
    assert proc.poll() is None, "the batch finished before it could be interrupted"
    proc.send_signal(signum)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == status, stderr
    if signum != signal.SIGKILL:
        assert stderr.endswith("fishgen: interrupted\n") and "Traceback" not in stderr
    time.sleep(1.0 if signum == signal.SIGKILL else 0)  # orphaned workers finish their one job each
    outputs = hashes(out)
    assert 5 <= len(outputs) < MANY
    assert set(outputs.values()) == {whole}  # no partial file
    done = record(out)
    assert all(entry["outputs"][name] == outputs[name] for name, entry in done.items())  # consistent
    if signum != signal.SIGKILL:  # the workers were stopped and cleaned up after themselves
        assert [p.name for p in out.rglob(".*.tmp")] == []
    again = batch(manifest, "-j", "2")
    assert again.returncode == 0, again.stderr
    found = statuses(again.stdout)
    assert {n for n, s in found.items() if s == "skipped"} == set(done)
    assert set(found) == {f"fish{i:03d}.glb" for i in range(MANY)}
    assert set(hashes(out).values()) == {whole}


def descendants(pid: int) -> list[int]:
    """Every process below ``pid`` (the forkserver's workers are the batch's grandchildren)."""
    parents = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            parents[int(stat.parent.name)] = int(stat.read_bytes().rpartition(b")")[2].split()[1])
        except (OSError, ValueError, IndexError):
            continue
    found, frontier = [], [pid]
    while frontier:
        children = [child for child, parent in parents.items() if parent in frontier]
        found += children
        frontier = children
    return found


def helper(pid: int, batch_pid: int) -> bool:
    """multiprocessing's resource tracker, or a forkserver (the batch's child; its workers are not)."""
    try:
        cmdline = Path(f"/proc/{pid}/cmdline").read_bytes()
        parent = int(Path(f"/proc/{pid}/stat").read_bytes().rpartition(b")")[2].split()[1])
    except (OSError, ValueError):
        return True
    return b"resource_tracker" in cmdline or (b"forkserver" in cmdline and parent == batch_pid)


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds the workers through /proc")
def test_a_killed_worker_is_replaced_and_its_jobs_are_tried_again(shipped):
    manifest, out = many_builds(shipped)
    proc = start_batch_until_recorded(manifest, out)
    workers = [pid for pid in descendants(proc.pid) if not helper(pid, proc.pid)]
    assert workers, "no worker found"
    os.kill(workers[0], signal.SIGKILL)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 0 and stderr == "", stderr
    outputs = hashes(out)
    assert len(outputs) == MANY and len(set(outputs.values())) == 1  # every file built, and whole
    assert set(record(out)) == set(outputs)
    again = batch(manifest, "-j", "2")
    assert again.returncode == 0 and set(statuses(again.stdout).values()) == {"skipped"}


def test_a_dask_cluster_builds_the_same_bytes_as_the_local_pool(shipped):
    distributed = pytest.importorskip("distributed")
    manifest = shipped / "params" / "assets.toml"
    assert batch(manifest, "--out", shipped / "local", "-j", "2").returncode == 0
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, protocol="tcp",
                                  host="127.0.0.1", dashboard_address="127.0.0.1:0") as cluster:
        run = batch(manifest, "--out", shipped / "dask", "--scheduler", cluster.scheduler_address,
                    "--report", shipped / "dask.json")
        assert run.returncode == 0, run.stderr
        assert run.stdout.rstrip().endswith(f"({cluster.scheduler_address})")
        again = batch(manifest, "--out", shipped / "dask", "--scheduler", cluster.scheduler_address)
    assert hashes(shipped / "dask") == hashes(shipped / "local")
    assert set(statuses(again.stdout).values()) == {"skipped"}
    report = json.loads((shipped / "dask.json").read_text())
    assert report["scheduler"] == cluster.scheduler_address and report["counts"]["built"] == 9


@contextlib.contextmanager
def server(answer: bytes | None):
    """A TCP server on 127.0.0.1 that, to each connection, says ``answer`` and closes, or (None)
    says nothing until the test ends: what a scheduler address may find that is no scheduler."""
    import socket

    listener = socket.create_server(("127.0.0.1", 0))
    held: list[socket.socket] = []
    stop = threading.Event()

    def serve() -> None:
        listener.settimeout(0.1)
        while not stop.is_set():
            try:
                conn, _ = listener.accept()
            except TimeoutError:
                continue
            if answer is None:
                held.append(conn)
            else:
                with conn:
                    conn.sendall(answer)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        yield f"tcp://127.0.0.1:{listener.getsockname()[1]}"
    finally:
        stop.set()
        thread.join()
        for conn in held:
            conn.close()
        listener.close()


@pytest.mark.parametrize("answer,said", [
    (None, "something there said nothing in 0.5 s, where a scheduler greets at once: another port, "
           "such as its dashboard's?"),
    (b"HTTP/1.1 400 Bad Request\r\n\r\n", "something else answers there: 'HTTP/1.1 400'"),
    (b"", "it closed at once"),
])
def test_an_address_where_no_scheduler_answers_is_refused_in_one_line(answer, said):
    """Dask's Client hung for good on a port that waits for a request (a dashboard's), and read a
    length of 3 EiB from one that answers HTTP, then died 'out of memory' (QA pass 14)."""
    from fishgen.batch.runner import _probe
    from fishgen.errors import SystemFailure

    with server(answer) as address, pytest.raises(SystemFailure) as caught:
        _probe(address, seconds=0.5)
    assert str(caught.value) == f"cannot reach a Dask scheduler at {address} ({said})"


def test_batch_names_what_answers_at_a_scheduler_address_at_once(shipped):
    pytest.importorskip("distributed")
    with server(b"HTTP/1.1 400 Bad Request\r\n\r\n") as address:
        start = time.monotonic()
        run = batch(shipped / "params" / "assets.toml", "--scheduler", address)
    assert run.returncode == 1 and time.monotonic() - start < 10
    assert run.stderr == (f"fishgen: cannot reach a Dask scheduler at {address} (something else answers "
                          "there: 'HTTP/1.1 400')\n")


def test_a_scheduler_passes_the_probe():
    distributed = pytest.importorskip("distributed")
    from fishgen.batch.runner import _probe

    with distributed.LocalCluster(n_workers=0, processes=False, protocol="tcp", host="127.0.0.1",
                                  dashboard_address="127.0.0.1:0") as cluster:
        _probe(cluster.scheduler_address, seconds=5)
