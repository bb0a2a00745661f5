"""Where a command's outputs go, checked before any work starts.

The ``-o`` rule, for every command:

- ``-o`` names a folder only when it is an existing folder or ends in ``/``; each input then
  becomes ``FOLDER/<input stem>.<format>``;
- anything else names a file, whose extension picks the format; several inputs into one file
  is refused, and so is a name with no extension that is not a folder;
- an output that exists must be a regular file (never a FIFO or ``/dev/null``);
- no output may be one of the command's inputs;
- an output the command cannot write (its extension, a format that would lose what it holds) is a
  bad command line, exit 2 kind ``usage``, said as ``OUTPUT: expected ..., found ...``
  (:func:`output_at_fault`).

Optional dependencies a chosen feature needs are checked before any work too (:func:`needs`, from
:mod:`fishgen.extras`, which the layers below the commands use as well).
"""
from __future__ import annotations

import os
import sys
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from fishgen.atomic import check_target, protecting
from fishgen.errors import FishgenError, UsageError
from fishgen.extras import needs as needs  # the commands' one place for their checks

if TYPE_CHECKING:
    from fishgen.exchange.registry import Format


def check_inputs(paths: Iterable[str | os.PathLike], command: str, kinds: Sequence[Format],
                 default: Format | None = None) -> list[Format]:
    """Every input is a file of a kind ``command`` reads (a file meant for another command names
    that command); returns each input's format. ``default``: the format of an input whose extension
    no format claims (species files need not end in .txt)."""
    from fishgen.exchange.registry import input_format

    found = []
    for path in map(Path, paths):
        if path.is_dir():
            raise FishgenError("expected a file, found a directory", path)
        found.append(input_format(path, kinds=kinds, command=command, default=default))
    return found


def read_beside(inputs: Sequence[Path], kinds: Sequence[Format],
                textures: str | os.PathLike | None = None) -> list[Path]:
    """The files source inputs read besides themselves, found before any work so that no output
    replaces one: a species file's textures, a texture cloud's pictures, a school scene's species
    files, their textures and its path files (``kinds``: each input's format, as
    :func:`check_inputs` found it; ``textures``: the command's ``--textures``)."""
    found: list[Path] = []
    for path, kind in zip(inputs, kinds, strict=True):
        if kind.name == "school scene":
            from fishgen.exchange.registry import FORMATS
            from fishgen.school.scene_file import load_scene_file

            scene = load_scene_file(path)
            species = [entry.file for entry in scene.species]
            found += [*species, *scene.read]
            found += read_beside(species, [FORMATS["species"]] * len(species), textures)
        elif kind.name == "species":
            from fishgen.species.parser import load_species

            found += load_species(path, textures).side_files
        elif kind.name == "texture cubes":
            from fishgen.clouds.pipeline import cloud_textures, read_cube_files

            # every cube line, however many particles: the command's own read says if they are too many
            found += cloud_textures(read_cube_files([path], max_particles=sys.maxsize, textures_dir=textures,
                                                    note=lambda _: None))
    return found


@contextmanager
def output_at_fault() -> Iterator[None]:
    """The exchange layer's refusal of an output (a :class:`FishgenError` naming the file, as a
    library caller gets it) as the command line's: the -o a user typed is at fault, not an input."""
    try:
        yield
    except FishgenError as err:
        if type(err) is not FishgenError:     # a missing package stays exit 1, kind dependency
            raise
        raise UsageError(err.message, err.file, err.line) from None


def names_folder(output: str | os.PathLike) -> bool:
    """Whether ``-o`` names a folder: an existing one, or a name ending in ``/``."""
    text = os.fspath(output)
    return text.endswith(("/", os.sep)) or Path(text).is_dir()


def targets(inputs: Sequence[Path], given: str | os.PathLike | None, *, fmt: str, holding: Iterable[str] = (),
            default_folder: Path = Path("out"), noun: str = "input") -> list[Path]:
    """One output per input by the ``-o`` rule; ``fmt`` is the format inside a folder."""
    from fishgen.exchange.registry import output_format

    need = list(holding)
    several = len(inputs) > 1
    output = Path(given) if given is not None else None
    if given is not None and output is not None and not names_folder(given):
        check_target(output)  # `-o /dev/null`: not a regular file, whatever its name
        if several:
            raise UsageError(f"expected a folder for {len(inputs)} {noun}s (an existing folder, or a "
                             f"name ending in /), found {os.fspath(output)!r}")
        if not output.suffix:
            raise UsageError("expected an output file with an extension, or a folder (an existing one, "
                             "or a name ending in /), found no extension", output)
        with output_at_fault():
            output_format(output, need)
        return [output]
    folder = output if output is not None else default_folder
    with output_at_fault():
        output_format(Path(f"x.{fmt}"), need)
    made: dict[str, Path] = {}
    for path in inputs:
        name = f"{path.stem}.{fmt}"
        if name in made:
            raise UsageError(f"expected {noun}s with distinct names for one folder, found {made[name]} "
                             f"and {path} (both make {name})")
        made[name] = path
    return [folder / name for name in made]


def check_targets(outputs: Iterable[str | os.PathLike | None], inputs: Iterable[str | os.PathLike],
                  images: Sequence[str] | None = None) -> None:
    """Every output may be written: a missing or regular file, none of the command's inputs, none
    of the side files its format writes beside it an input either (a glTF's ``NAME_skin.png`` over a
    species' texture), and no two outputs one file (checked before any work; the writers check
    again, see :func:`fishgen.atomic.protecting`). ``images``: the names of the images the scene
    will hold, when known, so only their side files count (else any ``NAME_*.png`` does)."""
    targets = [Path(t) for t in outputs if t is not None]
    read = [Path(p) for p in inputs]
    with protecting(read):
        for target in targets:
            check_target(target)
    check_beside(targets, read, images)
    check_apart(targets)


def check_beside(outputs: Iterable[Path], inputs: Iterable[Path],
                 images: Sequence[str] | None = None) -> None:
    """No input is a file that writing one of ``outputs`` may make beside it (its side files; with
    ``images``, an image's side file only for the images named)."""
    from fishgen.exchange.registry import Written, written_names
    from fishgen.exchange.sidefiles import image_stem

    folders: dict[Path, list[Path]] = {}
    for path in inputs:
        folders.setdefault(Path(os.path.abspath(path)).parent.resolve(), []).append(path)
    for target in outputs:
        sides = written_names(target)[1:]
        if images is not None:  # fish7.glb of a fish with a skin writes fish7_skin.png, not fish7_mask.png
            sides = tuple(w for side in sides for w in (
                [side] if side.after is None else
                [Written(side.before + image_stem(name), side.after) for name in images]))  # NAME_skin*.png
        for path in folders.get(Path(os.path.abspath(target)).parent.resolve(), ()) if sides else ():
            side = next((s for s in sides if s.matches(path.name)), None)
            if side is not None:
                raise UsageError(f"expected an output that is not one of the command's inputs, found "
                                 f"{os.fspath(target)!r}, which writes {str(side)!r} beside it, and the "
                                 f"input {os.fspath(path)!r} is one")


def check_apart(outputs: Sequence[str | os.PathLike]) -> None:
    """No two of a command's outputs, their side files included, may be one file."""
    from fishgen.exchange.registry import first_shared

    clash = first_shared(outputs)
    if clash is not None:
        first, second, name = (Path(outputs[clash[0]]), Path(outputs[clash[1]]), clash[2])
        shown, both = first.parent / str(name), f" ({first} and {second} both write it)"
        if os.path.abspath(first) == os.path.abspath(second):
            shown, both = first, ""
        elif name.after is None and name.before in (first.name, second.name):
            both = ""
        raise UsageError(f"expected every output of one run to be a different file, found {shown} "
                         f"twice{both}")


def suffix_of(path: Path, allowed: Sequence[str], what: str) -> None:
    """A side output (``--metrics``, ``--plot``) ends in one of ``allowed``."""
    if path.suffix.lower() not in allowed:
        raise UsageError(f"expected {what} ending in {' or '.join(allowed)}, found "
                         f"{path.suffix or 'no extension'!r}", path)

