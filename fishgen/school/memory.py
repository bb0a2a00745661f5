"""How much memory a school run needs, known from its sizes before anything is allocated.

A leaf module (no numpy). The figures are `fishgen school`'s peak address space (VmPeak),
measured on BonyBream with the body wave (docs/decisions.md, "A school's memory, estimated"):
about 360 MiB for the interpreter and its libraries, 13-41 KiB per fish (its nodes, channels
and neighbour lists) and 190 bytes per fish-frame (tracks, keys, the file), and 150-200 bytes more
per fish-frame with ``--tracks`` (the table of rows and its file). The constants are rounded up,
so the estimate is 10-35 % above what was measured.
"""
from __future__ import annotations

from fishgen.memory import allowed, size_text

__all__ = ["BASE", "PER_FISH", "PER_FISH_FRAME", "PER_TRACK_FRAME", "allowed", "estimate", "size_text"]

BASE = 400 * 2**20
PER_FISH = 46 * 2**10
PER_FISH_FRAME = 230
PER_TRACK_FRAME = 240  # --tracks: float64 rows, float32 columns and the compressed or CSV file


def estimate(fish: int, frames: int, tracks: bool = False) -> int:
    """Bytes of address space a run of ``fish`` x ``frames`` is expected to peak at; ``tracks``
    when the raw tracks are written too (``--tracks``)."""
    return BASE + PER_FISH * fish + (PER_FISH_FRAME + PER_TRACK_FRAME * tracks) * fish * frames
