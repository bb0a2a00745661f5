"""Pakawan's three sky modes, in numbers. A leaf module (no numpy): the CLI's --help reads it.

Pakawan (RekAwan user manual, chapter 4) had "three mode; thin cloud, medium cloud and thick
cloud", each combining "several cloud models ... to develop a difference size and thickness".
The manual gives no numbers; these are fishgen's (``docs/decisions.md``, "Sky modes"):

========  ======  ==========  ===========  ====================================================
mode      clouds  scale       particles    what it looks like
========  ======  ==========  ===========  ====================================================
thin      16      0.8 - 1.6   20,000       a few small fair-weather clouds, sky between them
medium    48      1.2 - 2.4   150,000      scattered cumulus
thick     120     1.8 - 3.4   1,000,000    a crowded, deep cloud field
========  ======  ==========  ===========  ====================================================

over an area of 400 x 400 units at cloud bases 40 to 80 units up (cube-file units; the shipped
cumulus is about 13 wide and 7 tall at scale 1). A cloud's particle share is proportional to its
volume. Its particles are finer than the source file's as its share grows (the packing stays the
source's), and ``puff`` scales every radius on top, so a thick sky is also optically thicker.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class SkyMode:
    """How many clouds, how big, how many particles in all."""

    name: str
    clouds: int                               # clouds in the sky
    scale: tuple[float, float]                # each cloud's scale, uniform in this range
    particles: int                            # the whole sky's particles (before the lower LOD)
    puff: float                               # every particle radius times this
    depth: tuple[float, float] = (1.6, 2.6)   # the source's depth (z) stretched by this: rounder clouds
    summary: str = ""


MODES: dict[str, SkyMode] = {m.name: m for m in (
    SkyMode("thin", 16, (0.8, 1.6), 20_000, 0.9, summary="a few small fair-weather clouds"),
    SkyMode("medium", 48, (1.2, 2.4), 150_000, 1.0, summary="scattered cumulus"),
    SkyMode("thick", 120, (1.8, 3.4), 1_000_000, 1.1, summary="a crowded, deep cloud field"),
)}
"""Pakawan's modes 1, 2, 3."""

SHIPPED_CUBES = 23
"""The most cubes with particles in one of the default cloud files (Table 4.4's 23; 4.3 has fewer):
a sky needs a particle in each cube of every cloud, so the least --particles is a mode's clouds times
this (a test checks it against the files)."""

AREA = (400.0, 400.0)
"""Default sky area, width (x) by depth (z), centred on the origin."""
ALTITUDE = (40.0, 80.0)
"""Default range of cloud base heights (y)."""
NOISE = 0.5
"""Default noise amount: radii and densities scaled by 1 +- 0.5 x fBm (mostly within +-25 %)."""
LOD_LEVELS = ((8.0, 0.8), (64.0, 0.2))
"""A cloud's lower levels of detail: (one particle kept in RATIO, shown below COVERAGE), coarser
down the list. COVERAGE is MSFT_screencoverage's: the share of the view's height the cloud's
bounding sphere spans. Chosen where the level differs from full detail by no more than two fills
of the same cloud differ from each other (measured: docs/fly.md, "Levels of detail")."""
LOD_MIN_PARTICLES = 32
"""A level is made only if it keeps at least this many particles (a cloud of 256 has a level 1;
of 2,048, a level 2)."""
