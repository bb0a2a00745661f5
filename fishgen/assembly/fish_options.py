"""How a fish is built: one frozen dataclass of the options, their documented defaults, no numpy.

A leaf module, as :mod:`fishgen.clouds.lighting` is for the sunlight: each field is the option of
`fishgen build` (a :mod:`fishgen.options` declaration: type, range, default, help), which
:class:`fishgen.commands.build.BuildOptions` takes as its own, and ``__post_init__`` checks each
value by that declaration, as click checks the command line. So
:func:`fishgen.assembly.fish.make_fish`, which builds its record from its arguments, refuses what
the command line refuses, with the command line's words.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import click

from fishgen.assembly.clip_names import BENDING_CLIPS, CLIP_NAMES, DEFAULT_CLIPS
from fishgen.errors import FishgenError
from fishgen.fish_modes import DEFAULT_SPEED, MAX_TAIL_BEAT_HZ
from fishgen.options import (
    FiniteRange,
    Names,
    compact_option,
    declared,
    fins_option,
    lods_option,
    long_name,
    merge_option,
    option,
    swim_option,
)


@dataclass(frozen=True)
class FishOptions:
    """The options of a built fish, checked when made (see the module's docstring)."""

    fins: str | None = fins_option("mask if the file says masked, else blend")
    length: float | None = option(FiniteRange(0.001, 1e4), "Nose-to-tail length in metres.",
                                  shown_default="world scale x scaleX x 0.05 m for the body",
                                  metavar="METRES")
    fps: float = option(FiniteRange(1, 1000), "Frames per second of the animation; each fin turns by its "
                        "species file's step size (degrees) a frame.",
                        30.0)
    swim: str = swim_option("body: a travelling body wave (carangiform, tail-beat frequency from --speed) "
                            "under the fin swings; fins: a rigid body, only the fins move (VRFish's fish).")
    # None: not given, so that one given with --swim fins (no body wave to set) can be refused
    speed: float | None = option(FiniteRange(0.01, 100), "Cruising speed of the swim loop in body lengths "
                                 "per second; the tail beats at Strouhal number 0.3 (1.5 Hz per BL/s), "
                                 f"at most {MAX_TAIL_BEAT_HZ:g} Hz (from {MAX_TAIL_BEAT_HZ / 1.5:.2f} BL/s "
                                 "up: the same fish), a whole number of beats in the loop (rounded down "
                                 f"where up would pass {MAX_TAIL_BEAT_HZ:g} Hz). --swim body only.",
                                 shown_default=f"{DEFAULT_SPEED:g}", metavar="BL/S")
    lods: tuple[tuple[int, int], ...] | None = lods_option()
    merge: bool = merge_option()
    clips: tuple[str, ...] = option(Names(CLIP_NAMES), "Clips to write (each loops, except burst): "
                                    f"{', '.join(CLIP_NAMES)}.", DEFAULT_CLIPS, metavar="NAME,...")
    compact: bool = compact_option()

    def __post_init__(self) -> None:
        for f, spec in declared(FishOptions):  # a subclass's own options are its own business
            value = getattr(self, f.name)
            if value is None and spec.default is None:   # None: the species file's, or the computed default
                continue
            object.__setattr__(self, f.name, _checked(spec.type, spec.flag, value, long_name(f)))
        bending = [c for c in self.clips if c in BENDING_CLIPS]
        if bending and self.swim != "body":
            raise FishgenError(f"expected --swim body for the clips {', '.join(bending)} (a rigid body "
                               f"cannot bend), found --swim {self.swim}")


def _checked(kind: click.ParamType, flag: bool, value: Any, name: str) -> Any:
    """``value`` converted by its option's type as click converts the command line's text; its
    refusal in click's words (``Invalid value for '--lods': expected ...``)."""
    try:
        if flag:
            if not isinstance(value, bool):
                raise click.BadParameter(f"expected true or false, found {value!r}")
            return value
        return kind.convert(value, None, None)
    except click.BadParameter as err:
        raise FishgenError(f"Invalid value for '--{name}': {err.message}") from None
