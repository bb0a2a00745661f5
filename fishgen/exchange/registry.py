"""The format registry: every file format fishgen reads or writes, declared in one place.

A format names its extensions, what it can hold, and its writer and reader as
``"module:function"`` strings, imported only when used. The CLI's ``-o``
checks, ``--format`` choices and help texts, preview inputs and viewer inputs
all come from here. Adding a format is one module plus one ``register_format``
call below.

Writers are ``write(scene, path) -> list[Path]`` (atomic, every file written);
readers are ``read(path, **options) -> Scene``, taking exactly the options the format declares
(``reads_with``). Source formats (species and cube files) have a reader that builds the scene and
name the command that makes assets from them.

An extension may belong to several formats (meshio's idea): ``.toml`` is a school scene or a
batch manifest. Each such format declares a ``sniff`` that tells its files by their content, and
:func:`detect` asks them.
"""
from __future__ import annotations

import bisect
import importlib
import os
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

from fishgen.errors import FishgenError

MESHES, POINTS, TEXTURES, NODE_ANIMATION, SKINS, MORPH_TARGETS = (
    "meshes", "points", "textures", "node animation", "skins", "morph targets")
ALPHA_CUTOFF, DOUBLE_SIDED = "alpha cutoff", "double-sided faces"
INSTANCES = "instances"  # copies of prototypes placed per frame (a school as USD's PointInstancer)
LEVELS, CLIPS = "levels of detail", "more than one clip"
CONTENT = (MESHES, POINTS, TEXTURES, NODE_ANIMATION, SKINS, MORPH_TARGETS, ALPHA_CUTOFF, DOUBLE_SIDED,
           LEVELS, CLIPS, INSTANCES)


@dataclass(frozen=True)
class Format:
    name: str
    extensions: tuple[str, ...]
    description: str
    holds: frozenset[str] = frozenset()
    writer: str | None = None
    reader: str | None = None
    viewer: bool = False            # the three.js viewer page can show it
    command: str | None = None      # for source formats: the command that turns them into assets
    reads_with: tuple[str, ...] = ()  # the options its reader takes, of READER_OPTIONS
    writes_with: tuple[str, ...] = ()  # the options its writer takes, of WRITER_OPTIONS
    sniff: str | None = None        # "module:function(path) -> bool": is this file of this format?
    extra: tuple[str, str, str] | None = None  # (module, pip package, extra) its writer needs
    sides: tuple[str, ...] = ()     # files written beside a target: "{stem}.bin", "{stem}_*.png" (* any text)

    def write(self, scene, path: Path, **offered) -> list[Path]:
        """Write ``scene`` to ``path``; of the ``offered`` options (each one of WRITER_OPTIONS, or it
        is a TypeError) the writer gets those it declares taking."""
        unknown = set(offered) - set(WRITER_OPTIONS)
        if unknown:
            raise TypeError(f"no writer takes {', '.join(sorted(unknown))}")
        return _load(self.writer)(scene, path, **{k: v for k, v in offered.items() if k in self.writes_with})

    def read(self, path: Path, **offered):
        """Read ``path``; of the ``offered`` options (each one of READER_OPTIONS, or it is a
        TypeError) the reader gets those it declares taking."""
        unknown = set(offered) - set(READER_OPTIONS)
        if unknown:
            raise TypeError(f"no reader takes {', '.join(sorted(unknown))}")
        return _load(self.reader)(path, **{k: v for k, v in offered.items() if k in self.reads_with})

    def matches(self, path: Path) -> bool:
        return self.sniff is None or bool(_load(self.sniff)(path))


FORMATS: dict[str, Format] = {}
READER_OPTIONS = ("textures_dir", "seed", "lighting")
"""What a caller may offer readers: a species file's (or texture cloud's) texture folder, a cube
file's fill seed, and the sunlight a cloud is lit with (:class:`fishgen.clouds.lighting.Lighting`)."""
WRITER_OPTIONS = ("voxel_size", "advance")
"""What a caller may offer writers: a volume's voxel side (.vdb, .nvdb), and ``advance(k)`` for a
progress bar of its particles splatted."""


def register_format(fmt: Format) -> Format:
    for ext in fmt.extensions:
        shared = [f for f in FORMATS.values() if ext in f.extensions]
        if shared and (fmt.sniff is None or any(f.sniff is None for f in shared)):
            raise ValueError(f"{ext} is already registered to {shared[0].name}; formats that share an "
                             "extension each need a sniff")
    unknown = set(fmt.reads_with) - set(READER_OPTIONS)
    if unknown:
        raise ValueError(f"{fmt.name}: no such reader option {', '.join(sorted(unknown))}")
    unknown = set(fmt.writes_with) - set(WRITER_OPTIONS)
    if unknown:
        raise ValueError(f"{fmt.name}: no such writer option {', '.join(sorted(unknown))}")
    FORMATS[fmt.name] = fmt
    return fmt


def _load(target: str | None) -> Callable:
    if target is None:
        raise ValueError("no such entry point")
    module, name = target.split(":")
    return getattr(importlib.import_module(module), name)


def formats(*, writable: bool = False, readable: bool = False, holding: Iterable[str] = (),
            viewer: bool = False) -> list[Format]:
    """Formats that can do all that is asked, in registration order."""
    need = set(holding)
    return [f for f in FORMATS.values()
            if (not writable or f.writer) and (not readable or f.reader) and (not viewer or f.viewer)
            and (need <= f.holds or not need)]


def extensions(fmts: Iterable[Format]) -> tuple[str, ...]:
    return tuple(ext for f in fmts for ext in f.extensions)


def by_extension(path: str | os.PathLike) -> Format | None:
    """The first format registered for ``path``'s extension (the only one, unless it is shared)."""
    return next(iter(candidates(path)), None)


def candidates(path: str | os.PathLike) -> list[Format]:
    ext = Path(path).suffix.lower()
    return [f for f in FORMATS.values() if ext in f.extensions]


def detect(path: str | os.PathLike) -> Format | None:
    """The format of an existing file: by extension, and by content where formats share it.
    None when no format claims the extension, or none of the sharing formats' sniffs agree."""
    found = candidates(path)
    if len(found) <= 1:
        return found[0] if found else None
    return next((f for f in found if f.matches(Path(path))), None)


def output_format(path: str | os.PathLike, holding: Iterable[str] = (), what: str = "output") -> Format:
    """The writable format ``path``'s extension names, able to hold ``holding``; else a one-line error."""
    need = [holding] if isinstance(holding, str) else list(holding)   # "meshes" is one need, not six
    usable = formats(writable=True, holding=need)
    fmt = by_extension(path)
    if fmt is None or fmt.writer is None:
        found = Path(path).suffix or "no extension"
        if fmt is not None and fmt.command:
            raise FishgenError(f"expected an {what} ending in {', '.join(extensions(usable))}, found "
                               f"{found!r} ({fmt.description}, an input of `fishgen {fmt.command}`)", path)
        raise FishgenError(f"expected an {what} ending in {', '.join(extensions(usable))}, found {found!r}",
                           path)
    missing = [k for k in need if k not in fmt.holds]
    if missing:  # before the package: installing usd-core would not make a .usdc hold a cloud
        instead = f"use {' or '.join(extensions(usable))} instead" if usable else "no format holds them"
        raise FishgenError(f"expected a format that holds {' and '.join(missing)}, found "
                           f"{fmt.extensions[0]} ({fmt.description}), which would lose them; {instead}",
                           path)
    if fmt.extra is not None:
        from fishgen.extras import needs

        module, package, extra = fmt.extra
        needs(module, extra, f"writing {Path(path).suffix.lower()}", package)
    return fmt


def input_format(path: str | os.PathLike, *, kinds: Iterable[Format], command: str,
                 default: Format | None = None) -> Format:
    """The readable format of an input to ``command``; a file meant for another command says which.

    ``default``: the format of inputs whose extension no format claims (species
    files are often named ``*.txt`` but need not be).
    """
    allowed = list(kinds)
    if Path(path).is_dir():
        raise FishgenError("expected a file, found a directory", path)
    found = candidates(path)
    there = Path(path).is_file()
    fmt = detect(path) if there else None
    sniffed = fmt is not None and len(found) > 1    # read and recognised, not named by its extension
    if fmt is None:  # no content to tell by (or no sniff agreed): the one this command reads
        fmt = next((f for f in found if f in allowed), found[0] if found else None)
    if fmt in allowed:
        return fmt
    if fmt is not None and there and len(found) > 1 and not sniffed:  # no sharing format knew it
        names = " nor ".join(f.description for f in found)
        raise FishgenError(f"expected an input of `fishgen {command}` ({', '.join(extensions(allowed))}), "
                           f"found a {Path(path).suffix} file that is neither {names}", path)
    if fmt is not None:
        use = f"; use `fishgen {fmt.command}` for it" if fmt.command and fmt.command != command else ""
        # only a sniff reads the content: a format judged by its extension alone is said to be
        suffix = Path(path).suffix
        what = (fmt.description if sniffed
                else f"a {suffix} file ({fmt.description.removeprefix('a ')}, by its extension)" if there
                else f"{suffix!r}, the extension of {fmt.description}")
        raise FishgenError(f"expected an input of `fishgen {command}` ({', '.join(extensions(allowed))}), "
                           f"found {what}{use}", path)
    if default is not None:
        return default
    suffix = Path(path).suffix or "no extension"
    raise FishgenError(f"expected an input ending in {', '.join(extensions(allowed))}, found {suffix!r}",
                       path)


class Written(NamedTuple):
    """A file name writing a target may make: ``before`` alone, or with a wildcard, any name that
    starts with ``before`` and ends with ``after`` (an image's name goes between)."""

    before: str
    after: str | None = None

    def __str__(self) -> str:
        return self.before if self.after is None else f"{self.before}*{self.after}"

    def matches(self, name: str) -> bool:
        """Whether the file ``name`` is one this stands for."""
        if self.after is None:
            return name == self.before
        return (len(name) >= len(self.before) + len(self.after) and name.startswith(self.before)
                and name.endswith(self.after))

    def shared(self, other: Written) -> Written | None:
        """A name both may stand for, or None."""
        if self.after is None:
            return self if other.matches(self.before) else None
        if other.after is None:
            return other if self.matches(other.before) else None
        a, b, x, y = self.before, other.before, self.after, other.after
        if (a.startswith(b) or b.startswith(a)) and (x.endswith(y) or y.endswith(x)):
            return Written(max(a, b, key=len), max(x, y, key=len))
        return None


def written_names(target: str | os.PathLike) -> tuple[Written, ...]:
    """Every file name writing ``target`` may make in its folder: its own, then the side files its
    format declares (``sides``)."""
    path = Path(target)
    fmt = by_extension(path)
    found = [Written(path.name)]
    for side in fmt.sides if fmt is not None else ():
        before, star, after = side.partition("*")  # split before the stem goes in: it may hold a *
        found.append(Written(before.replace("{stem}", path.stem),
                             after.replace("{stem}", path.stem) if star else None))
    return tuple(found)


def first_shared(targets: Sequence[str | os.PathLike]) -> tuple[int, int, Written] | None:
    """The first two of ``targets`` whose writes may make one file (their own names and their
    formats' side files, in one folder): their indices and that name, or None. Sorted by name, so
    that a batch of many outputs is checked in n log n."""
    by_folder: dict[Path, list[tuple[Written, int]]] = {}
    for k, target in enumerate(targets):
        path = Path(os.path.abspath(target))
        by_folder.setdefault(path.parent, []).extend((name, k) for name in written_names(path))
    found: list[tuple[int, int, Written]] = []
    for names in by_folder.values():
        names.sort(key=lambda item: item[0].before)
        starts = [name.before for name, _ in names]
        by_start: dict[str, list[tuple[Written, int]]] = {}
        for item in names:
            by_start.setdefault(item[0].before, []).append(item)
        for name, k in names:
            if name.after is None:  # a plain name meets a plain one of the same start, seen from there
                others = [o for o in by_start[name.before] if o[0].after is None]
            else:  # a pattern meets names starting with its start, and patterns whose start begins it
                end = bisect.bisect_left(starts, name.before + "\U0010ffff")
                others = names[bisect.bisect_left(starts, name.before):end]
                others += [o for n in range(len(name.before)) for o in by_start.get(name.before[:n], ())
                           if o[0].after is not None]
            for other, j in others:
                if j != k and (shared := name.shared(other)) is not None:
                    found.append((min(j, k), max(j, k), shared))
    return min(found, key=lambda f: (f[0], f[1])) if found else None


def lost(fmt: Format, scene) -> list[str]:
    """What ``scene`` holds that ``fmt`` cannot: said once in a command's summary."""
    return [k for k in CONTENT if k in scene.has() and k not in fmt.holds]


_ALL = frozenset(CONTENT) - {INSTANCES}
register_format(Format("glb", (".glb",), "binary glTF 2.0", _ALL,
                       "fishgen.exchange.gltf:write_glb", "fishgen.exchange.gltf_reader:read_gltf",
                       viewer=True))
register_format(Format("gltf", (".gltf",), "glTF 2.0 JSON with .bin and images beside it", _ALL,
                       "fishgen.exchange.gltf:write_gltf", "fishgen.exchange.gltf_reader:read_gltf",
                       viewer=True, sides=("{stem}.bin", "{stem}_*.png", "{stem}_*.jpg")))
register_format(Format("obj", (".obj",), "Wavefront OBJ: a rest-pose mesh with .mtl and images",
                       frozenset({MESHES, TEXTURES}),
                       "fishgen.exchange.obj:write_obj", "fishgen.exchange.mesh_reader:read_mesh_file",
                       viewer=True, sides=("{stem}.mtl", "{stem}_*.png")))
register_format(Format("ply", (".ply",), "binary PLY: a rest-pose mesh or particles",
                       frozenset({MESHES, POINTS, TEXTURES}),
                       "fishgen.exchange.ply:write_ply", "fishgen.exchange.mesh_reader:read_mesh_file",
                       viewer=True, sides=("{stem}_*.png",)))
register_format(Format("csv", (".csv",), "CSV table of particles", frozenset({POINTS}),
                       "fishgen.exchange.table:write_csv"))
register_format(Format("npy", (".npy",), "NumPy structured array of particles", frozenset({POINTS}),
                       "fishgen.exchange.table:write_npy"))
register_format(Format("nvdb", (".nvdb",), "NanoVDB volume: a cloud's density and light grids",
                       frozenset({POINTS}), "fishgen.exchange.nanovdb:write_nvdb",
                       writes_with=("voxel_size", "advance")))
register_format(Format("vdb", (".vdb",), "OpenVDB volume: a cloud's density and light grids",
                       frozenset({POINTS}), "fishgen.exchange.openvdb:write_vdb",
                       writes_with=("voxel_size", "advance")))
register_format(Format("species", (".txt",), "a VRFish species file",
                       frozenset({MESHES, TEXTURES, NODE_ANIMATION}),
                       reader="fishgen.assembly.fish:species_scene", command="build",
                       reads_with=("textures_dir",), sides=("{stem}.png", "{stem}_mask.png")))
register_format(Format("school scene", (".toml",), "a school scene file", frozenset({MESHES, NODE_ANIMATION}),
                       command="school", sniff="fishgen.tomlfile:is_school_scene"))
register_format(Format("batch manifest", (".toml",), "a batch manifest", command="batch",
                       sniff="fishgen.tomlfile:is_batch_manifest"))
register_format(Format("cubes", (".awn",), "a RekAwan cloud cube file", frozenset({POINTS}),
                       reader="fishgen.clouds.scene:cube_file_scene", command="clouds",
                       reads_with=("seed", "lighting")))
register_format(Format("texture cubes", (".awa",), "a RekAwan texture cloud file", frozenset({MESHES,
                                                                                             TEXTURES}),
                       reader="fishgen.clouds.scene:cube_file_scene", command="clouds",
                       reads_with=("seed", "lighting", "textures_dir")))
_USD = frozenset({MESHES, TEXTURES, NODE_ANIMATION, SKINS, MORPH_TARGETS, ALPHA_CUTOFF, DOUBLE_SIDED,
                  INSTANCES})
for _name, _what in (("usdc", "binary"), ("usda", "text"),
                     ("usdz", "a package of binary USD and its textures")):
    register_format(Format(_name, (f".{_name}",), f"OpenUSD, {_what}: a fish as a skinned UsdSkel mesh, a "
                           "school as a PointInstancer (needs usd-core)", _USD,
                           "fishgen.exchange.usd:write_usd", extra=("pxr", "usd-core", "usd"),
                           sides=() if _name == "usdz" else ("{stem}_*.png",)))
