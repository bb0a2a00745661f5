"""How much memory `fishgen clouds` needs, known from its particle count before anything is filled.

A leaf module (no numpy). The figures are the whole command's peak address space (VmPeak),
measured on Table 4.4 scaled to 10^6 and 3 x 10^6 particles, lit (docs/decisions.md, "Fourth QA
pass"): about 320-370 MiB for the interpreter and its libraries, then per particle 43 bytes as
points (.ply, .csv, .npy, .glb; 84 in a .gltf, whose buffer is also encoded), 748 as billboards in
a .glb and 918 in a .gltf (each particle three textured quads). `fishgen sky` (its thick mode, 10^6
and 3 x 10^6 particles) peaked at 750 MiB, 113 bytes a point with its levels of detail, and about
540 a billboard. Rounded up, as the school's are.
"""
from __future__ import annotations

from fishgen.memory import allowed, over

BASE = 400 * 2**20
SKY_BASE = 800 * 2**20
PER_PARTICLE = {  # (sky, billboards, .gltf): bytes
    (False, False, False): 56, (False, False, True): 110, (False, True, False): 900,
    (False, True, True): 1_100, (True, False, False): 140, (True, False, True): 200,
    (True, True, False): 700, (True, True, True): 900}


def estimate(particles: int, suffix: str, billboards: bool = False, sky: bool = False) -> int:
    """Bytes of address space writing ``particles`` to a ``suffix`` file is expected to peak at
    (``sky``: as `fishgen sky`, its levels of detail included)."""
    each = PER_PARTICLE[sky, billboards, suffix.lower() == ".gltf"]
    return (SKY_BASE if sky else BASE) + each * particles


def check_fits(particles: int, suffix: str, billboards: bool = False, sky: bool = False) -> None:
    """Refuse, before anything is filled, a cloud whose estimated peak is more than this process
    may use (a usage error: the output's kind and the counts are the command line's)."""
    from fishgen.errors import UsageError

    limit = allowed()
    texts = over(limit, estimate(particles, suffix, billboards, sky))
    if limit is not None and texts is not None:
        noun = "billboards" if billboards else "particles"
        have, want = texts
        raise UsageError(f"expected a {'sky' if sky else 'cloud'} that fits in {have} ({limit[1]}), found "
                         f"{particles:,} {noun} for {suffix}, which need about {want}: use fewer "
                         f"particles{' or points' if billboards else ''}")
