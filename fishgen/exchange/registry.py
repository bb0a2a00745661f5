"""The format registry: every file format fishgen reads or writes, declared in one place.

A format names its extensions, what it can hold, and its writer and reader as
``"module:function"`` strings, imported only when used. The CLI's ``-o``
checks, ``--format`` choices and help texts, preview inputs and viewer inputs
all come from here. Adding a format is one module plus one ``register_format``
call below.

Writers are ``write(scene, path) -> list[Path]`` (atomic, every file written);
readers are ``read(path) -> Scene``. Source formats (species and cube files)
have a reader that builds the scene and name the command that makes assets from them.
"""
from __future__ import annotations

import importlib
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

from fishgen.errors import FishgenError

MESHES, POINTS, TEXTURES, NODE_ANIMATION, SKINS, MORPH_TARGETS = (
    "meshes", "points", "textures", "node animation", "skins", "morph targets")
ALPHA_CUTOFF, DOUBLE_SIDED = "alpha cutoff", "double-sided faces"
CONTENT = (MESHES, POINTS, TEXTURES, NODE_ANIMATION, SKINS, MORPH_TARGETS, ALPHA_CUTOFF, DOUBLE_SIDED)


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

    def write(self, scene, path: Path) -> list[Path]:
        return _load(self.writer)(scene, path)

    def read(self, path: Path, **options):
        return _load(self.reader)(path, **options)


FORMATS: dict[str, Format] = {}


def register_format(fmt: Format) -> Format:
    for ext in fmt.extensions:
        taken = next((f.name for f in FORMATS.values() if ext in f.extensions), None)
        if taken is not None:
            raise ValueError(f"{ext} is already registered to {taken}")
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
    ext = Path(path).suffix.lower()
    return next((f for f in FORMATS.values() if ext in f.extensions), None)


def output_format(path: str | os.PathLike, holding: Iterable[str] = (), what: str = "output") -> Format:
    """The writable format ``path``'s extension names, able to hold ``holding``; else a one-line error."""
    need = list(holding)
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
    if missing:
        raise FishgenError(f"expected a format that holds {' and '.join(missing)}, found "
                           f"{fmt.extensions[0]} ({fmt.description}), which would lose them; use "
                           f"{' or '.join(extensions(usable))} instead", path)
    return fmt


def input_format(path: str | os.PathLike, *, kinds: Iterable[Format], command: str,
                 default: Format | None = None) -> Format:
    """The readable format of an input to ``command``; a file meant for another command says which.

    ``default``: the format of inputs whose extension no format claims (species
    files are often named ``*.txt`` but need not be).
    """
    allowed = list(kinds)
    fmt = by_extension(path)
    if fmt in allowed:
        return fmt
    if fmt is not None:
        use = f"; use `fishgen {fmt.command}` for it" if fmt.command and fmt.command != command else ""
        raise FishgenError(f"expected an input of `fishgen {command}` ({', '.join(extensions(allowed))}), "
                           f"found {fmt.description}{use}", path)
    if default is not None:
        return default
    found = Path(path).suffix or "no extension"
    raise FishgenError(f"expected an input ending in {', '.join(extensions(allowed))}, found {found!r}", path)


def lost(fmt: Format, scene) -> list[str]:
    """What ``scene`` holds that ``fmt`` cannot: said once in a command's summary."""
    return [k for k in CONTENT if k in scene.has() and k not in fmt.holds]


_ALL = frozenset(CONTENT)
register_format(Format("glb", (".glb",), "binary glTF 2.0", _ALL,
                       "fishgen.exchange.gltf:write_glb", "fishgen.exchange.gltf_reader:read_gltf",
                       viewer=True))
register_format(Format("gltf", (".gltf",), "glTF 2.0 JSON with .bin and images beside it", _ALL,
                       "fishgen.exchange.gltf:write_gltf", "fishgen.exchange.gltf_reader:read_gltf",
                       viewer=True))
register_format(Format("obj", (".obj",), "Wavefront OBJ with .mtl and images (rest pose)",
                       frozenset({MESHES, TEXTURES}),
                       "fishgen.exchange.obj:write_obj", "fishgen.exchange.mesh_reader:read_mesh_file",
                       viewer=True))
register_format(Format("ply", (".ply",), "binary PLY: a rest-pose mesh or particles",
                       frozenset({MESHES, POINTS, TEXTURES}),
                       "fishgen.exchange.ply:write_ply", "fishgen.exchange.mesh_reader:read_mesh_file",
                       viewer=True))
register_format(Format("csv", (".csv",), "CSV table of particles", frozenset({POINTS}),
                       "fishgen.exchange.table:write_csv"))
register_format(Format("npy", (".npy",), "NumPy structured array of particles", frozenset({POINTS}),
                       "fishgen.exchange.table:write_npy"))
register_format(Format("species", (".txt",), "a VRFish species file",
                       frozenset({MESHES, TEXTURES, NODE_ANIMATION}),
                       reader="fishgen.assembly.fish:species_scene", command="build"))
register_format(Format("school scene", (".toml",), "a school scene file", frozenset({MESHES, NODE_ANIMATION}),
                       command="school"))
register_format(Format("cubes", (".awn",), "a RekAwan cloud cube file", frozenset({POINTS}),
                       reader="fishgen.clouds.scene:cube_file_scene", command="clouds"))
