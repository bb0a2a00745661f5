"""Options declared once: an options record's fields *are* the declarations.

    @dataclass(frozen=True)
    class BuildOptions:
        fps: float = option(FiniteRange(1, 1000), "Frames per second.", 30.0)

One such field gives the command line its ``--fps`` (type, range, default and help, checked by
click before any work), the batch manifest its ``fps = 30`` key (the same type checks on the TOML
value, with the manifest's ``FILE:LINE``), and the library function its ``options.fps``. Scene
files check their keys against the same declarations.

Leaf module: click and the standard library only, so ``fishgen --help`` never loads numpy.
"""
from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Iterator, Mapping
from dataclasses import MISSING, Field, dataclass, field, fields
from pathlib import Path
from typing import Any, TypeVar

import click

from fishgen.errors import FishgenError

OPTION = "fishgen.option"
FLOAT32_MAX = 3.4028234663852886e38  # mirrors fishgen.numeric without importing numpy at --help time
SEED_MAX = 2**63 - 1
"""The largest seed: every command takes 0 .. 2^63 - 1 (a TOML integer holds no more)."""

T = TypeVar("T")


# -- types click checks (and manifests reuse) -------------------------------------------------

class Numbers(click.ParamType):
    """``A,B,...``: ``count`` finite numbers, by default within float32 range (where particles and
    nodes live); ``low``/``high`` bound each, ``ordered`` wants them ascending, ``positive`` all
    above 0, ``nonzero`` not all 0 (a direction). A TOML array is taken as the numbers."""

    toml_list = True
    _WORDS = {2: "two", 3: "three", 4: "four", 6: "six"}

    def __init__(self, count: int, name: str, low: float = -FLOAT32_MAX, high: float = FLOAT32_MAX, *,
                 ordered: bool = False, positive: bool = False, nonzero: bool = False):
        self.count, self.name, self.low, self.high = count, name, low, high
        self.ordered, self.positive, self.nonzero = ordered, positive, nonzero
        float32 = (low, high) == (-FLOAT32_MAX, FLOAT32_MAX)
        within = "within float32 range" if float32 else f"from {low:g} to {high:g}"
        # shown in --help as click shows a number range; float32's own bounds go unsaid
        self.range_text = None if float32 else f"{_plain(low)}<=each<={_plain(high)}"
        self.what = (f"{name} with {self._WORDS.get(count, count)} finite numbers {within}"
                     + (", the first at most the second" if ordered else "")
                     + (", all above 0" if positive else "") + (", not all 0" if nonzero else ""))

    def convert(self, value, param, ctx):
        if isinstance(value, (tuple, list)):
            numbers = tuple(value)
        else:
            try:
                numbers = tuple(float(part) for part in str(value).replace(" ", "").split(","))
            except (ValueError, OverflowError):
                numbers = ()
        ok = (len(numbers) == self.count
              and all(_finite_number(v) and self.low <= v <= self.high for v in numbers)
              and not (self.ordered and list(numbers) != sorted(numbers))
              and not (self.positive and min(numbers) <= 0)
              and not (self.nonzero and not any(numbers)))
        if not ok:
            self.fail(f"expected {self.what}, found {value!r}", param, ctx)
        return tuple(float(v) for v in numbers)


def _plain(value: float) -> str:
    """A bound as --help shows it: 1000000, not 1e+06."""
    return str(int(value)) if float(value).is_integer() else f"{value:g}"


class Triple(Numbers):
    """``X,Y,Z``: three finite numbers (see :class:`Numbers`)."""

    def __init__(self, low: float = -FLOAT32_MAX, high: float = FLOAT32_MAX, nonzero: bool = False,
                 name: str = "X,Y,Z"):
        super().__init__(3, name, low, high, nonzero=nonzero)


class FiniteRange(click.FloatRange):
    """click's FloatRange, refusing NaN too (it compares false with both bounds, so it passes them),
    and an integer too big for a float (a TOML integer of 400 digits) as out of range."""

    def convert(self, value, param, ctx):
        try:
            number = super().convert(value, param, ctx)
        except OverflowError:
            self.fail(f"{str(value)[:20]}... is not a number a float can hold.", param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number.", param, ctx)
        return number


class Size(click.ParamType):
    """``WxH`` in pixels, each side within ``low`` .. ``high``."""

    name = "WxH"

    def __init__(self, low: int = 16, high: int = 8192):
        self.low, self.high = low, high
        self.range_text = f"{low}<=W,H<={high}"
        self.what = f"WxH with {low} to {high} pixels a side"

    def convert(self, value, param, ctx):
        import re

        if isinstance(value, tuple):   # click's converted value, or a Python caller's (W, H)
            if not (len(value) == 2 and all(_whole(v) and self.low <= v <= self.high for v in value)):
                self.fail(f"expected {self.what}, found {value!r}", param, ctx)
            return value
        m = re.fullmatch(r"\s*(\d{1,6})\s*[xX×]\s*(\d{1,6})\s*", str(value))
        if not m or not all(self.low <= int(v) <= self.high for v in m.groups()):
            self.fail(f"expected {self.what}, found {value!r}", param, ctx)
        return int(m[1]), int(m[2])


class Colour(click.ParamType):
    """A CSS colour (``#8cadcc``, ``#rrggbbaa``, ``white``) or ``transparent``, as sRGB 0-255 RGBA."""

    name = "COLOUR"

    def __init__(self, opaque: bool = False) -> None:
        self.opaque = opaque  # a page's background: a browser shows no see-through one
        self.what = ("an opaque colour (#8cadcc, white)" if opaque
                     else "a colour (#8cadcc, white) or transparent")

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):   # click's converted value, or a Python caller's RGBA
            if not (len(value) == 4 and all(_whole(v) and 0 <= v <= 255 for v in value)
                    and not (self.opaque and value[3] != 255)):
                self.fail(f"expected {self.what} (or four whole numbers 0-255), found {value!r}", param, ctx)
            return value
        from PIL import ImageColor

        text = str(value).strip()
        rgba: tuple[int, ...] | int | None = None
        if text.lower() in ("transparent", "none"):
            rgba = (0, 0, 0, 0)
        else:
            try:
                rgba = ImageColor.getcolor(text, "RGBA")
            except ValueError:
                self.fail(f"expected {self.what}, found {value!r}", param, ctx)
        r, g, b, a = rgba if isinstance(rgba, tuple) else (rgba, rgba, rgba, 255)
        if self.opaque and a != 255:
            self.fail(f"expected {self.what}, found {value!r}", param, ctx)
        return int(r), int(g), int(b), int(a)


class Lods(click.ParamType):
    """``32x24,16x12,8x6``: levels of detail as BodySections x CircleSections, finest first, each
    level with fewer sections than the one before; at most ``most`` levels, each count 3 to ``high``."""

    name = "BxC,..."

    def __init__(self, most: int = 8, high: int = 1024, points: int = 65_536):
        self.most, self.high, self.points = most, high, points
        self.what = (f"levels BODIESxCIRCLES from finest to coarsest (e.g. 32x24,16x12,8x6): at most {most}, "
                     f"each count 3 to {high}, BODIES x CIRCLES at most {points:,}")

    def convert(self, value, param, ctx):
        import re

        if isinstance(value, (tuple, list)):  # from Python (or click's converted value): checked as its text
            try:
                value = ",".join(f"{b}x{c}" for b, c in value)
            except (TypeError, ValueError):
                self.fail(f"expected {self.what}, found {value!r}", param, ctx)
        parts = [p.strip() for p in str(value).split(",")]
        levels = []
        for part in parts:
            m = re.fullmatch(r"(\d{1,5})\s*[xX×]\s*(\d{1,5})", part)
            if (not m or not all(3 <= int(v) <= self.high for v in m.groups())
                    or int(m[1]) * int(m[2]) > self.points):  # 1000x1000 took 14 s and 1 GB
                self.fail(f"expected {self.what}, found {value!r}", param, ctx)
            levels.append((int(m[1]), int(m[2])))
        if not 1 <= len(levels) <= self.most or any(
                b1 * c1 <= b2 * c2 for (b1, c1), (b2, c2) in zip(levels, levels[1:], strict=False)):
            self.fail(f"expected {self.what}, found {value!r}", param, ctx)
        return tuple(levels)


class Names(click.ParamType):
    """``a,b,c``: distinct names, each one of ``choices``, in the order given."""

    name = "NAME,..."

    def __init__(self, choices: tuple[str, ...]):
        self.choices = choices
        self.what = f"names from {', '.join(choices)}, separated by commas, each once"

    def convert(self, value, param, ctx):
        if isinstance(value, (tuple, list)):  # from Python (or click's converted value): checked as its text
            value = ",".join(map(str, value))
        names = tuple(p.strip() for p in str(value).split(","))
        if not names or any(n not in self.choices for n in names) or len(set(names)) != len(names):
            self.fail(f"expected {self.what}, found {value!r}", param, ctx)
        return names


def _whole(value: Any) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _finite_number(value: Any) -> bool:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    return isinstance(value, int) or math.isfinite(value)  # an int of any size is finite; isfinite overflows


class NamedPath(click.Path):
    """A path option that must name something: ``--out ''`` is Path('.'), the working folder."""

    def convert(self, value, param, ctx):
        if isinstance(value, str) and not value:
            self.fail("expected a file or folder name, found an empty one", param, ctx)
        return super().convert(value, param, ctx)


SEED = click.IntRange(0, SEED_MAX)
FOLDER = NamedPath(file_okay=False, path_type=Path)
# A folder written into: a file in its place is the system's refusal (status 1), said when the
# folder is made, after the command line and the inputs are judged, as for any output's folder;
# click's file_okay=False made it a usage error (2), before them.
OUT_FOLDER = NamedPath(path_type=Path)
FILE = NamedPath(dir_okay=False, path_type=Path)


# -- the declaration ------------------------------------------------------------------------------

@dataclass(frozen=True)
class Option:
    """What one option is: its type (a click ParamType, which checks it), help, default, how
    ``--help`` shows the default, and where it may be set."""

    type: click.ParamType
    help: str
    default: Any = None
    shown_default: str | None = None  # for --help when the default alone does not say (None: computed)
    short: str | None = None          # e.g. "-j"
    metavar: str | None = None
    flag: bool = False
    multiple: bool = False
    manifest: bool = True             # a batch manifest may set it
    required: bool = False            # on the command line
    off: str | None = None            # a flag's switch-off name (--no-scattering)
    path: bool = False                # a file or folder: relative to the manifest in a manifest
    exists: bool = False              # a folder read from: it must be there (commands.run checks it once a
                                      # manifest has resolved it; click would check it against the cwd)

    def default_text(self) -> str:
        if self.shown_default is not None:
            return self.shown_default
        if self.flag:
            return "on" if self.default else "off"
        if self.multiple and not self.default:
            return "none"
        if isinstance(self.default, tuple):
            return ",".join(f"{v:g}" if isinstance(v, float) else str(v) for v in self.default)
        if isinstance(self.default, float):
            return f"{self.default:g}"
        return str(self.default)


def option(type: click.ParamType, help: str, default: Any = None, **kwargs: Any) -> Any:
    """A field of an options record, declaring its option (see the module's docstring)."""
    return declare(Option(type, help, default, **kwargs))


def declare(spec: Option, **changes: Any) -> Any:
    """A field of an options record from a declaration made elsewhere (a scene file's key that is
    also an option), with ``changes`` (another default, how --help shows it)."""
    from dataclasses import replace

    spec = replace(spec, **changes)
    return field(default=spec.default, metadata={OPTION: spec})


GROUP = "fishgen.option_group"


def group(record: type) -> Any:
    """A field holding a whole options record (a cloud's lighting), whose options the command takes
    as its own: declared once in ``record``, shared by every command that groups it."""
    return field(default_factory=record, metadata={GROUP: record})


def declared(record: type | Any) -> Iterator[tuple[Field, Option]]:
    """Each option of an options record with its declaration, in declaration order; the options
    of its groups take their group's place."""
    for f in fields(record):
        spec = f.metadata.get(OPTION)
        if spec is not None:
            yield f, spec
        elif GROUP in f.metadata:
            yield from declared(f.metadata[GROUP])


def build(record: type[T], values: Mapping[str, Any]) -> T:
    """The record from option values keyed by field name (a group's options fill its record)."""
    given: dict[str, Any] = {}
    for f in fields(record):  # type: ignore[arg-type]  # an options record is a dataclass
        if GROUP in f.metadata:
            given[f.name] = build(f.metadata[GROUP], values)
        elif f.name in values:
            given[f.name] = values[f.name]
    return record(**given)


def flat(options: Any) -> dict[str, Any]:
    """An options record's values keyed by field name, its groups' options among them."""
    values: dict[str, Any] = {}
    for f in fields(options):
        value = getattr(options, f.name)
        if GROUP in f.metadata:
            values.update(flat(value))
        elif OPTION in f.metadata:
            values[f.name] = value
    return values


def long_name(f: Field) -> str:
    """The option's name on the command line and in manifests: ``max_particles`` -> ``max-particles``."""
    return f.name.replace("_", "-")


# -- the command line -----------------------------------------------------------------------------

def click_params(record: type) -> list[click.Parameter]:
    """The click options of an options record, each documenting its default."""
    params: list[click.Parameter] = []
    for f, spec in declared(record):
        switch = f"--{long_name(f)}" + (f"/{spec.off}" if spec.off else "")
        decls = [switch, *([spec.short] if spec.short else []), f.name]
        help_text = f"{spec.help}  [default: {spec.default_text()}]" if not spec.required else spec.help
        bounds = getattr(spec.type, "range_text", None)
        if bounds:  # as click adds a FloatRange's bounds
            help_text += f"  [{bounds}]"
        # a required option gets no default at all: click 8.3 takes an explicit default=None as a value
        default = {} if spec.required else {"default": bool(spec.default) if spec.flag else spec.default}
        if spec.flag:
            params.append(click.Option(decls, is_flag=True, help=help_text, required=spec.required,
                                       **default))
        else:
            params.append(click.Option(decls, type=spec.type, multiple=spec.multiple, metavar=spec.metavar,
                                       help=help_text, show_default=False, required=spec.required, **default))
    return params


def from_values(record: type[T], values: Mapping[str, Any]) -> T:
    """The options record from click's values (keyed by field name); unknown keys are a bug."""
    names = {f.name for f, _ in declared(record)}
    unknown = set(values) - names
    if unknown:
        raise TypeError(f"{record.__name__} has no option {', '.join(sorted(unknown))}")
    return build(record, {k: (tuple(v) if isinstance(v, list) else v) for k, v in values.items()})


# -- manifests and scene files --------------------------------------------------------------------

def what(spec: Option) -> str:
    """The words a manifest's error uses for what a value must be."""
    t = spec.type
    if spec.flag:
        text = "true or false"
    elif hasattr(t, "what"):
        text = str(t.what)
    elif isinstance(t, click.Choice):
        text = "one of " + ", ".join(map(str, t.choices))
    elif isinstance(t, (click.IntRange, click.FloatRange)):
        kind = "a whole number" if isinstance(t, click.IntRange) else "a number"
        if t.min is not None and t.max is not None:
            text = f"{kind} from {t.min:g} to {t.max:g}" if isinstance(t, click.FloatRange) else \
                f"{kind} from {t.min} to {t.max}"
        elif t.min is not None:
            text = f"{kind} of {t.min} or more"
        else:
            text = kind
    elif isinstance(t, click.Path):
        text = "a folder name" if not t.file_okay else "a file name"
    else:
        text = f"a {t.name}"
    return f"a list of {text}" if spec.multiple else text


def _toml_kind_ok(spec: Option, value: Any) -> bool:
    """TOML values come typed: a number where a number is declared, text where a name is."""
    t = spec.type
    if spec.flag:
        return isinstance(value, bool)
    if isinstance(value, bool):
        return False
    if isinstance(t, click.IntRange) or t is click.INT:
        return isinstance(value, numbers.Integral)
    if isinstance(t, click.FloatRange) or t is click.FLOAT:
        return isinstance(value, numbers.Real)
    if getattr(t, "toml_list", False):  # a TOML array where numbers are declared
        return isinstance(value, list)
    return isinstance(value, str)


def check_value(spec: Option, value: Any, fail: Callable[[str], FishgenError]) -> Any:
    """A manifest's or scene file's value, checked exactly as the command line checks it.
    ``fail(what)`` makes the error at the value's line."""
    items = value if spec.multiple else [value]
    if spec.multiple and not isinstance(value, list):
        raise fail(what(spec))
    converted = []
    for item in items:
        if not _toml_kind_ok(spec, item):
            raise fail(what(spec))
        if spec.flag:
            converted.append(item)
            continue
        try:
            converted.append(spec.type.convert(item, None, None))
        except click.BadParameter:
            raise fail(what(spec)) from None
    return tuple(converted) if spec.multiple else converted[0]


def check_record(options: Any) -> None:
    """A Python caller's options record, each value checked by its declaration as the command line
    and manifests check theirs (theirs are checked on the way in; a record made in Python is not):
    a UsageError naming the field and its option. Not :func:`check_value`: a Python value comes as
    Python types (a tuple, a Path), not as TOML's."""
    from fishgen.errors import UsageError

    for f in fields(options):
        value = getattr(options, f.name)
        if GROUP in f.metadata:
            check_record(value)
            continue
        spec, default = f.metadata.get(OPTION), field_default(f)
        if spec is None or value is default or (type(value) is type(default) and value == default):
            continue
        if not _fits(spec, value):
            raise UsageError(f"expected options.{f.name} (--{long_name(f)}) to be {what(spec)}, "
                             f"found {value!r}")


def _fits(spec: Option, value: Any) -> bool:
    """Whether ``value`` is one its option's type takes as it is (a whole number stays whole:
    click's int() would make 2.5 two)."""
    if value is None or (spec.multiple and not isinstance(value, (tuple, list))):
        return False
    for item in value if spec.multiple else [value]:
        if spec.flag:
            if not isinstance(item, bool):
                return False
            continue
        try:
            if not _same(spec.type.convert(item, None, None), item):
                return False
        except click.BadParameter:
            return False
    return True


def _same(converted: Any, given: Any) -> bool:
    """Whether a converted value is the given one: numbers equal, sequences item by item (a path
    given as text and converted to a Path is the same)."""
    if isinstance(converted, bool) or isinstance(given, bool):   # only flags are true or false
        return converted is given
    if isinstance(converted, numbers.Real) and isinstance(given, numbers.Real):
        return converted == given
    if isinstance(converted, (tuple, list)) and isinstance(given, (tuple, list)):
        return len(converted) == len(given) and all(map(_same, converted, given))
    return True


def manifest_options(record: type) -> dict[str, tuple[Field, Option]]:
    """The keys a manifest may set for a command: long name -> (field, declaration)."""
    return {long_name(f): (f, spec) for f, spec in declared(record) if spec.manifest}


def field_default(f: Field) -> Any:
    return None if f.default is MISSING else f.default


# -- options several commands share (each call declares one field) -----------------------------

def fins_option(shown_default: str) -> Any:
    from fishgen.fish_modes import FIN_MODES

    return option(click.Choice(FIN_MODES), "Fin technique (thesis ch. 5): translucent, mask cut-out or "
                  "opaque.", shown_default=shown_default)


def lods_option() -> Any:
    return option(Lods(), "Levels of detail, BodySections x CircleSections from finest to coarsest: one glTF "
                  "holds them all (MSFT_lod on the finest, screen-coverage switch points; clients without "
                  "levels of detail show the finest).", shown_default="the species file's own level",
                  metavar="BxC,...")


def merge_option() -> Any:
    return option(click.BOOL, "One skinned mesh of two primitives (opaque body, fins): two draw calls a fish "
                  "instead of one per part; fins swing on joints.", False, flag=True)


PROTOTYPES = 4
"""A USD school's prototypes a species when --prototypes is not given."""


def prototypes_option() -> Any:
    # None when not given: a glb has no prototypes, and a --prototypes given with one is refused
    return option(click.IntRange(1, 64), "In a USD file (.usdc, .usda, .usdz), each species as this many "
                  "prototypes of a PointInstancer, their swim clips phase-shifted by an equal share of a "
                  "loop; each fish wears one, seeded, and only those some fish wears are written (more: "
                  "fewer fish swim in step, a larger file).", None,
                  shown_default=str(PROTOTYPES))


def compact_option() -> Any:
    return option(click.BOOL, "Rotation keys and morph weights as normalized 16-bit integers "
                  "(core glTF 2.0), about half their size.", False, flag=True)


def instancing_option() -> Any:
    """--instancing of the pages that draw glb files (view, fly)."""
    return option(click.BOOL, "Draw a `fishgen school` glb one instanced mesh per species and material (two "
                  "draw calls for a school of one species, however many fish); --no-instancing draws it "
                  "fish by fish as the file holds it, to compare (the page's ?instancing=0 does too).", True,
                  flag=True, off="--no-instancing")


def swim_option(help_text: str) -> Any:
    from fishgen.fish_modes import SWIM_MODES

    return option(click.Choice(SWIM_MODES), help_text, "body")


def textures_option(shown_default: str) -> Any:
    return option(FOLDER, "Folder texture names resolve in (and may not leave).", shown_default=shown_default,
                  metavar="DIR", path=True, exists=True)


def cloud_textures_option() -> Any:
    """--textures of a command reading texture clouds (.awa): where their PNGs are found."""
    return textures_option("a .awa file's folder, then the textures/ folder beside it (or beside its parent)")


def max_particles_option(default: int, whole: str = "scenes") -> Any:
    """--max-particles of a command filling clouds: the particles of the whole it makes (``whole``).
    ``default``: the cloud model's own cap, which the caller passes (options sit below the models)."""
    return option(click.IntRange(min=1), f"Refuse {whole} with more particles than this, before allocating "
                  "anything.", default)


def seed_option(help_text: str, default: int | None = 0, shown_default: str | None = None) -> Any:
    return option(SEED, f"Random seed (0 to 2^63-1); the same seed gives byte-identical files. {help_text}",
                  default, shown_default=shown_default)


def voxel_size_option(default: float) -> Any:
    """--voxel-size of a command writing volumes (.vdb, .nvdb). ``default``: the cloud model's own
    (options sit below the models), shown in --help; the field's own is None, so that one given with
    another output can be refused."""
    return option(FiniteRange(0, FLOAT32_MAX, min_open=True),
                  ".vdb and .nvdb only: the side of a voxel, in the cube files' units; a box of more "
                  "than 2^25 voxels around the cloud is refused before filling.",
                  shown_default=f"{default:g}", metavar="SIZE")
