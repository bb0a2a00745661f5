"""TOML input files (school scenes, batch manifests): parse with ``FILE:LINE`` errors, locate keys.

tomllib keeps no line numbers, so :class:`Where` finds a key's line in the text for messages.
Leaf module: no numpy, so `fishgen batch` can read its manifest on the fast no-change path.
"""
from __future__ import annotations

import os
import re
import sys
from typing import Any

from fishgen.errors import FishgenError, describe


def text_of(data: bytes, file: str) -> str:
    """A TOML file's text: UTF-8, as TOML must be (a BOM dropped). Bytes that are not were read as
    U+FFFD and came back as a job's input named 'bonybream\ufffd.txt', missing."""
    try:
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as err:
        line = data.count(b"\n", 0, err.start) + 1
        raise FishgenError(f"expected UTF-8 text (TOML), found the byte {data[err.start]:#04x}", file,
                           line) from None


def loads(text: str, file: str) -> dict[str, Any]:
    """Parse TOML text; a syntax error is the one-line ``FILE:LINE: expected TOML, found ...``."""
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # Python 3.10: the same parser as a package
        import tomli as tomllib

    try:
        return tomllib.loads(text)
    except ValueError as err:
        if not isinstance(err, tomllib.TOMLDecodeError):  # Python's limit on an integer's digits
            limit = getattr(sys, "get_int_max_str_digits", lambda: 4300)() or 4300
            run = re.search(f"[0-9_]{{{limit},}}", text)
            line = text.count("\n", 0, run.start()) + 1 if run else None
            raise FishgenError("expected a number of at most a few hundred digits, found one of "
                               f"{len(run[0]) if run else 'thousands of'} digits", file, line) from None
        match = re.search(r"\(at line (\d+), column \d+\)", str(err))
        message = re.sub(r"\s*\(at line \d+, column \d+\)", "", str(err)) or "valid TOML"
        line = int(match[1]) if match else None
        if message.startswith("Cannot overwrite a value"):   # tomllib's words for a key given twice
            raise FishgenError("expected each key once in its table, found one given again", file,
                               line) from None
        raise FishgenError(f"expected TOML, found {message[0].lower() + message[1:]}", file, line) from None


class Where:
    """Line numbers of keys in the TOML text, for messages (tomllib keeps none)."""

    def __init__(self, text: str, file: str):
        self.text = text
        self.file = file
        self._index: tuple[dict, dict] | None = None

    def _indexed(self) -> tuple[dict, dict]:
        """One pass over the text: each table header's line, each key's first line per table
        (a manifest of many jobs asks once per job, so a scan per question would be quadratic)."""
        if self._index is None:
            headers: dict[tuple[str, int], int] = {}
            keys: dict[tuple[str | None, int, str], int] = {}
            counts: dict[str, int] = {}
            section: str | None = None
            for number, raw in enumerate(self.text.splitlines(), 1):
                stripped = raw.strip()
                header = re.match(r"^\[\[?\s*([A-Za-z_.-]+)\s*\]\]?", stripped)
                if header:
                    section = header[1]
                    counts[section] = counts.get(section, -1) + 1
                    headers.setdefault((section, counts[section]), number)
                    continue
                key = re.match(r"^([^=]*?)\s*=", stripped)
                if key:
                    nth = 0 if section is None else counts[section]
                    keys.setdefault((section, nth, key[1]), number)
            self._index = headers, keys
        return self._index

    def line(self, key: str, table: str | None = None, nth: int = 0) -> int | None:
        """The line of ``key`` at the top level, or in the ``nth`` ``[table]``/``[[table]]``;
        without such a key, the table's header line."""
        headers, keys = self._indexed()
        found = keys.get((table, 0 if table is None else nth, key))
        if found is not None:
            return found
        return None if table is None else headers.get((table, nth))

    def fail(self, what: str, found: Any, key: str, table: str | None = None, nth: int = 0) -> FishgenError:
        plain = isinstance(found, str) and found.startswith(("a ", "an ", "no "))
        shown = found if plain else describe(_as_toml(found))
        return FishgenError(f"expected {what}, found {shown}", self.file, self.line(key, table, nth))


def _as_toml(value: Any) -> str:
    """A value as TOML writes it (``true``, not Python's ``True``), for a message."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def _top_keys(path: str | os.PathLike) -> set[str]:
    """The top-level keys of a small TOML file; none when it is unreadable, too big or not TOML."""
    try:
        with open(path, "rb") as handle:
            data = handle.read(_SNIFF_BYTES + 1)
        if len(data) > _SNIFF_BYTES:
            return set()
        return set(loads(data.decode("utf-8", errors="replace").removeprefix("\ufeff"), os.fspath(path)))
    except (OSError, FishgenError):
        return set()


_SNIFF_BYTES = 16 << 20


def is_school_scene(path: str | os.PathLike) -> bool:
    """A school scene file names its species (``[[species]]``)."""
    return "species" in _top_keys(path)


def is_batch_manifest(path: str | os.PathLike) -> bool:
    """A batch manifest lists jobs (``[[build]]``, ``[[school]]``, ``[[clouds]]``) or its ``out``."""
    keys = _top_keys(path)
    return "species" not in keys and bool(keys & {"build", "school", "clouds", "out"})
