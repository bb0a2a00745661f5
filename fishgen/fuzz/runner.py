"""Run fuzz cases in persistent worker processes under a memory and time budget.

Each worker is started once (from a fork server), imports everything, loads the seed corpus,
then lowers its own address-space limit (``RLIMIT_AS``) and serves batches of case indices: it
regenerates each case from ``(seed, target, index)``, runs it in-process with a per-case timer, and sends back
counts and findings. The parent is a watchdog: a worker that stops making progress (a hang
in C code the timer cannot interrupt) is killed and restarted, and a worker that dies (the
kernel's OOM killer, a crash under the memory limit) is a finding as well.

A case's time budget is CPU time (the worker's, all its threads), not wall time: on a shared
machine a loaded hour made cases that take 15 s of CPU take 30 s of wall time, and a wall-clock
budget reported the machine's load as fishgen's overrun (seed 33's run, issue 32 item 5). The
watchdog's backstop for a case that waits without using CPU leaves out the time the worker
waited for a core: a niced run beside busy neighbours waited a minute for one.
"""
from __future__ import annotations

import logging
import multiprocessing as mp
import os
import re
import resource
import shutil
import signal
import tempfile
import time
import warnings
from collections import deque
from dataclasses import dataclass, field
from multiprocessing.connection import wait
from pathlib import Path

from fishgen.fuzz.cases import make_case, run_case
from fishgen.fuzz.inputs import DEFAULT_CORPUS, load_seeds
from fishgen.fuzz.verdict import CaseTimeout, Outcome

#: Address space a worker may use. Imports take ~360 MB of address space, an EGL preview
#: context another ~650 MB (measured with /proc/self/status VmPeak), so a correct CLI preview
#: peaks near 1.0 GB; everything a correct run needs fits well inside 1.5 GB.
DEFAULT_BUDGET_MB = 1536
#: A worker whose address space comes within this much of its budget retires after its batch and
#: a fresh one takes its place: one process runs ~10^5 cases, and what the libraries keep (caches,
#: an EGL context, a fragmented heap) grows until a correct case finds no room (seed 31: a
#: MemoryError reading a 1 KB file, and one in the fuzzer's own case generation, each of which
#: replays clean in a fresh process).
RETIRE_HEADROOM_MB = 256
#: CPU seconds one case may take (parsers are ~1 ms, readers ~10 ms, CLI previews ~0.3 s). A photo's
#: `--fit-shape` takes 3 s, but one whose silhouette fits badly is fitted at five placements, 7 s
#: each on a tall, narrow photo (seed 37, photo #48: 26-31 s): the limit is twice that.
TIME_LIMITS = {"species": 2.0, "cubes": 2.0, "gltf": 5.0, "obj": 5.0, "ply": 5.0, "cli": 20.0,
               "scene": 5.0, "paths": 5.0, "manifest": 5.0, "fxl": 2.0, "photo": 60.0, "awa": 5.0,
               "editor": 10.0, "options": 20.0}
#: Extra CPU seconds the parent allows past a case's limit before killing a worker stuck in C code.
GRACE = 10.0
#: A case still running after this many times its limit in wall time (plus GRACE) is hung even
#: without using CPU (a wait that never ends); a loaded machine stretches wall time, so it is wide.
WALL_FACTOR = 6.0
BATCH = {"species": 100, "cubes": 200, "gltf": 20, "obj": 10, "ply": 20, "cli": 2,
         "scene": 50, "paths": 10, "manifest": 50, "fxl": 200, "photo": 1, "awa": 20, "editor": 5,
         "options": 2}


@dataclass
class Finding:
    key: str
    target: str
    seed: int
    index: int
    detail: str
    count: int = 1
    folder: Path | None = None


@dataclass
class Stats:
    inputs: int = 0
    ok: int = 0
    errors: int = 0
    findings: int = 0
    busy: float = 0.0  # worker-seconds spent on this target

    @property
    def rate(self) -> float:
        return self.inputs / self.busy if self.busy else 0.0


@dataclass
class Report:
    stats: dict[str, Stats] = field(default_factory=dict)
    findings: dict[str, Finding] = field(default_factory=dict)
    wall: float = 0.0
    retired: int = 0    # workers replaced because they neared their memory budget

    @property
    def total(self) -> int:
        return sum(s.inputs for s in self.stats.values())


def _worker(conn, progress, corpus: str, budget: int, workdir: str, headroom: int,
            quiet: bool = True) -> None:
    # Import everything a case may need before the memory limit, as a long-lived tool would.
    import fishgen.assembly.fish  # noqa: F401

    # issue 26's targets
    import fishgen.authoring.photo.fxl  # noqa: F401
    import fishgen.authoring.photo.run  # noqa: F401
    import fishgen.batch.manifest  # noqa: F401
    import fishgen.cli.adapter  # noqa: F401
    import fishgen.clouds.fill  # noqa: F401
    import fishgen.commands.build  # noqa: F401
    import fishgen.commands.clouds  # noqa: F401
    import fishgen.commands.fly  # noqa: F401
    import fishgen.commands.preview  # noqa: F401
    import fishgen.commands.sky  # noqa: F401
    import fishgen.commands.texture  # noqa: F401
    import fishgen.editor.session  # noqa: F401
    import fishgen.exchange.gltf_reader  # noqa: F401
    import fishgen.exchange.mesh_reader  # noqa: F401
    import fishgen.fly.assets  # noqa: F401
    import fishgen.fly.headless  # noqa: F401
    import fishgen.preview.inputs  # noqa: F401
    import fishgen.scene.pose  # noqa: F401
    import fishgen.school.scene_file  # noqa: F401
    import fishgen.species.parser  # noqa: F401
    import fishgen.web.server  # noqa: F401

    seeds = load_seeds(Path(corpus))
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles ^C
    # Libraries log and warn about the broken inputs they are fed (trimesh prints tracebacks of
    # errors it recovers from); none of that is a finding, and it would drown the report.
    logging.disable(logging.CRITICAL)
    warnings.simplefilter("ignore")
    if quiet:
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, 1)
        os.dup2(null, 2)

    def alarm(*_):
        raise CaseTimeout("per-case time limit")

    signal.signal(signal.SIGPROF, alarm)
    if budget:
        resource.setrlimit(resource.RLIMIT_AS, (budget, budget))
    work = Path(workdir)
    while True:
        msg = conn.recv()
        if msg is None:
            break
        target, seed, indices, limit = msg
        counts = {"ok": 0, "error": 0}
        found: list[tuple[int, str, str]] = []
        start = time.monotonic()
        for index in indices:
            progress[0], progress[1] = index, time.monotonic()
            progress[2], progress[3] = _clock() or (0.0, 0.0)
            try:
                signal.setitimer(signal.ITIMER_PROF, limit)
                try:
                    case = make_case(seeds, target, seed, index)
                except Exception as err:  # a bug in the fuzzer itself: shown, never hidden
                    outcome = Outcome("finding", f"fuzz harness error: {err!r}", "")
                else:
                    outcome = run_case(case, work)
            except CaseTimeout:
                outcome = Outcome("finding", f"budget overrun (time) in {target}", "")
            except MemoryError:
                outcome = Outcome("finding", f"budget overrun (memory) in {target} (outside fishgen)", "")
            finally:
                signal.setitimer(signal.ITIMER_PROF, 0)
            if outcome.status == "finding":
                found.append((index, outcome.key, outcome.detail))
            else:
                counts[outcome.status] += 1
        retire = bool(budget) and _address_space() > budget - headroom
        conn.send((counts, found, time.monotonic() - start, retire))
        if retire:
            break


def _address_space() -> int:
    """This process's address space in bytes (what RLIMIT_AS caps); 0 where /proc does not say."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) << 10
    except OSError:
        pass
    return 0


_TICK = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100


def _clock(pid: int | str = "self") -> tuple[float, float] | None:
    """Process ``pid``'s CPU seconds so far (user + system, all its threads) and the seconds its
    main thread waited for a core (runnable, not run); None where /proc does not say (the
    watchdog then goes by wall time alone)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as stat:
            fields = stat.read().rsplit(")", 1)[1].split()
        with open(f"/proc/{pid}/schedstat", encoding="ascii") as sched:
            waited = int(sched.read().split()[1]) / 1e9
    except (OSError, IndexError, ValueError):
        return None
    return (int(fields[11]) + int(fields[12])) / _TICK, waited   # utime, stime: stat's 14th, 15th


def _hung(pid: int, progress, now: float, limit: float) -> bool:
    """Whether the worker's current case ran past its limit plus GRACE in CPU seconds (stuck in C
    code the timer cannot interrupt), or past WALL_FACTOR times it in wall time less the time it
    waited for a core (stuck waiting; a starved worker on a busy machine is not)."""
    clock = _clock(pid)
    if clock is None:
        return now - progress[1] > limit + GRACE
    cpu, waited = clock
    return (cpu - progress[2] > limit + GRACE
            or now - progress[1] - (waited - progress[3]) > WALL_FACTOR * limit + GRACE)


class _Worker:
    def __init__(self, ctx, corpus: Path, budget: int, root: Path, number: int, headroom: int):
        self.ctx, self.corpus, self.budget, self.number = ctx, corpus, budget, number
        self.headroom = headroom
        self.workdir = root / f"w{number}"
        self.batch: tuple[str, int, list[int]] | None = None
        self.sent = 0.0
        self.start()

    def start(self) -> None:
        self.workdir.mkdir(parents=True, exist_ok=True)
        self.conn, child = self.ctx.Pipe()
        # the case, and its start: wall time, CPU time, time waited for a core
        self.progress = self.ctx.RawArray("d", [-1.0, 0.0, 0.0, 0.0])
        self.proc = self.ctx.Process(target=_worker, daemon=True,
                                     args=(child, self.progress, str(self.corpus), self.budget,
                                           str(self.workdir), self.headroom))
        self.proc.start()
        child.close()

    def send(self, target: str, seed: int, indices: list[int]) -> None:
        self.batch = (target, seed, indices)
        # until its first case starts, the worker is timed from now, on its clocks as they stand
        self.progress[:] = [-1.0, time.monotonic(), *(_clock(self.proc.pid) or (0.0, 0.0))]
        self.sent = time.monotonic()
        self.conn.send((target, seed, indices, TIME_LIMITS[target]))

    def kill(self) -> None:
        if self.proc.is_alive():
            os.kill(self.proc.pid, signal.SIGKILL)
        self.proc.join()
        self.conn.close()

    def stop(self) -> None:
        try:
            self.conn.send(None)
        except (BrokenPipeError, OSError):
            pass
        self.proc.join(5)
        if self.proc.is_alive():
            self.kill()
        self.conn.close()


def _slug(key: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "-", key).strip("-")[:90]


def run(targets: list[str], *, seed: int = 0, minutes: float | None = None,
        counts: dict[str, int] | None = None, jobs: int = 1, corpus: Path = DEFAULT_CORPUS,
        findings_dir: Path | None = None, budget_mb: int = DEFAULT_BUDGET_MB,
        on_finding=None, headroom_mb: int = RETIRE_HEADROOM_MB) -> Report:
    """Fuzz ``targets`` for ``minutes`` (round-robin by time) or ``counts[target]`` inputs each.
    A worker within ``headroom_mb`` of ``budget_mb`` after a batch is replaced by a fresh one.

    Case indices start at 0, so every run first replays the whole seed corpus verbatim.
    """
    seeds = load_seeds(corpus)
    report = Report({t: Stats() for t in targets})
    next_index = {t: 0 for t in targets}
    requeued: dict[str, deque[int]] = {t: deque() for t in targets}
    deadline = time.monotonic() + minutes * 60 if minutes is not None else None
    # A fork server, not fork: the caller may hold threads (pytest with playwright's browser), and a
    # child forked from a threaded process can deadlock on a lock another thread held.
    ctx = mp.get_context("forkserver")
    ctx.set_forkserver_preload(["fishgen.fuzz.runner"])
    root = Path(tempfile.mkdtemp(prefix="fishgen-fuzz-"))
    workers = [_Worker(ctx, corpus, budget_mb << 20, root, j, headroom_mb << 20) for j in range(max(1, jobs))]
    started = time.monotonic()

    def record(target: str, index: int, key: str, detail: str) -> None:
        report.stats[target].findings += 1
        if key in report.findings:
            report.findings[key].count += 1
            return
        f = Finding(key, target, seed, index, detail)
        report.findings[key] = f
        if findings_dir is not None:
            f.folder = findings_dir / f"{len(report.findings):03d}-{_slug(key)}"
            try:
                make_case(seeds, target, seed, index).save(f.folder)
            except Exception as err:  # a case that cannot even be regenerated is still reported
                f.detail += f"\n(could not save the input: {err!r})"
            f.folder.mkdir(parents=True, exist_ok=True)
            (f.folder / "finding.txt").write_text(
                f"{key}\n\ntarget {target}, seed {seed}, index {index}\n"
                f"replay: python -m fishgen.fuzz --replay {target}:{seed}:{index}\n\n{detail}\n")
        if on_finding is not None:
            on_finding(f)

    def pick() -> tuple[str, list[int]] | None:
        if deadline is not None:
            if time.monotonic() >= deadline:
                return None
            live = targets
        else:
            assert counts is not None
            live = [t for t in targets if requeued[t] or next_index[t] < counts.get(t, 0)]
            if not live:
                return None
        # the target with the least worker time so far (plus what is in flight) goes next
        in_flight = {t: 0.0 for t in targets}
        for w in workers:
            if w.batch is not None:
                in_flight[w.batch[0]] += time.monotonic() - w.sent + 0.01
        target = min(live, key=lambda t: report.stats[t].busy + in_flight[t])
        if requeued[target]:
            batch = [requeued[target].popleft() for _ in range(min(len(requeued[target]), BATCH[target]))]
            return target, batch
        stop = next_index[target] + BATCH[target]
        if counts is not None:
            stop = min(stop, counts.get(target, 0))
        # the seed corpus goes one case per batch position so a broken seed cannot hide others
        batch = list(range(next_index[target], stop))
        next_index[target] = stop
        return target, batch

    try:
        while True:
            for w in workers:
                if w.batch is None:
                    job = pick()
                    if job is not None:
                        w.send(job[0], seed, job[1])
            busy = [w for w in workers if w.batch is not None]
            if not busy:
                break
            ready = wait([w.conn for w in busy], timeout=0.25)
            now = time.monotonic()
            for w in busy:
                assert w.batch is not None
                target, _, indices = w.batch
                if w.conn in ready:
                    try:
                        done, found, elapsed, retire = w.conn.recv()
                    except (EOFError, OSError):
                        done = None
                    if done is not None:
                        st = report.stats[target]
                        st.inputs += len(indices)
                        st.ok += done["ok"]
                        st.errors += done["error"]
                        st.busy += elapsed
                        for index, key, detail in found:
                            record(target, index, key, detail)
                        w.batch = None
                        if retire:  # near its memory budget: a fresh worker takes over
                            report.retired += 1
                            w.stop()
                            w.start()
                        continue
                current = int(w.progress[0])
                stuck = _hung(w.proc.pid, w.progress, now, TIME_LIMITS[target])
                if w.proc.is_alive() and not stuck:
                    continue
                # died or hung: the current case is a finding; the rest of the batch is run again
                code = w.proc.exitcode
                w.kill()
                if current < 0:
                    current = indices[0]
                if stuck:
                    hung = TIME_LIMITS[target] + GRACE
                    key = f"budget overrun (time: hung in C code past {hung:.0f} CPU s) in {target}"
                else:
                    key = f"worker died ({_death(code)}) in {target}"
                done_before = indices.index(current) if current in indices else 0
                st = report.stats[target]
                st.inputs += done_before + 1
                st.busy += now - w.sent
                record(target, current, key, f"exit code {code}")
                requeued[target].extend(indices[done_before + 1:])
                w.batch = None
                w.start()
    finally:
        for w in workers:
            w.stop()
        shutil.rmtree(root, ignore_errors=True)
    report.wall = time.monotonic() - started
    return report


def _death(code: int | None) -> str:
    if code is not None and code < 0:
        try:
            return f"signal {signal.Signals(-code).name}"
        except ValueError:
            return f"signal {-code}"
    return f"exit code {code}"
