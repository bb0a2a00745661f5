"""How much memory a school run needs, known from its sizes before anything is allocated.

A leaf module (no numpy). The figures are `fishgen school`'s peak address space (VmPeak),
measured on BonyBream with the body wave (docs/decisions.md, "A school's memory, estimated"):
about 360 MiB for the interpreter and its libraries, 13-41 KiB per fish (its nodes, channels
and neighbour lists) and 190 bytes per fish-frame (tracks, keys, the file), and 150-200 bytes more
per fish-frame with ``--tracks`` (the table of rows and its file). The constants are rounded up,
so the estimate is 10-35 % above what was measured.
"""
from __future__ import annotations

import os
import resource

BASE = 400 * 2**20
PER_FISH = 46 * 2**10
PER_FISH_FRAME = 230
PER_TRACK_FRAME = 240  # --tracks: float64 rows, float32 columns and the compressed or CSV file


def estimate(fish: int, frames: int, tracks: bool = False) -> int:
    """Bytes of address space a run of ``fish`` x ``frames`` is expected to peak at; ``tracks``
    when the raw tracks are written too (``--tracks``)."""
    return BASE + PER_FISH * fish + (PER_FISH_FRAME + PER_TRACK_FRAME * tracks) * fish * frames


def allowed() -> tuple[int, str] | None:
    """The memory this process may use and what sets it: the address-space limit if one is set,
    else the machine's available memory; None if neither is known."""
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY:
        return soft, "this process's address-space limit"
    try:
        with open("/proc/meminfo", encoding="ascii") as info:
            for line in info:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024, "the memory this machine has available"
    except OSError:
        pass
    pages = os.sysconf("SC_AVPHYS_PAGES") if hasattr(os, "sysconf") else -1
    if pages <= 0:
        return None
    return pages * os.sysconf("SC_PAGE_SIZE"), "the memory this machine has available"


def size_text(n: int) -> str:
    return f"{n / 2**30:.1f} GiB" if n >= 2**30 else f"{n / 2**20:.0f} MiB"
