"""The sunlight a cloud is lit with: one frozen dataclass, its documented defaults, no numpy.

A leaf module: its fields are the ``--sun`` ... options of every command that lights clouds
(:mod:`fishgen.options` declarations: type, range, default, help), read without importing numpy
or the lighting code. The light itself is computed by :mod:`fishgen.clouds.light`.

The model is Harris's (Harris and Lastra 2001; Harris 2002), as the RekAwan report
rendered its clouds (section 5.3), with the constants of Harris's own
implementation, SkyWorks' ``SkyCloud.cpp``: albedo 0.9, extinction 80, forward
scattering sampled over a 0.09 sr solid angle, and the Rayleigh phase function.
``docs/decisions.md`` ("Sunlight, baked") says how each one is used.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

import click

from fishgen.errors import FishgenError
from fishgen.options import FiniteRange, check_value, declared, option
from fishgen.options import Triple as TripleType

Triple = tuple[float, float, float]
Direction = TripleType(nonzero=True)
Colour3 = TripleType(0.0, 10.0, name="R,G,B")

SUN = (0.35, 1.0, 0.55)
"""Towards the sun: 57 degrees up, in front, to the right: the sun `fishgen preview` lights fish with."""
SUN_COLOR = (0.72, 0.70, 0.66)
SKY_COLOR = (0.36, 0.40, 0.50)
ALBEDO = 0.9           # SkyWorks: SkyCloud::s_rAlbedo
EXTINCTION = 80.0      # SkyWorks: SkyCloud::s_rExtinction (a particle's centre passes e^-80)
SOLID_ANGLE = 0.09     # SkyWorks: rSolidAngle in SkyCloud::Illuminate, steradians
ANISOTROPY = 0.0       # Cornette-Shanks g (report eq. 3.14); 0 is Rayleigh scattering, as SkyWorks uses
DIFFUSE = 2.0 ** -10
"""The share of sunlight that reaches deep into a cloud by scattering many times
(``fishgen.clouds.light.light_of_depth``): a power of two, so full sun stays exactly 1."""


@dataclass(frozen=True)
class Lighting:
    """How the sun and the sky light a cloud. Colours are linear RGB; the sun colour is its
    radiance on a particle in full sun, the sky colour the ambient light every particle gets.

    Each field is also the option of every command that lights clouds (``fishgen clouds``,
    ``preview``, ``sky``, ``fly``, ``edit``: they group this record), checked by its declaration
    whether it comes from the command line, a manifest or Python."""

    sun: Triple = option(Direction, "Direction towards the sun (+Y is up): where the light comes from; "
                         "its length does not matter.", SUN)
    sun_color: Triple = option(Colour3, "Sunlight on a particle in full sun, linear RGB.",
                               SUN_COLOR)
    sky_color: Triple = option(Colour3, "Ambient sky light every particle gets, linear RGB: "
                               "the colour of shadowed undersides.", SKY_COLOR)
    albedo: float = option(FiniteRange(0, 1), "Fraction of the light a particle stops that it scatters "
                           "rather than absorbs.", ALBEDO)
    extinction: float = option(FiniteRange(0, 1000), "Optical depth through the centre of a particle of "
                               "density 1 (SkyWorks' 80: opaque cores). It also sets the light scattered "
                               "forward (SkyWorks' formula, at most the albedo), so a lower value often "
                               "makes a darker cloud, not a thinner one.", EXTINCTION)
    solid_angle: float = option(FiniteRange(0, 4 * math.pi, min_open=True), "Cone over which "
                                "forward-scattered light is gathered, steradians (SkyWorks' 0.09).",
                                SOLID_ANGLE, metavar="STERADIANS")
    anisotropy: float = option(FiniteRange(-0.9, 0.9), "Phase function asymmetry g (report eq. 3.14, "
                               "Cornette-Shanks); 0 is Rayleigh, positive scatters more light forward.",
                               ANISOTROPY, metavar="G")
    scattering: bool = option(click.BOOL, "Multiple forward scattering (Harris); off leaves only the "
                              "sunlight that passes straight through (and the faint diffuse share "
                              "of docs/clouds.md).", True, flag=True,
                              off="--no-scattering")

    def __post_init__(self) -> None:
        for f, spec in declared(Lighting):  # a library caller's values are checked as options are
            value = getattr(self, f.name)
            checked = check_value(spec, list(value) if isinstance(value, tuple) else value,
                                  _fail(f.name.replace("_", " "), value))
            object.__setattr__(self, f.name, checked)

    # -- derived -----------------------------------------------------------------------------
    @property
    def sun_unit(self) -> Triple:
        """The sun direction as a unit vector (towards the sun)."""
        big = max(abs(v) for v in self.sun)  # scaled first: squares of 1e38 overflow
        x, y, z = (v / big for v in self.sun)
        length = math.sqrt(x * x + y * y + z * z)
        x, y, z = x / length, y / length, z / length
        return (x, y, z)

    def phase(self, cos_angle: float) -> float:
        """Cornette-Shanks phase function of the scattering angle, averaging 1 over the sphere.

        The report's eq. 3.14 prints ``2(1 + g^2)`` in the denominator; the published function
        (Cornette and Shanks 1992, used by Harris) has ``(2 + g^2)``, which makes g = 0 the
        Rayleigh function 3/4 (1 + cos^2) that SkyWorks uses.
        """
        g = self.anisotropy
        c = max(-1.0, min(1.0, cos_angle))
        return 1.5 * (1 - g * g) / (2 + g * g) * (1 + c * c) / (1 + g * g - 2 * g * c) ** 1.5

    @property
    def forward_fraction(self) -> float:
        """Share of the light a particle stops that it passes on towards the particles behind it.

        Harris's first pass, as SkyWorks computes it: albedo x extinction x p(0) x solid angle / 4 pi
        (0.773 with the defaults), at most the albedo: a particle passes on no more than it scatters.
        Capped at 1, every particle let all the light through past an extinction of 104 (or
        anisotropy 0.1, or a solid angle of 0.12), and the cloud was one flat white; 0 with
        scattering off.
        """
        if not self.scattering:
            return 0.0
        share = self.albedo * self.extinction * self.phase(1.0) * self.solid_angle / (4 * math.pi)
        return min(self.albedo, share)

    def extras(self) -> dict[str, Any]:
        """What a glTF file records of this light (the scene's ``extras["fishgen_light"]``), so a
        client shader can do Harris's second pass from each particle's ``_LIGHT``; see
        :func:`from_extras`."""
        return {"sun": [float(v) for v in self.sun_unit], "sun_color": list(self.sun_color),
                "sky_color": list(self.sky_color), "albedo": self.albedo, "extinction": self.extinction,
                "solid_angle": self.solid_angle, "anisotropy": self.anisotropy,
                "scattering": self.scattering,
                "light": f"_LIGHT = e^-E + 2^{round(math.log2(DIFFUSE))} (1 / (1 + E) - e^-E), E the "
                         "effective optical depth towards the sun (Harris's first pass, and light "
                         "scattered many times)",
                "colour": "COLOR_0 = albedo * (sky_color + sun_color * _LIGHT), clamped to 0..1",
                "second_pass": "albedo * (sky_color + sun_color * _LIGHT * phase(dot(view, sun)))"}


EXTRAS_KEY = "fishgen_light"
"""The member of a glTF scene's extras that holds ``Lighting.extras()``."""


def from_extras(extras: Any) -> Lighting | None:
    """The lighting a file's scene extras record, or None when there is none or it is not valid
    (a client without it shows the baked colours)."""
    if not isinstance(extras, dict) or not isinstance(extras.get(EXTRAS_KEY), dict):
        return None
    record = extras[EXTRAS_KEY]
    names = {f.name for f in fields(Lighting)}
    try:
        return Lighting(**{k: v for k, v in record.items() if k in names})
    except (FishgenError, TypeError):
        return None


def _fail(name: str, value: Any):
    return lambda what: FishgenError(f"expected {name} as {what}, found {value!r}")
