"""The sunlight a cloud is lit with: one frozen dataclass, its documented defaults, no numpy.

A leaf module: the command line declares its ``--sun`` ... options from the fields
below (each field's ``metadata`` holds the option name, the value's form and range,
and the help text) without importing numpy or the lighting code. The light itself
is computed by :mod:`fishgen.clouds.light`.

The model is Harris's (Harris and Lastra 2001; Harris 2002), as the RekAwan report
rendered its clouds (section 5.3), with the constants of Harris's own
implementation, SkyWorks' ``SkyCloud.cpp``: albedo 0.9, extinction 80, forward
scattering sampled over a 0.09 sr solid angle, and the Rayleigh phase function.
``docs/decisions.md`` ("Sunlight, baked") says how each one is used.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any

from fishgen.errors import FishgenError

Triple = tuple[float, float, float]
_FLOAT32_MAX = 3.4028234663852886e38  # mirrors fishgen.numeric without importing numpy

SUN = (0.35, 1.0, 0.55)
"""Towards the sun: 57 degrees up, in front, to the right: the sun `fishgen preview` lights fish with."""
SUN_COLOR = (0.72, 0.70, 0.66)
SKY_COLOR = (0.36, 0.40, 0.50)
ALBEDO = 0.9           # SkyWorks: SkyCloud::s_rAlbedo
EXTINCTION = 80.0      # SkyWorks: SkyCloud::s_rExtinction (a particle's centre passes e^-80)
SOLID_ANGLE = 0.09     # SkyWorks: rSolidAngle in SkyCloud::Illuminate, steradians
ANISOTROPY = 0.0       # Cornette-Shanks g (report eq. 3.14); 0 is Rayleigh scattering, as SkyWorks uses


def _meta(option: str, form: str, limits: str, text: str) -> dict[str, str]:
    return {"option": option, "form": form, "range": limits, "help": text}


@dataclass(frozen=True)
class Lighting:
    """How the sun and the sky light a cloud. Colours are linear RGB; the sun colour is its
    radiance on a particle in full sun, the sky colour the ambient light every particle gets."""

    sun: Triple = field(default=SUN, metadata=_meta(
        "--sun", "X,Y,Z", "any direction but 0,0,0 (the length does not matter)",
        "Direction towards the sun (+Y is up): where the light comes from."))
    sun_color: Triple = field(default=SUN_COLOR, metadata=_meta(
        "--sun-color", "R,G,B", "each 0 to 10, linear",
        "Sunlight on a particle in full sun, linear RGB."))
    sky_color: Triple = field(default=SKY_COLOR, metadata=_meta(
        "--sky-color", "R,G,B", "each 0 to 10, linear",
        "Ambient sky light every particle gets, linear RGB: the colour of shadowed undersides."))
    albedo: float = field(default=ALBEDO, metadata=_meta(
        "--albedo", "NUMBER", "0 to 1",
        "Fraction of the light a particle stops that it scatters rather than absorbs."))
    extinction: float = field(default=EXTINCTION, metadata=_meta(
        "--extinction", "NUMBER", "0 to 1000",
        "Optical depth through the centre of a particle of density 1 (SkyWorks' 80: opaque "
        "cores); lower makes a thinner, brighter cloud."))
    solid_angle: float = field(default=SOLID_ANGLE, metadata=_meta(
        "--solid-angle", "STERADIANS", "above 0, at most 4 pi",
        "Cone over which forward-scattered light is gathered (SkyWorks' 0.09 sr)."))
    anisotropy: float = field(default=ANISOTROPY, metadata=_meta(
        "--anisotropy", "G", "-0.9 to 0.9",
        "Phase function asymmetry g (report eq. 3.14, Cornette-Shanks); 0 is Rayleigh, "
        "positive scatters more light forward."))
    scattering: bool = field(default=True, metadata=_meta(
        "--scattering/--no-scattering", "FLAG", "on or off",
        "Multiple forward scattering (Harris); off leaves only the sunlight that passes straight through."))

    def __post_init__(self) -> None:
        sun = _triple(self.sun, "sun direction", -_FLOAT32_MAX, _FLOAT32_MAX)
        if not any(sun):
            raise FishgenError("expected a sun direction other than 0,0,0, found 0,0,0")
        object.__setattr__(self, "sun", sun)
        object.__setattr__(self, "sun_color", _triple(self.sun_color, "sun colour", 0.0, 10.0))
        object.__setattr__(self, "sky_color", _triple(self.sky_color, "sky colour", 0.0, 10.0))
        object.__setattr__(self, "albedo", _number(self.albedo, "albedo", 0.0, 1.0))
        object.__setattr__(self, "extinction", _number(self.extinction, "extinction", 0.0, 1000.0))
        solid = _number(self.solid_angle, "solid angle (steradians)", 0.0, 4 * math.pi)
        if solid == 0:
            raise FishgenError("expected a solid angle (steradians) above 0, found 0")
        object.__setattr__(self, "solid_angle", solid)
        object.__setattr__(self, "anisotropy", _number(self.anisotropy, "anisotropy g", -0.9, 0.9))
        object.__setattr__(self, "scattering", bool(self.scattering))

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
        (0.773 with the defaults), at most 1; 0 with scattering off.
        """
        if not self.scattering:
            return 0.0
        share = self.albedo * self.extinction * self.phase(1.0) * self.solid_angle / (4 * math.pi)
        return min(1.0, share)

    def extras(self) -> dict[str, Any]:
        """What a glTF file records of this light (the scene's ``extras["fishgen_light"]``), so a
        client shader can do Harris's second pass from each particle's ``_LIGHT``; see
        :func:`from_extras`."""
        return {"sun": [float(v) for v in self.sun_unit], "sun_color": list(self.sun_color),
                "sky_color": list(self.sky_color), "albedo": self.albedo, "extinction": self.extinction,
                "solid_angle": self.solid_angle, "anisotropy": self.anisotropy,
                "scattering": self.scattering,
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


def options() -> list[dict[str, Any]]:
    """Each field as the command line declares it: name, option, form, range, default and help."""
    return [{"name": f.name, "default": f.default, **f.metadata} for f in fields(Lighting)]


def _number(value: Any, what: str, low: float, high: float) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise FishgenError(f"expected a number for the {what}, found {value!r}") from None
    if not (math.isfinite(number) and low <= number <= high):
        raise FishgenError(f"expected the {what} from {low:g} to {high:g}, found {value!r}")
    return number


def _triple(values: Any, what: str, low: float, high: float) -> Triple:
    try:
        items = tuple(values)
    except TypeError:
        raise FishgenError(f"expected three numbers for the {what}, found {values!r}") from None
    if len(items) != 3:
        raise FishgenError(f"expected three numbers for the {what}, found {len(items)}")
    x, y, z = (_number(v, what, low, high) for v in items)
    return (x, y, z)
