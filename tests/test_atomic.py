"""Atomic output: all or nothing, no temp files left, errors name the user's target."""
from __future__ import annotations

import os
import sys

import pytest

import fishgen.atomic
from fishgen import interrupts
from fishgen.atomic import atomic_open, together, write_bytes, write_files
from fishgen.errors import FishgenError


def leftovers(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def test_replaces_a_file(tmp_path):
    target = tmp_path / "a.bin"
    target.write_bytes(b"old")
    write_bytes(target, b"new")
    assert target.read_bytes() == b"new" and leftovers(tmp_path) == []


def test_folder_in_the_way_is_refused_before_writing(tmp_path):
    (tmp_path / "x.glb").mkdir()
    with pytest.raises(FishgenError, match=r"expected an output file, found a folder$"):
        write_bytes(tmp_path / "x.glb", b"data")
    assert leftovers(tmp_path) == []


def test_a_file_where_a_folder_of_the_target_should_be_is_named(tmp_path):
    (tmp_path / "models").write_bytes(b"not a folder")
    with pytest.raises(FishgenError, match=r"cannot write .*models/fish/a\.glb: expected a folder at "
                                           r".*models, found a file"):
        write_bytes(tmp_path / "models" / "fish" / "a.glb", b"data")
    assert (tmp_path / "models").read_bytes() == b"not a folder" and leftovers(tmp_path) == []


def test_multi_file_output_is_all_or_nothing(tmp_path):
    good = tmp_path / "x.gltf"
    good.write_bytes(b"yesterday")
    (tmp_path / "x.bin").mkdir()
    with pytest.raises(FishgenError):
        write_files({good: b"today", tmp_path / "x.bin": b"buffer"})
    assert good.read_bytes() == b"yesterday" and leftovers(tmp_path) == []


def test_failed_rename_restores_earlier_targets(tmp_path, monkeypatch):
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    a.write_bytes(b"old a")
    b.write_bytes(b"old b")
    real = os.replace
    calls = []

    def flaky(src, dst):
        calls.append(dst)
        if str(dst) == str(b) and str(src).endswith(".tmp"):
            raise OSError(28, "No space left on device")
        return real(src, dst)

    monkeypatch.setattr(os, "replace", flaky)
    with pytest.raises(FishgenError, match="cannot write .*b.txt: No space left on device"):
        write_files({a: b"new a", b: b"new b"})
    assert a.read_bytes() == b"old a" and b.read_bytes() == b"old b" and leftovers(tmp_path) == []


@pytest.mark.parametrize("links", [True, False], ids=["hard links", "no hard links"])
def test_a_set_lands_with_no_moment_its_earlier_files_are_missing(tmp_path, monkeypatch, links):
    """A reader between two renames of a set found no file: each earlier file was renamed aside
    before its new one came. It is linked aside now, and renamed only where links are refused
    (then a rollback still puts it back)."""
    a, b = tmp_path / "x.gltf", tmp_path / "x.bin"
    a.write_bytes(b"old a")
    b.write_bytes(b"old b")
    real, missing = os.replace, []

    def watched(src, dst):
        missing.extend(str(t) for t in (a, b) if not t.exists())
        return real(src, dst)

    monkeypatch.setattr(os, "replace", watched)
    if not links:
        def refused(*args, **kwargs):
            raise OSError(1, "Operation not permitted")

        monkeypatch.setattr(os, "link", refused)
    write_files({a: b"new a", b: b"new b"})
    assert a.read_bytes() == b"new a" and b.read_bytes() == b"new b" and leftovers(tmp_path) == []
    assert missing == ([] if links else [str(a), str(b)])


def test_a_failed_set_leaves_no_folder_it_made_even_after_some_renames(tmp_path, monkeypatch):
    a, b = tmp_path / "new" / "a.gltf", tmp_path / "new" / "b.bin"
    real = os.replace

    def flaky(src, dst):
        if str(dst) == str(b):
            raise OSError(28, "No space left on device")
        return real(src, dst)

    monkeypatch.setattr(os, "replace", flaky)
    with pytest.raises(FishgenError, match="cannot write .*b.bin: No space left on device"):
        write_files({a: b"new a", b: b"new b"})
    assert list(tmp_path.iterdir()) == []


def test_an_earlier_output_that_cannot_be_put_back_is_kept_and_named(tmp_path, monkeypatch):
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    a.write_bytes(b"old a")
    b.write_bytes(b"old b")
    real = os.replace

    def flaky(src, dst):
        if str(dst) == str(b) and str(src).endswith(".tmp"):
            raise OSError(28, "No space left on device")
        if str(dst) == str(a) and str(src).endswith(".old"):  # the restore fails too
            raise OSError(5, "Input/output error")
        return real(src, dst)

    monkeypatch.setattr(os, "replace", flaky)
    with pytest.raises(FishgenError, match=r"cannot write .*a\.txt, nor put its earlier content back: it is "
                                           r"in .*\.a\.txt\.\w+\.old") as raised:
        write_files({a: b"new a", b: b"new b"})
    kept = raised.value.args[0].rsplit(" ", 1)[1]
    assert open(kept, "rb").read() == b"old a" and b.read_bytes() == b"old b"


def test_streaming_writer_discards_on_error(tmp_path):
    target = tmp_path / "big.ply"
    target.write_bytes(b"good")
    with pytest.raises(RuntimeError):
        with atomic_open(target) as handle:
            handle.write(b"partial")
            raise RuntimeError("interrupted")
    assert target.read_bytes() == b"good" and leftovers(tmp_path) == []


def test_streaming_writer_interrupted_while_opening_leaves_no_temp_file(tmp_path, monkeypatch):
    def interrupted(*args, **kwargs):  # SIGTERM in a batch worker raises at any line
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "fdopen", interrupted)
    with pytest.raises(KeyboardInterrupt):
        with atomic_open(tmp_path / "fish.glb"):
            pass
    assert list(tmp_path.iterdir()) == []


def test_a_killed_writers_temporary_file_is_swept_by_the_next_write(tmp_path):
    """Issue 26, fault 15: SIGKILL left full-size `.NAME.XXXX.tmp` files that no run removed. A
    temporary file nobody holds locked and older than a few seconds is a dead run's."""
    import os
    import signal
    import subprocess
    import sys
    import time

    import fishgen.atomic as atomic

    target = tmp_path / "big.bin"
    code = ("import sys, time; from fishgen.atomic import atomic_open\n"
            f"with atomic_open({str(target)!r}) as f:\n"
            "    f.write(b'x' * 1000); f.flush(); print('writing', flush=True); time.sleep(60)\n")
    writer = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert writer.stdout.readline() == "writing\n"
    (temp,) = tmp_path.glob(".big.bin.*.tmp")
    old = time.time() - 2 * atomic.STALE_SECONDS
    os.utime(temp, (old, old))
    assert atomic.sweep(target) == [] and temp.exists()       # held by a live writer: kept
    writer.send_signal(signal.SIGKILL)
    writer.wait()
    assert temp.exists()                                       # SIGKILL: nothing cleaned up
    write_bytes(tmp_path / "big.bin", b"new")           # the next write of that target
    assert not temp.exists() and target.read_bytes() == b"new"


def test_a_fresh_temporary_file_is_never_swept(tmp_path):
    """One that may be a writer's between creating and locking it: younger than STALE_SECONDS."""
    import fishgen.atomic as atomic

    fresh = tmp_path / ".a.txt.0123456789ab.tmp"
    fresh.write_bytes(b"x")
    assert atomic.sweep(tmp_path / "a.txt") == [] and fresh.exists()


@pytest.mark.parametrize("name", ["f" * 251 + ".glb", "é" * 125 + ".glb"], ids=["ascii", "two-byte"])
def test_a_name_as_long_as_the_file_system_takes_is_written_and_swept(tmp_path, name):
    """255 bytes: the temporary file's own name is then shortened, not refused (ENAMETOOLONG)."""
    import fishgen.atomic as atomic

    target = tmp_path / name
    assert len(os.fsencode(target.name)) in (255, 254)
    write_files({target: b"one", tmp_path / "b.bin": b"b"})
    write_files({target: b"two", tmp_path / "b.bin": b"c"})  # over older files: backups, long too
    with atomic_open(target) as handle:
        handle.write(b"three")
    assert target.read_bytes() == b"three" and leftovers(tmp_path) == []
    stale = atomic._beside(target, ".tmp")
    open(stale, "wb").close()
    os.utime(stale, (0, 0))
    assert atomic.sweep(target) == [atomic.Path(stale)]


def test_where_files_cannot_be_locked_none_is_open_as_it_is_renamed(tmp_path, monkeypatch):
    """Windows has no advisory locks, and there a file still open cannot be renamed."""
    if not os.path.isdir("/proc/self/fd"):
        pytest.skip("needs /proc to list open files")
    import fishgen.atomic as atomic

    monkeypatch.setattr(atomic, "_lock", lambda fd: False)
    replace = os.replace
    open_at_rename: list[str] = []

    def checked(src, dst):
        for fd in os.listdir("/proc/self/fd"):
            try:
                if os.readlink(f"/proc/self/fd/{fd}") == os.fspath(src):
                    open_at_rename.append(os.fspath(src))
            except OSError:
                pass
        replace(src, dst)

    monkeypatch.setattr(os, "replace", checked)
    write_files({tmp_path / "a.glb": b"a", tmp_path / "a.bin": b"b"})
    write_files({tmp_path / "a.glb": b"a2", tmp_path / "a.bin": b"b2"})
    with atomic_open(tmp_path / "c.ply") as handle:
        handle.write(b"c")
    assert open_at_rename == [] and (tmp_path / "c.ply").read_bytes() == b"c"
    assert (tmp_path / "a.glb").read_bytes() == b"a2" and leftovers(tmp_path) == []


def test_a_set_larger_than_the_open_file_limit_holds_few_descriptors_and_lands_whole(tmp_path, monkeypatch):
    """QA: 10,000 species are 30,000 staged files, each held open for its lock: `Too many open
    files` from the thousandth on. Beyond a budget, staged files go unlocked, and none is swept."""
    import fishgen.atomic as atomic

    monkeypatch.setattr(atomic, "_budget", 4, raising=False)
    monkeypatch.setattr(atomic, "STALE_SECONDS", -1.0)   # every unlocked file is "old": still ours
    with together():
        for k in range(40):
            write_files({tmp_path / f"s{k}.txt": b"t", tmp_path / f"s{k}.png": bytes([k])})
            assert len(atomic._held) <= 4
        assert atomic.sweep(tmp_path / "s0.txt") == []   # this run's own sweep takes none of them
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [f"s{k}.txt" for k in range(40)] + [f"s{k}.png" for k in range(40)])
    assert (tmp_path / "s39.png").read_bytes() == bytes([39]) and atomic._held == {}


def test_a_large_set_resolves_each_target_once_not_once_per_write(tmp_path, monkeypatch):
    """QA: every write inside `together` resolved every target staged before it, so 30,000 files
    (species --count 10000) took half an hour of resolve() calls."""
    import fishgen.atomic as atomic

    calls = 0
    real = atomic.Path.resolve

    def counted(self, *args, **kwargs):
        nonlocal calls
        calls += 1
        return real(self, *args, **kwargs)

    monkeypatch.setattr(atomic.Path, "resolve", counted)
    with together():
        for k in range(200):
            write_bytes(tmp_path / f"f{k}.bin", b"x")
        with pytest.raises(FishgenError, match="twice"):
            write_bytes(tmp_path / "f7.bin", b"y")   # the check still holds
    assert calls < 3 * 201 and len(list(tmp_path.iterdir())) == 200


def test_a_failed_set_of_outputs_leaves_no_folder_it_made(tmp_path):
    with pytest.raises(RuntimeError), together():
        write_bytes(tmp_path / "a" / "b" / "x.glb", b"glb")
        write_bytes(tmp_path / "a" / "b" / "x.bin", b"bin")
        write_bytes(tmp_path / "a" / "m.json", b"{}")
        raise RuntimeError("a later output failed")
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "kept").mkdir()
    with pytest.raises(RuntimeError), together():
        write_bytes(tmp_path / "kept" / "new" / "x.glb", b"glb")
        raise RuntimeError("a later output failed")
    assert list(tmp_path.iterdir()) == [tmp_path / "kept"] and list((tmp_path / "kept").iterdir()) == []


class Interrupt(BaseException):
    """What a signal handler raises (SIGTERM in a batch worker, Ctrl-C in the CLI)."""


def interrupted_at(step: int, write) -> bool:
    """Run ``write()`` with an interrupt raised at its ``step``-th chance, as a signal handler's
    exception would be: CPython runs handlers on entering a function or resuming a generator, when
    a call returns, and on a backward jump. Counted in the frames of the atomic writer, of
    fishgen.interrupts and of contextlib (every frame would be thousands of steps of pathlib, and an
    exception inside the standard library's own locks would hang it). Then, as the CLI and a batch
    worker do before they exit, the registered cleanups run. False: it ended first."""
    import contextlib
    import dis
    import sys

    count = 0
    after: dict = {}  # a running frame's id -> the instruction it ran last (no reference: a frame kept
    # alive would keep a generator from being closed, as it is when its exception is dropped)
    watched = {fishgen.atomic.__file__, interrupts.__file__, contextlib.__file__}

    def chance() -> None:
        nonlocal count
        count += 1
        if count == step:
            interrupts.deliver(Interrupt())  # as fishgen's signal handlers raise

    def trace(frame, event, arg):
        if frame.f_code.co_filename not in watched:
            return None
        frame.f_trace_opcodes = True
        if event == "call":  # entering the function, or resuming the generator
            chance()
        elif event == "return":
            after.pop(id(frame), None)
        elif event == "opcode":
            name = dis.opname[frame.f_code.co_code[frame.f_lasti]]
            if name in ("JUMP_BACKWARD", "JUMP_ABSOLUTE") or after.get(id(frame), "").startswith("CALL"):
                chance()
            after[id(frame)] = name
        return trace

    sys.settrace(trace)
    try:
        write()
    except Interrupt:
        sys.settrace(None)
        interrupts.stopped()
        return True
    finally:
        sys.settrace(None)
    return False


@pytest.mark.skipif(sys.version_info[:2] == (3, 12), reason="Python 3.12 traces no instruction of the frame "
                    "already running when tracing starts (CPython issue 114480)")
@pytest.mark.parametrize("how", ["write_files", "write_files over older files", "together", "atomic_open"])
def test_an_interrupt_at_any_step_leaves_no_temporary_file_and_no_half_set(tmp_path, how):
    """A signal's exception may come at any of the writer's steps, also between creating a
    temporary file and noting its name, or between two renames: every step is tried, and none may
    leave a file behind or a set of outputs half old and half new."""
    target, other = tmp_path / "out" / "deep" / "a.glb", tmp_path / "out" / "deep" / "a.png"
    old = how.endswith("older files")
    if old:
        target.parent.mkdir(parents=True)
        target.write_bytes(b"old glb")
        other.write_bytes(b"old png")

    def write():
        if how.startswith("write_files"):
            write_files({target: b"new", other: b"png"})
        elif how == "together":
            with together():
                write_bytes(target, b"new")
                write_bytes(other, b"png")
        else:
            with atomic_open(target) as handle:
                handle.write(b"new")

    step = 1
    while interrupted_at(step, write):
        names = sorted(p.name for p in tmp_path.rglob("*"))
        assert [n for n in names if n.endswith((".tmp", ".old"))] == [], f"interrupted at step {step}"
        assert old or target.exists() or names == [], f"interrupted at step {step}: a folder made is left"
        assert fishgen.atomic._staging.get() is None, f"interrupted at step {step}: later writes staged"
        if old:  # all old or all new
            pair = (target.read_bytes(), other.read_bytes())
            assert pair in {(b"old glb", b"old png"), (b"new", b"png")}, f"interrupted at step {step}"
        elif target.exists():  # the rename came first: the output is whole
            assert target.read_bytes() == b"new"
        step += 1
    assert step > 10 and target.read_bytes() == b"new"


def test_a_new_file_gets_what_the_umask_allows_and_a_replaced_one_keeps_its_mode(tmp_path):
    """Every write was chmod 0644: a 0600 file turned world-readable when replaced."""
    import os
    import stat

    old = os.umask(0o077)
    try:
        write_files({tmp_path / "new.txt": b"a"})
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "new.txt").stat().st_mode) == 0o600
    (tmp_path / "private.txt").write_bytes(b"x")
    (tmp_path / "private.txt").chmod(0o640)
    write_files({tmp_path / "private.txt": b"y"})
    assert stat.S_IMODE((tmp_path / "private.txt").stat().st_mode) == 0o640
    with atomic_open(tmp_path / "private.txt") as handle:
        handle.write(b"z")
    assert stat.S_IMODE((tmp_path / "private.txt").stat().st_mode) == 0o640
