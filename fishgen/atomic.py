"""Atomic output: write to a temporary file beside the target, then rename.

A failed or interrupted run never leaves a partial file and never clobbers a
good one. Multi-file outputs (OBJ + MTL + textures, glTF + bin + images) are
staged together and renamed only once every part was written; if a rename
fails part-way, the targets already replaced get their old contents back.

A command with several outputs (a school's glb, tracks, metrics and plot) writes them inside
:func:`together`: every writer then stages, and the whole set is renamed at the end, or none of it.
Inside :func:`protecting`, no file may be written over one of the command's inputs.

A signal's exception (SIGTERM in a batch worker, Ctrl-C) may come between any two instructions.
So a temporary file's name is noted before the file is created, and every cleanup knows it; and
the renames that land a set of files run to their end first (:mod:`fishgen.interrupts`).
"""
from __future__ import annotations

import errno
import logging
import os
import re
import stat
import time
from collections.abc import Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from types import TracebackType
from typing import BinaryIO, Literal, TypeVar, cast

from fishgen import interrupts
from fishgen.errors import FishgenError, SystemFailure, UsageError, cannot
from fishgen.file_names import NAME_MAX
from fishgen.uncached import UncachedWriter

#: A path type: any one of them per call (a Mapping's key type cannot widen).
_PathT = TypeVar("_PathT", bound="str | os.PathLike[str]")
_log = logging.getLogger("fishgen")  # `--verbose` shows each file written; silent otherwise
_staging: ContextVar[list[tuple[str, Path]] | None] = ContextVar("fishgen_staging", default=None)
#: the targets staged in the innermost :func:`together`, resolved
_taken: ContextVar[set[Path] | None] = ContextVar("fishgen_taken", default=None)
_inputs: ContextVar[dict[tuple[int, int], str] | None] = ContextVar("fishgen_inputs", default=None)


@contextmanager
def together() -> Iterator[list[tuple[str, Path]]]:
    """Every file written inside is staged and renamed into place when the block ends without an
    exception; otherwise none is. Inside another such block, the staged files join the outer one's
    (the CLI prints a school's summary before anything lands, so a failed print leaves no file).
    Yields the (temporary file, target) pairs staged so far, to be read inside the block."""
    staged: list[tuple[str, Path]] = []
    outer, outer_taken = _staging.get(), _taken.get()
    try:  # set inside, and reset in both clauses: an interrupt just before one of them would
        # leave every later write staged here
        _staging.set(staged)
        _taken.set(set())
        try:
            yield staged
        finally:
            _staging.set(outer)
            _taken.set(outer_taken)
        _land(staged)
    except BaseException:
        _staging.set(outer)
        _taken.set(outer_taken)
        for tmp, _ in reversed(staged):  # the last first: a folder made for the first is then empty
            _discard(tmp)
        raise


def where_now(path: str | os.PathLike) -> Path:
    """Where ``path``'s bytes are now: inside a :func:`together` block, its staged temporary file
    (the target is not there yet); else ``path`` itself."""
    target = os.path.abspath(path)
    for tmp, staged in _staging.get() or ():
        if os.path.abspath(staged) == target:
            return Path(tmp)
    return Path(path)


@contextmanager
def protecting(paths: Iterable[str | os.PathLike]) -> Iterator[None]:
    """No file written inside may be one of ``paths`` (the command's inputs), whatever its name."""
    ids = dict(_inputs.get() or {})
    for path in paths:
        try:
            info = os.stat(path)
        except OSError:
            continue
        ids[(info.st_dev, info.st_ino)] = os.fspath(path)
    outer = _inputs.get()
    try:
        _inputs.set(ids)
        yield
    finally:
        _inputs.set(outer)


def _umask() -> int:
    """This process's umask: read from /proc where Linux says it, else set and restored at once."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _mode_for(path: str | os.PathLike) -> int:
    """The permissions a written file gets: a replaced file keeps its own (a 0600 file stays
    private), a new one what the umask allows of 0666, as ``open`` would have given it."""
    try:
        return stat.S_IMODE(os.stat(path).st_mode)
    except OSError:
        return 0o666 & ~_umask()


def check_writable(target: str | os.PathLike) -> None:
    """Refuse now, as a write would later, a target whose folder the system will not write in: for
    an output written only after long work (a fly-through's report). A folder still to be made is
    left to the write."""
    import tempfile

    folder = Path(target).parent
    if not folder.is_dir():
        if _in_the_way((folder, *folder.parents)) is not None:
            raise write_failure(Path(target), FileExistsError(errno.EEXIST, "File exists"))
        return
    try:
        fd, probe = tempfile.mkstemp(prefix=".fishgen-probe-", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as err:
        raise cannot("write", target, err) from None


def protect(path: str | os.PathLike) -> None:
    """Protect ``path`` too inside the :func:`protecting` under way, if any: a file an input names
    (a glTF's image, an OBJ's material), found only as the input is read."""
    ids = _inputs.get()
    if ids is None:
        return
    try:
        info = os.stat(path)
    except OSError:
        return
    ids[(info.st_dev, info.st_ino)] = os.fspath(path)


def _land(staged: list[tuple[str, Path]]) -> None:
    """Rename staged files into place now, or leave them to the enclosing :func:`together`."""
    pending = _staging.get()
    if pending is None:
        _commit(staged)
        return
    # the targets staged so far, resolved once each: resolving all of them at every write made a
    # set of 30,000 files (species --count 10000) quadratic, half an hour of resolve() calls
    taken = _taken.get()
    if taken is None:
        taken = {target.resolve() for _, target in pending}
    mine = [target.resolve() for _, target in staged]
    if len(set(mine)) < len(mine) or not taken.isdisjoint(mine):  # a later one would replace the earlier
        target = next(t for t, r in zip((t for _, t in staged), mine, strict=True)
                      if r in taken or mine.count(r) > 1)
        for tmp, _ in reversed(staged):
            _discard(tmp)
        raise UsageError(f"expected every output of one run to be a different file, found {target} "
                         f"twice")
    taken.update(mine)
    pending.extend(staged)


def _in_the_way(folders: Sequence[Path]) -> Path | None:
    """The first of ``folders`` that cannot be one: a file, or a broken (or looping) link."""
    return next((f for f in folders if f.is_file() or (f.is_symlink() and not f.exists())), None)


def write_failure(target: Path, err: OSError, folder: bool = False) -> SystemFailure:
    """An OS error about a temp file or rename, reported against the user's target (a full disk's
    error names no file, so the target is always named here). ``folder``: the target is to be a
    folder (a batch's out folder), so a file there is in the way too."""
    if target.is_dir() and not folder:
        return SystemFailure(f"cannot write {target}: a folder is in the way", target)
    blocker = _in_the_way(((target,) if folder else ()) + tuple(target.parents))
    if blocker is not None:  # mkdir's error says only "File exists"
        found = "a file" if blocker.is_file() else "a broken symbolic link"
        return SystemFailure(f"cannot write {target}: expected a folder at {blocker}, found {found}", target)
    return cannot("write", target, err)


def check_target(target: Path) -> None:
    """Only a missing file or a regular file may be replaced: renaming over a FIFO or a device
    node (``-o /dev/null`` run as root) would replace the special file itself."""
    if target.is_dir():
        # named as its FILE: without one, a command blamed its input (`photo.png: …, found a folder at d.png`)
        raise FishgenError("expected an output file, found a folder", target)
    try:
        info = target.stat()
    except OSError:
        return  # nothing there (or a dangling link): the rename creates the file
    if not stat.S_ISREG(info.st_mode):
        raise FishgenError("expected a regular file or no file as the output, found a device, pipe or "
                           "other special file", target)
    same = (_inputs.get() or {}).get((info.st_dev, info.st_ino))
    if same is not None:
        raise UsageError(f"expected an output that is not one of the command's inputs, found "
                         f"{os.fspath(target)!r}, which is the input {same!r}")


STALE_SECONDS = 10.0
"""A temporary file of fishgen's naming pattern that nobody holds locked and that is this old was
left by a killed run (SIGKILL runs no cleanup): the next write beside it removes it."""
_held: dict[str, int] = {}  # temporary file -> the descriptor holding its lock until renamed or discarded
_folders: dict[str, list[Path]] = {}  # temporary file -> the folders made for it, deepest first
_live: dict[str, None] = {}  # every temporary file named and not yet renamed or discarded, in order


@interrupts.at_stop
def discard_all() -> None:
    """Discard every temporary file not yet renamed into place, the newest first: the process stops
    on a signal, which may have come as a writer's cleanup began, before it could run."""
    for tmp in reversed(list(_live)):
        _discard(tmp)


_CREATE = (os.O_RDWR | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
           | getattr(os, "O_BINARY", 0))


_TAIL = 16  # XXXXXXXXXXXX.tmp


def _prefix(path: Path) -> str:
    """How the temporary files of ``path`` begin: ``.NAME.``, or for a name too long to take the
    tail, ``.NAM~HASH.``: the name cut to fit and 8 hex digits of the whole name's SHA-1, so that
    any name a file system takes can be written."""
    prefix = f".{path.name}."
    raw = os.fsencode(prefix)
    if len(raw) + _TAIL <= NAME_MAX:
        return prefix
    import hashlib

    digest = hashlib.sha1(os.fsencode(path.name)).hexdigest()[:8]
    cut = raw[1:NAME_MAX - _TAIL - len(digest) - 3].decode("utf-8", "ignore")  # no half a character
    return f".{cut}~{digest}."


def _beside(path: Path, suffix: str) -> str:
    """A fresh name for a temporary file beside ``path``: ``.NAME.XXXXXXXXXXXX.tmp``."""
    return os.path.join(path.parent, f"{_prefix(path)}{os.urandom(6).hex()}{suffix}")


def _temporary(path: Path, into: list[tuple[str, Path]]) -> tuple[int, str]:
    """A new temporary file beside ``path``, locked for as long as this run may rename it; stale
    ones of the same target are swept first. Its name goes on ``into`` before the file (or a
    folder made for it) exists, so that whoever cleans up after an interrupt knows it."""
    made: list[Path] = []
    folder = path.parent
    while not folder.exists() and folder != folder.parent:
        made.append(folder)
        folder = folder.parent
    for _ in range(100):
        tmp = _beside(path, ".tmp")
        _live[tmp] = None
        if made:  # a run that fails leaves no folder it made either
            _folders[tmp] = made
        into.append((tmp, path))
        path.parent.mkdir(parents=True, exist_ok=True)
        sweep(path, listed=True)
        try:
            fd = os.open(tmp, _CREATE, 0o600)
        except FileExistsError:  # 48 random bits: another writer's name, once in a lifetime
            into.pop()
            _folders.pop(tmp, None)
            _live.pop(tmp, None)
            continue
        if len(_held) < _lock_budget() and _lock(fd):
            _held[tmp] = fd
        return fd, tmp
    raise FileExistsError(f"no free temporary name beside {path}")


def _lock_budget() -> int:
    """How many temporary files may hold a descriptor for their lock at once: a quarter of the
    process's open-file limit. A set staged beyond it (10,000 species are 30,000 files) keeps the
    rest unlocked, as on Windows: a sweep by this run skips them (:data:`_live`), and only another
    run writing the same target name could take one older than STALE_SECONDS, failing this set
    whole at its rename rather than this run failing for want of descriptors."""
    global _budget
    if _budget is None:
        try:
            import resource

            soft = resource.getrlimit(resource.RLIMIT_NOFILE)[0]
        except (ImportError, OSError, ValueError):
            soft = 1024
        _budget = max(16, min(soft, 1 << 20) // 4)
    return _budget


_budget: int | None = None


def _remove_empty(folders: list[Path]) -> None:
    for folder in folders:
        try:
            folder.rmdir()
        except FileNotFoundError:  # never made: an interrupt came inside mkdir
            continue
        except OSError:  # not empty: another output, or a file someone else put there
            return


def _lock(fd: int) -> bool:
    """Take an exclusive lock on an open file, without waiting (False: another process holds it)."""
    try:
        import fcntl
    except ImportError:  # Windows: no advisory locks, and no sweeping either
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return False
    return True


def sweep(path: Path, *, listed: bool = False) -> list[Path]:
    """Remove ``path``'s stale temporary files: ours by their name (``.NAME.XXXXXXXXXXXX.tmp``),
    older than STALE_SECONDS, and not locked, so no running writer holds them. Returns what was
    removed. ``listed``: from the folder's listing of the last STALE_SECONDS (:func:`_stale_names`),
    as every write does, rather than listing it again."""
    removed: list[Path] = []
    folder = os.fspath(path.parent)
    names = _stale_names(folder, fresh=not listed).get(_prefix(path), [])
    now = time.time()
    for name in list(names):
        full = os.path.join(folder, name)
        if full in _live:
            continue
        try:
            info = os.lstat(full)
            if not stat.S_ISREG(info.st_mode) or now - info.st_mtime < STALE_SECONDS:
                continue
            fd = os.open(full, os.O_RDONLY | os.O_NONBLOCK)
        except OSError:
            continue
        try:
            if _lock(fd):
                os.unlink(full)
                names.remove(name)
                removed.append(Path(full))
        except OSError:
            pass
        finally:
            os.close(fd)
    return removed


_HEX = re.compile(r"[0-9a-f]{12}")
_listings: dict[str, tuple[float, dict[str, list[str]]]] = {}
"""Per folder: when this process last listed it, and the temporary files of our pattern there by
their target's prefix."""


def _stale_names(folder: str, fresh: bool) -> dict[str, list[str]]:
    """The folder's files named as our temporary files are (``PREFIX`` + 12 hex digits + ``.tmp``),
    by prefix. A write lists its folder at most once every STALE_SECONDS: listing it at every write
    made a set of N files in one folder cost N^2 (10,000 species: 30,000 files)."""
    now = time.monotonic()
    known = _listings.get(folder)
    if known is not None and not fresh and now - known[0] < STALE_SECONDS:
        return known[1]
    index: dict[str, list[str]] = {}
    try:
        with os.scandir(folder) as entries:
            for entry in entries:
                name = entry.name
                if len(name) > 18 and name.endswith(".tmp") and _HEX.fullmatch(name, len(name) - 16,
                                                                                  len(name) - 4):
                    index.setdefault(name[:-16], []).append(name)
    except OSError:
        pass
    _listings[folder] = (now, index)
    return index


def _writer(tmp: str, fd: int) -> UncachedWriter:
    """A handle that writes ``tmp``. Where ``fd`` holds its lock, the lock stays with ``fd`` until
    the rename; where there are no locks (Windows) the handle takes ``fd``, since a file still open
    there cannot be renamed. Big files go past the page cache (:mod:`fishgen.uncached`)."""
    return UncachedWriter(os.fdopen(os.dup(fd) if tmp in _held else fd, "wb", buffering=0))


def _finish(handle: UncachedWriter, tmp: str, path: Path) -> None:
    """Make ``tmp`` durable and close it, with the permissions ``path`` is to have."""
    handle.flush()
    os.fsync(handle.fileno())
    handle.close()
    os.chmod(tmp, _mode_for(path))


def _drop(handle: UncachedWriter | None, tmp: str) -> None:
    """Abandon ``tmp``: nothing more written, its file closed at once (a full disk gets its space
    back), then removed."""
    if handle is not None:
        handle.abort()
    _discard(tmp)


def _release(tmp: str) -> None:
    _live.pop(tmp, None)
    _folders.pop(tmp, None)
    fd = _held.pop(tmp, None)
    if fd is not None:
        os.close(fd)


def _stage(path: Path, data: bytes, into: list[tuple[str, Path]]) -> None:
    """Write ``data`` to a new temporary file for ``path``, named on ``into`` (the caller discards
    what is there if this raises)."""
    check_target(path)
    try:
        fd, tmp = _temporary(path, into)
    except OSError as err:
        raise write_failure(path, err) from None
    handle = None
    try:
        handle = _writer(tmp, fd)
        handle.write(data)
        _finish(handle, tmp, path)
    except BaseException as err:
        _drop(handle, tmp)
        if isinstance(err, OSError):
            raise write_failure(path, err) from None
        raise


def _discard(tmp: str) -> None:
    try:
        os.unlink(tmp)
    except OSError:  # never made (its folder could not be), or already renamed into place
        pass
    made = _folders.get(tmp, [])
    _release(tmp)
    _remove_empty(made)


def write_files(files: Mapping[_PathT, bytes]) -> None:
    """Write every ``path -> bytes`` entry atomically: all of them, or none."""
    targets = [Path(p) for p in files]
    for target in targets:
        check_target(target)
    staged: list[tuple[str, Path]] = []
    try:
        for target, data in zip(targets, files.values(), strict=True):
            _stage(target, data, staged)
        _land(staged)
    except BaseException:  # files already renamed into place have no temporary file left to remove
        for tmp, _ in reversed(staged):
            _discard(tmp)
        raise


def _commit(staged: list[tuple[str, Path]]) -> None:
    """Rename every staged file over its target, undoing earlier renames if one fails. An interrupt
    waits for the end, so that a set of outputs is never left half old and half new."""
    with interrupts.held():
        undo: list[tuple[str, str | None, Path]] = []  # (temporary file, old target's backup, target)
        made = [_folders.get(tmp, []) for tmp, _ in staged]  # a rename forgets them; a rollback needs them
        try:
            for tmp, target in staged:
                backup = _beside(target, ".old") if len(staged) > 1 and target.is_file() else None
                undo.append((tmp, backup, target))
                if backup is not None:
                    _keep(target, backup)
                try:
                    os.replace(tmp, target)
                except OSError as err:
                    raise write_failure(target, err) from None
                _release(tmp)
        except BaseException as err:
            stranded: list[tuple[str, Path]] = []
            for tmp, backup, target in reversed(undo):
                try:  # every step tried: one that fails must not leave the others undone
                    if backup is not None:
                        if os.path.lexists(backup):
                            _put_back(backup, target)
                    elif len(staged) > 1 and not os.path.lexists(tmp) and target.is_file():
                        os.unlink(target)  # new in this set, and the set does not land
                except OSError:
                    if backup is not None:
                        stranded.append((backup, target))
            for tmp, _ in reversed(staged):
                _discard(tmp)
            for folders in reversed(made):
                _remove_empty(folders)
            if stranded:  # never discarded: the only copy of what the user had
                backup, target = stranded[0]
                raise SystemFailure(f"cannot write {target}, nor put its earlier content back: it is in "
                                    f"{backup}", target) from err
            raise
        for _, backup, _ in undo:
            if backup is not None:
                _discard(backup)
    for _, target in staged:
        _log.info("wrote %s", target)


def _keep(target: Path, backup: str) -> None:
    """Keep ``target`` at ``backup`` for a rollback: a second link to it, so that ``target`` is
    never missing while its set lands (renamed aside, it was gone for a reader between two renames);
    renamed aside where the file system has no hard links."""
    try:
        os.link(target, backup, follow_symlinks=False)    # a symlink kept as the link it is
    except (OSError, NotImplementedError):
        os.replace(target, backup)


def _put_back(backup: str, target: Path) -> None:
    """``target`` as ``_keep`` kept it. Where its new file never landed, the backup is a second link
    to ``target`` itself, and a rename of one link over another of the same file does nothing
    (POSIX): the backup is only removed."""
    try:
        kept, now = os.lstat(backup), os.lstat(target)
        same = (kept.st_dev, kept.st_ino) == (now.st_dev, now.st_ino)
    except FileNotFoundError:
        same = False
    if same:
        os.unlink(backup)
    else:
        os.replace(backup, target)


def write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write one file atomically."""
    write_files({path: data})


class atomic_open:
    """Context manager yielding a binary file handle for streaming writes.

    The data goes to a temporary file beside ``path``; it replaces ``path`` only
    when the ``with`` block finishes without an exception.
    """

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)
        self._tmp: str | None = None
        self._handle: UncachedWriter | None = None

    def __enter__(self) -> BinaryIO:
        check_target(self.path)
        named: list[tuple[str, Path]] = []
        try:
            fd, self._tmp = _temporary(self.path, named)
            self._handle = _writer(self._tmp, fd)
        except BaseException as err:  # also SIGTERM or Ctrl-C before the `with` body: no temp file left
            for tmp, _ in named:
                _discard(tmp)
            if isinstance(err, OSError):
                raise write_failure(self.path, err) from None
            raise
        return cast(BinaryIO, self._handle)

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> Literal[False]:
        assert self._handle is not None and self._tmp is not None
        try:
            if exc_type is not None:     # the output is dropped: nothing more written, the first error kept
                _drop(self._handle, self._tmp)
            else:
                _finish(self._handle, self._tmp, self.path)
                if _staging.get() is None:
                    os.replace(self._tmp, self.path)
                    _release(self._tmp)
                    _log.info("wrote %s", self.path)
                else:
                    _land([(self._tmp, self.path)])
                return False
        except OSError as err:
            _drop(self._handle, self._tmp)
            raise write_failure(self.path, err) from None
        except BaseException:
            _drop(self._handle, self._tmp)
            raise
        if isinstance(exc, OSError) and exc.filename is None:
            # A write to the handle failed (a full disk, a file size limit): its error names no
            # file, so say which output it was.
            raise write_failure(self.path, exc) from None
        return False
