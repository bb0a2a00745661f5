"""Big outputs go past the page cache in whole blocks; the bytes are the same whatever happens."""
import errno
import os

import numpy as np
import pytest

import fishgen.uncached as uncached
from fishgen.atomic import atomic_open, write_bytes

BLOCK = 4 * 4096


@pytest.fixture
def small_blocks(monkeypatch):
    """Blocks of 16 KiB, so a test file of a few blocks takes the big-file path."""
    monkeypatch.setattr(uncached, "BLOCK", BLOCK)


@pytest.fixture
def writes(monkeypatch):
    """Every os.write: (bytes, whether the descriptor had O_DIRECT on)."""
    import fcntl

    seen: list[tuple[int, bool]] = []
    write = os.write

    def spy(fd, data):
        direct = bool(uncached._O_DIRECT and fcntl.fcntl(fd, fcntl.F_GETFL) & uncached._O_DIRECT)
        seen.append((len(data), direct))
        return write(fd, data)

    monkeypatch.setattr(os, "write", spy)
    return seen


def pieces(total: int, seed: int = 0) -> list[bytes]:
    """``total`` random bytes in pieces of odd sizes, as the PLY header and record chunks come."""
    rng = np.random.default_rng(seed)
    data = rng.integers(0, 256, total, dtype=np.uint8).tobytes()
    cuts = np.sort(rng.choice(np.arange(1, total), 9, replace=False))
    return [data[a:b] for a, b in zip([0, *cuts], [*cuts, total], strict=True)]


needs_direct = pytest.mark.skipif(not uncached._O_DIRECT, reason="no O_DIRECT on this system")


@needs_direct
def test_whole_blocks_go_past_the_cache_and_the_tail_through_it(tmp_path, small_blocks, writes):
    parts = pieces(3 * BLOCK + 1234)
    with atomic_open(tmp_path / "cloud.ply") as handle:
        for part in parts:
            handle.write(part)
    assert (tmp_path / "cloud.ply").read_bytes() == b"".join(parts)
    assert writes == [(BLOCK, True)] * 3, "every full block written with O_DIRECT, in one write"
    assert [p for p in os.listdir(tmp_path) if p != "cloud.ply"] == []


def test_a_small_file_is_one_ordinary_write(tmp_path, small_blocks, writes):
    write_bytes(tmp_path / "fish.glb", b"x" * (BLOCK - 1))
    assert (tmp_path / "fish.glb").read_bytes() == b"x" * (BLOCK - 1)
    assert not any(direct for _, direct in writes)


@pytest.mark.parametrize("refusal", ["no fcntl", "EINVAL", "short write"])
def test_where_direct_writes_are_refused_the_same_bytes_land(tmp_path, small_blocks, monkeypatch, refusal):
    """Another system, a file system without O_DIRECT, a device with bigger blocks, a nearly full disk."""
    parts = pieces(5 * BLOCK + 77, seed=1)
    write = os.write
    if refusal == "no fcntl":
        monkeypatch.setattr(uncached, "_set_direct", lambda fd, on: False)
    else:
        def refusing(fd, data):
            if len(data) == BLOCK:
                if refusal == "EINVAL":
                    raise OSError(errno.EINVAL, os.strerror(errno.EINVAL))
                return write(fd, bytes(data[:4096]))
            return write(fd, data)
        monkeypatch.setattr(os, "write", refusing)
    write_bytes(tmp_path / "cloud.ply", b"".join(parts))
    assert (tmp_path / "cloud.ply").read_bytes() == b"".join(parts)


def test_a_full_disk_is_said_and_nothing_is_left(tmp_path, small_blocks, monkeypatch):
    from fishgen.errors import SystemFailure

    target = tmp_path / "cloud.ply"
    target.write_bytes(b"earlier")

    def full(fd, data):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "write", full)
    with pytest.raises(SystemFailure, match="No space left on device"):
        write_bytes(target, b"y" * (2 * BLOCK))
    assert target.read_bytes() == b"earlier" and os.listdir(tmp_path) == ["cloud.ply"]
