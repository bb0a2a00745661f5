"""fishgen.memory: how a limit and a need are said."""
from __future__ import annotations

from fishgen.memory import over


def test_a_need_just_over_the_limit_reads_as_more_than_it():
    """Rounded alike, "fits in 1.43 GiB ... need about 1.43 GiB" read as nonsense (QA pass 13)."""
    gib = 2**30
    assert over((int(1.4301 * gib), "x"), int(1.4302 * gib)) == ("1.4301 GiB", "1.4302 GiB")
    have, want = over((int(1.43 * gib), "x"), int(1.43 * gib) + 1)
    assert have != want
    assert over((600 * 2**20, "x"), 700 * 2**20) == ("600 MiB", "700 MiB")
    assert over((600 * 2**20, "x"), 500 * 2**20) is None and over(None, 10**12) is None
