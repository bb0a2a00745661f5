"""How much memory this process may use, to refuse a run that would not fit before allocating.

A leaf module (no numpy): `fishgen school` (:mod:`fishgen.school.memory`), the cloud commands
(:mod:`fishgen.clouds.memory`) and `fishgen preview` (:mod:`fishgen.preview.memory`) estimate their
peaks from their sizes and compare them with this.
"""
from __future__ import annotations

import os
import resource

ADDRESS_SPACE = "this process's address-space limit"


def allowed() -> tuple[int, str] | None:
    """The memory this process may use and what sets it: the address-space limit if one is set,
    else the machine's available memory; None if neither is known."""
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY:
        return soft, ADDRESS_SPACE
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


def over(limit: tuple[int, str] | None, need: int) -> tuple[str, str] | None:
    """(what may be used, what ``need`` is) as a message says them, when ``need`` bytes are more than
    ``limit`` (:func:`allowed`'s) allows; else None. Near the line, with places enough to differ."""
    if limit is None or need <= limit[0]:
        return None
    have, want = size_text(limit[0]), size_text(need)
    places = 2
    while have == want and places <= 9:     # "fits in 1.43 GiB ... need about 1.43 GiB" read as nonsense
        have, want = f"{limit[0] / 2**30:.{places}f} GiB", f"{need / 2**30:.{places}f} GiB"
        places += 1
    if have == want:
        have, want = f"{limit[0]:,} bytes", f"{need:,} bytes"
    return have, want


def size_text(n: int) -> str:
    return f"{n / 2**30:.1f} GiB" if n >= 2**30 else f"{n / 2**20:.0f} MiB"
