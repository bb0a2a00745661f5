"""Big outputs go past the page cache in whole blocks; the bytes are the same whatever happens."""
import errno
import mmap
import os

import numpy as np
import pytest

import fishgen.uncached as uncached
from fishgen.atomic import atomic_open, write_bytes
from fishgen.errors import SystemFailure

BLOCK = 4 * 4096


@pytest.fixture(autouse=True)
def small_blocks(monkeypatch):
    """Blocks of 16 KiB, so a test file of a few blocks takes the big-file path; no spare buffers."""
    monkeypatch.setattr(uncached, "BLOCK", BLOCK)
    monkeypatch.setattr(uncached, "_spare", [])


@pytest.fixture
def writes(monkeypatch):
    """Every write of the file's bytes: (how many, "direct" or "cached")."""
    seen: list[tuple[int, str]] = []
    write, drain = os.write, uncached.UncachedWriter._drain

    def direct(fd, data):
        written = write(fd, data)
        seen.append((written, "direct"))
        return written

    def cached(self, data):
        seen.append((len(data), "cached"))
        return drain(self, data)

    monkeypatch.setattr(os, "write", direct)
    monkeypatch.setattr(uncached.UncachedWriter, "_drain", cached)
    return seen


@pytest.fixture
def direct_here(tmp_path):
    """Skip where this file system takes no O_DIRECT write (another system, tmpfs before Linux 6.6)."""
    fd = os.open(tmp_path / "probe", os.O_WRONLY | os.O_CREAT, 0o600)
    try:
        buffer = mmap.mmap(-1, 4096)
        if not uncached._set_direct(fd, True) or os.write(fd, buffer) != 4096:
            pytest.skip("no O_DIRECT writes here")
    except OSError as err:
        pytest.skip(f"no O_DIRECT writes here: {err}")
    finally:
        os.close(fd)
        os.unlink(tmp_path / "probe")


def pieces(total: int, seed: int = 0) -> list[bytes]:
    """``total`` random bytes in pieces of odd sizes, as the PLY header and record chunks come."""
    rng = np.random.default_rng(seed)
    data = rng.integers(0, 256, total, dtype=np.uint8).tobytes()
    cuts = np.sort(rng.choice(np.arange(1, total), min(9, total - 1), replace=False)) if total > 1 else []
    return [data[a:b] for a, b in zip([0, *cuts], [*cuts, total], strict=True)]


def test_whole_blocks_go_past_the_cache_and_the_end_through_it(tmp_path, direct_here, writes):
    parts = pieces(3 * BLOCK + 1234)
    with atomic_open(tmp_path / "cloud.ply") as handle:
        for part in parts:
            handle.write(part)
    assert (tmp_path / "cloud.ply").read_bytes() == b"".join(parts)
    assert writes == [(BLOCK, "direct")] * 3 + [(1234, "cached")]
    assert os.listdir(tmp_path) == ["cloud.ply"]


def test_a_small_file_is_one_ordinary_write(tmp_path, writes):
    write_bytes(tmp_path / "fish.glb", b"x" * (BLOCK - 1))
    assert (tmp_path / "fish.glb").read_bytes() == b"x" * (BLOCK - 1)
    assert writes == [(BLOCK - 1, "cached")]


def test_files_one_after_another_share_one_buffer(tmp_path, monkeypatch):
    """A new mapping a file made thousands of small files slower than before (fresh pages each)."""
    made = []
    real = mmap.mmap

    def counted(*args, **kwargs):
        made.append(args)
        return real(*args, **kwargs)

    monkeypatch.setattr(uncached.mmap, "mmap", counted)
    for k in range(20):
        write_bytes(tmp_path / f"{k}.txt", b"%d" % k)
    assert len(made) == 1 and (tmp_path / "7.txt").read_bytes() == b"7"


@pytest.mark.parametrize("size", [0, 1, BLOCK - 1, BLOCK, BLOCK + 1, 2 * BLOCK, 2 * BLOCK + 4095])
def test_every_size_lands_as_given(tmp_path, size):
    parts = pieces(size, seed=size)
    with atomic_open(tmp_path / "a.bin") as handle:
        for part in parts:
            handle.write(memoryview(part))
        assert handle.tell() == size
    assert (tmp_path / "a.bin").read_bytes() == b"".join(parts)


def test_a_write_after_a_flush_and_numpy_records_land_as_given(tmp_path):
    records = np.zeros(3 * BLOCK // 7, dtype=[("x", "<f4"), ("c", "|u1"), ("i", "<u2")])
    records["x"] = np.arange(len(records)) / 3
    records["c"] = np.arange(len(records)) % 251
    with atomic_open(tmp_path / "a.bin") as handle:
        handle.write(b"header\n")
        handle.flush()                          # the offset is no longer aligned: the rest is cached
        handle.write(records.data.cast("B"))
    assert (tmp_path / "a.bin").read_bytes() == b"header\n" + records.tobytes()


def test_without_direct_writes_the_same_bytes_land_through_the_cache(tmp_path, monkeypatch, writes):
    """Another system, or a file system that refuses O_DIRECT when it is turned on."""
    monkeypatch.setattr(uncached, "_set_direct", lambda fd, on: False)
    parts = pieces(2 * BLOCK + 77, seed=1)
    write_bytes(tmp_path / "cloud.ply", b"".join(parts))
    assert (tmp_path / "cloud.ply").read_bytes() == b"".join(parts)
    assert writes == [(BLOCK, "cached"), (BLOCK, "cached"), (77, "cached")]


@pytest.mark.parametrize("refusal", ["EINVAL", "short"])
def test_after_a_refused_or_short_direct_write_the_rest_goes_through_the_cache(tmp_path, direct_here,
                                                                               monkeypatch, writes, refusal):
    """A device whose blocks the buffer does not fit (EINVAL), a nearly full disk (a short write)."""
    parts = pieces(4 * BLOCK + 77, seed=2)
    write = os.write          # the spy's
    calls = []

    def refusing(fd, data):
        calls.append(len(data))
        if len(calls) == 2 and refusal == "EINVAL":
            raise OSError(errno.EINVAL, os.strerror(errno.EINVAL))
        return write(fd, data[:4096] if len(calls) == 2 else data)   # aligned: a real short write

    monkeypatch.setattr(os, "write", refusing)
    write_bytes(tmp_path / "cloud.ply", b"".join(parts))
    assert (tmp_path / "cloud.ply").read_bytes() == b"".join(parts)
    second = [(BLOCK, "cached")] if refusal == "EINVAL" else [(4096, "direct"), (BLOCK - 4096, "cached")]
    assert writes == [(BLOCK, "direct"), *second, (BLOCK, "cached"), (BLOCK, "cached"), (77, "cached")]


@pytest.mark.parametrize("size", [BLOCK // 2, 3 * BLOCK])
def test_a_full_disk_is_said_and_nothing_is_left(tmp_path, monkeypatch, size):
    target = tmp_path / "cloud.ply"
    target.write_bytes(b"earlier")

    def full(*args):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "write", full)                       # a direct write
    monkeypatch.setattr(uncached.UncachedWriter, "_drain", full)  # and one through the cache
    with pytest.raises(SystemFailure, match="No space left on device"):
        write_bytes(target, b"y" * size)
    assert target.read_bytes() == b"earlier" and os.listdir(tmp_path) == ["cloud.ply"]


def test_a_full_block_is_written_on_its_own_thread_while_the_next_fills_and_in_order(tmp_path, monkeypatch):
    """The disk's time overlaps the caller's packing, as the page cache's writeback did."""
    import threading
    import time

    threads = []
    write, drain = os.write, uncached.UncachedWriter._drain

    def slow_direct(fd, data):
        threads.append(threading.current_thread().name)
        time.sleep(0.01)
        return write(fd, data)

    def slow_cached(self, data):
        threads.append(threading.current_thread().name)
        time.sleep(0.01)
        return drain(self, data)

    monkeypatch.setattr(os, "write", slow_direct)
    monkeypatch.setattr(uncached.UncachedWriter, "_drain", slow_cached)
    parts = pieces(6 * BLOCK + 5, seed=3)
    with atomic_open(tmp_path / "cloud.ply") as handle:
        for part in parts:
            handle.write(part)
    assert (tmp_path / "cloud.ply").read_bytes() == b"".join(parts)
    assert threads[:6] == [threads[0]] * 6 and threads[0].startswith("fishgen-write")
    assert threads[6:] == [threading.current_thread().name], "the file's end, from the caller's thread"


def test_an_error_in_the_body_waits_for_the_block_in_flight_writes_nothing_more_and_leaves_nothing(
        tmp_path, monkeypatch):
    import threading
    import time

    import fishgen.atomic as atomic

    events = []
    write, discard = os.write, atomic._discard

    def slow_block(fd, data):
        time.sleep(0.05)
        written = write(fd, data)
        events.append("block written")
        return written

    monkeypatch.setattr(os, "write", slow_block)
    def drained(self, data):
        events.append(f"{threading.current_thread().name} wrote {len(data)}")
        return slow_block(self.fileno(), data)

    monkeypatch.setattr(uncached.UncachedWriter, "_drain", drained)
    monkeypatch.setattr(atomic, "_discard", lambda tmp: (events.append("discarded"), discard(tmp)))
    with pytest.raises(RuntimeError, match="stopped"):
        with atomic_open(tmp_path / "cloud.ply") as handle:
            handle.write(b"z" * (BLOCK + 10))     # a block now in flight, 10 bytes staged
            raise RuntimeError("stopped")
    assert "block written" in events and events.index("block written") < events.index("discarded")
    assert not any(e.startswith("MainThread") for e in events), "a dropped file's staged end is not written"
    assert os.listdir(tmp_path) == []


def test_the_next_block_fills_while_one_is_written(tmp_path, monkeypatch):
    """A block's write that waited for nothing would be a synchronous write in another thread."""
    import threading

    filled = threading.Event()
    write, drain = os.write, uncached.UncachedWriter._drain

    def held(fd, data):
        assert filled.wait(10), "the caller did not go on filling while a block was written"
        return write(fd, data)

    monkeypatch.setattr(os, "write", held)
    monkeypatch.setattr(uncached.UncachedWriter, "_drain",
                        lambda self, data: held(self.fileno(), data) if threading.current_thread().name
                        .startswith("fishgen-write") else drain(self, data))
    with atomic_open(tmp_path / "cloud.ply") as handle:
        handle.write(b"a" * BLOCK)       # handed to the writing thread, which waits for the next write
        handle.write(b"b" * (BLOCK // 2))
        filled.set()
    assert (tmp_path / "cloud.ply").read_bytes() == b"a" * BLOCK + b"b" * (BLOCK // 2)


@pytest.mark.parametrize("interrupt", [KeyboardInterrupt, RuntimeError])
def test_an_interrupt_stays_an_interrupt_though_the_block_in_flight_fails(tmp_path, monkeypatch, interrupt):
    """The block's error replaced it, so a batch worker stopped by SIGTERM went on to its next job."""
    import time

    def failing(*args):
        time.sleep(0.05)
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    monkeypatch.setattr(os, "write", failing)
    monkeypatch.setattr(uncached.UncachedWriter, "_drain", failing)
    with pytest.raises(interrupt):
        with atomic_open(tmp_path / "cloud.ply") as handle:
            handle.write(b"z" * BLOCK)
            raise interrupt("stopped")
    assert os.listdir(tmp_path) == []


def test_a_failed_write_closes_its_file_at_once_so_a_full_disk_gets_its_space_back(tmp_path, monkeypatch):
    """The error's traceback held the writer, its thread and the open (deleted) temporary file."""
    import gc

    if not os.path.isdir("/proc/self/fd"):
        pytest.skip("needs /proc to list open files")

    def full(*args):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "write", full)
    monkeypatch.setattr(uncached.UncachedWriter, "_drain", full)
    gc.disable()
    try:
        kept = []
        for k in range(3):
            try:
                with atomic_open(tmp_path / f"c{k}.ply") as handle:
                    handle.write(b"y" * (BLOCK + 1))
            except SystemFailure as err:
                kept.append(err)          # as a batch keeps each job's error
        held = [os.readlink(f"/proc/self/fd/{fd}") for fd in os.listdir("/proc/self/fd")
                if os.path.exists(f"/proc/self/fd/{fd}")]
    finally:
        gc.enable()
    assert len(kept) == 3 and not [h for h in held if str(tmp_path) in h]


def test_after_a_block_fails_every_later_call_says_so(tmp_path, monkeypatch):
    write = os.write
    calls = []

    def first_fails(fd, data):
        calls.append(len(data))
        if len(calls) == 1:
            raise OSError(errno.EIO, os.strerror(errno.EIO))
        return write(fd, data)

    monkeypatch.setattr(os, "write", first_fails)
    monkeypatch.setattr(uncached, "_set_direct", lambda fd, on: True)
    fd = os.open(tmp_path / "a.bin", os.O_WRONLY | os.O_CREAT, 0o600)
    writer = uncached.UncachedWriter(os.fdopen(fd, "wb", buffering=0))
    writer.write(b"x" * BLOCK)
    with pytest.raises(OSError):
        writer.write(b"x" * BLOCK)      # the first block's error, at the next hand-over
    for later in (lambda: writer.write(b"x"), writer.flush):
        with pytest.raises(OSError, match="an earlier block was not written"):
            later()
    writer.abort()
    assert writer.closed


def test_a_buffer_that_cannot_be_mapped_is_out_of_memory_not_a_failed_write(monkeypatch):
    def refused(*args, **kwargs):
        raise OSError(errno.ENOMEM, os.strerror(errno.ENOMEM))

    monkeypatch.setattr(uncached.mmap, "mmap", refused)
    with pytest.raises(MemoryError):
        uncached._take_buffer()
