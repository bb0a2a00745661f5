"""Sampled species as files: the species text, its painted texture and fin mask, written atomically.

Naming, for `fishgen species` and `fishgen texture` alike: the species file is written exactly where
``-o`` says. Its textures are ``NEW.png`` and ``NEW_mask.png`` beside it (``NEW`` the file's name
without ``.txt``) whenever those names can stand in the species file's texture record
(:func:`fishgen.file_names.texture_token_problem`); otherwise each offending run of characters
becomes ``_`` (and a name too long is cut), the command says so in one line, and refuses names
that would be another output or a file already there that the species file does not name. The
species' own name, inside the file, is ``NEW`` with every run of characters other than ASCII
letters, digits and ``_`` made ``_``."""
from __future__ import annotations

import os
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

from fishgen.errors import FishgenError, UsageError
from fishgen.file_names import NAME_MAX, ascii_name, name_text, texture_token_problem

MASK_SUFFIX = "_mask.png"


@dataclass(frozen=True)
class TextureNames:
    """The texture and fin mask names a species file at ``species_file`` names (beside it)."""

    species_file: Path
    colour: str
    mask: str
    why: str | None = None   # why the names are not NEW.png and NEW_mask.png; None when they are

    @property
    def paths(self) -> tuple[Path, Path]:
        return self.species_file.with_name(self.colour), self.species_file.with_name(self.mask)

    @property
    def note(self) -> str | None:
        """The one line that says the names were derived, or None when they were not."""
        if self.why is None:
            return None
        stem = self.species_file.stem
        return (f"note: textures named {self.colour} and {self.mask}, not {stem!r} + .png and _mask.png: "
                f"that name {self.why}")


def texture_names(species_file: str | os.PathLike) -> TextureNames:
    """``NEW.png`` and ``NEW_mask.png`` for ``NEW.txt`` when both are legal texture tokens, else a
    derived pair that is (see the module's text)."""
    path = Path(species_file)
    stem = path.stem
    text = name_text(stem)     # as the species file will name them
    why = texture_token_problem(text + MASK_SUFFIX) or texture_token_problem(text + ".png")
    if why is None:
        return TextureNames(path, stem + ".png", stem + MASK_SUFFIX)
    safe = re.sub(r"[\s/\\\ud800-\udfff]+", "_", stem)
    raw = safe.encode("utf-8")[:NAME_MAX - len(MASK_SUFFIX)]
    safe = raw.decode("utf-8", "ignore") or "_"  # never half a character
    return TextureNames(path, safe + ".png", safe + MASK_SUFFIX, why)


def check_texture_names(names: TextureNames, others: Iterable[str | os.PathLike | None] = ()) -> None:
    """Texture names may not be a file that is already there and that the species file at
    ``names.species_file`` does not name (a rerun replaces its own textures), nor a texture another
    species file beside it names (see :func:`_named_by_another`); derived names may not be another
    output of the run (``others``) either."""
    _named_by_another(names)
    taken = {os.path.abspath(p) for p in others if p is not None}
    named = _named_textures(names.species_file)
    whence = "derived from -o" if names.why is not None else "beside"
    for path in names.paths:
        if names.why is not None and os.path.abspath(path) in taken:
            raise UsageError(f"expected texture names that are no other output, found {path.name!r} "
                             f"(derived from -o {os.fspath(names.species_file)!r}) also named as an "
                             f"output; choose another -o")
        # A rerun replaces the pictures its own species file names; any other file of that name is
        # someone's (an unrelated fish.png beside a new fish.txt was silently replaced); a folder
        # there is said as every output's is.
        if os.path.lexists(path) and not os.path.isdir(path) and (names.colour, names.mask) != named:
            there = "which does not name it" if os.path.lexists(names.species_file) else "not there yet"
            raise UsageError(f"expected texture names that are no file already there, found "
                             f"{os.fspath(path)!r} ({whence} {os.fspath(names.species_file)!r}, "
                             f"{there}); move it or choose another -o")


def _named_by_another(names: TextureNames) -> None:
    """Refuse textures another species file beside names them: ``fish7_mask.txt``'s colour texture
    is ``fish7_mask.png``, ``fish7.txt``'s fin mask, which it silently replaced with a colour
    picture. The other owners are looked up by the documented pair (``T.png`` is ``T.txt``'s
    colour, ``T_mask.png`` also ``T.txt``'s mask), not by reading the folder: ``species`` may
    write thousands of files into one."""
    own = os.path.abspath(names.species_file)
    for path in names.paths:   # there or not: a missing mask written as a colour picture is as wrong
        stem = path.name[:-len(".png")]
        owners = [stem + ".txt"] + ([stem[:-len("_mask")] + ".txt"] if stem.endswith("_mask") else [])
        for owner in (path.with_name(name) for name in owners):
            if os.path.abspath(owner) == own or not owner.is_file():
                continue
            if _names(owner, path):
                raise UsageError(f"expected textures no other species file names, found {path.name!r}, "
                                 f"named by {owner.name!r} beside it; choose another -o")
    mine = Path(own) if os.path.isfile(own) else None
    for path in names.paths:
        # A picture already there that this species file does not name (its rerun) may be
        # another's under any name: y.txt naming shared.png. Only then is the folder read, and
        # only species files that mention the name, so a folder of thousands costs nothing on a rerun.
        if not path.is_file() or (mine is not None and _names(mine, path)):
            continue
        for owner in sorted(path.parent.glob("*.txt")):
            if os.path.abspath(owner) == own or not owner.is_file():
                continue
            try:
                if path.name.encode("utf-8").lower() not in owner.read_bytes().lower():
                    continue
            except OSError:
                continue
            if _names(owner, path):
                raise UsageError(f"expected textures no other species file names, found {path.name!r}, "
                                 f"named by {owner.name!r} beside it; choose another -o")


def _names(owner: Path, picture: Path) -> bool:
    """Whether the species file ``owner`` names ``picture`` as a texture, however it writes the name
    (``./shared.png``, ``pics/../shared.png``); casefolded: on a case-insensitive disk
    Fish7_mask.png is fish7_mask.png."""
    target = os.path.abspath(picture).casefold()
    return any(os.path.abspath(owner.parent / name).casefold() == target
               for name in _named_textures(owner) or ())


def _named_textures(species_file: Path) -> tuple[str, str] | None:
    """The texture record of an existing species file, or None (none there, or unreadable)."""
    from fishgen.species.parser import parse_species

    names: list[str] = []

    def note(name: str, _line) -> Path:  # the parser's texture resolver, here only listening
        names.append(name)
        return Path(name)

    try:
        parse_species(species_file.read_text(encoding="utf-8"), species_file, note)
    except (OSError, UnicodeDecodeError, FishgenError, ValueError):
        return None
    return (names[0], names[1]) if len(names) == 2 else None


def sample_files(seed: int, stem: str, textures: TextureNames | None = None) -> dict[str, bytes]:
    """File name -> bytes of sample ``seed`` named ``stem`` inside: ``stem``.txt/.png/_mask.png, or
    the species file and texture names ``textures`` gives."""
    from dataclasses import replace

    from fishgen.authoring.painter import texture_files
    from fishgen.authoring.sampler import sample_species
    from fishgen.species.parser import parse_species
    from fishgen.species.writer import format_species

    names = textures or TextureNames(Path(f"{stem}.txt"), f"{stem}.png", f"{stem}{MASK_SUFFIX}")
    sample = sample_species(seed, stem)
    sp = replace(sample.species, name=stem)
    text = format_species(sp, name_text(names.colour), name_text(names.mask))
    file_name = names.species_file.name
    parse_species(text, file_name)   # a sample the parser would refuse is a bug here, not the user's
    colour, mask = texture_files(sp, sample.palette, seed)
    return {file_name: text.encode(), names.colour: colour, names.mask: mask}


def write_samples(seed: int, count: int, output: Path, folder: bool | None = None,
                  note: Callable[[str], None] | None = None,
                  progress: Callable[[int], None] | None = None) -> list[Path]:
    """Write ``count`` sampled species from ``seed`` on: into the folder ``output`` when ``folder``
    (default: when it has no extension), else as the one species file ``output``, exactly there.
    Every file of every species is one atomic set (:func:`fishgen.atomic.together`): an interrupt
    or a failure leaves none of them. ``note`` is told when texture names had to be derived, and
    ``progress`` gets 1 as each species is written."""
    from fishgen.atomic import together, write_files

    if folder is None:
        folder = not output.suffix
    if not folder:
        if count != 1 or output.suffix.lower() != ".txt":
            raise FishgenError(f"expected -o to name one species file (.txt) or a folder, found "
                               f"{output.name!r}")
        names = texture_names(output)
        check_texture_names(names)
        if note is not None and names.note is not None:
            note(names.note)
        plan: list[tuple[Path, str, TextureNames | None]] = [(output.parent, species_name(output), names)]
    else:
        if output.exists() and not output.is_dir():
            raise FishgenError("expected a folder, found a file", output)
        plan = [(output, stem, None) for stem in (f"species_{seed + k}" for k in range(count))]
        for where, stem, _ in plan:
            check_texture_names(texture_names(where / f"{stem}.txt"))
    written: list[Path] = []
    with together():
        for k, (where, stem, given) in enumerate(plan):
            files = sample_files(seed + k, stem, given)
            write_files({where / name: data for name, data in files.items()})
            written.append(where / next(iter(files)))
            if progress is not None:
                progress(1)
    return written


def species_name(species_file: Path) -> str:
    """The species' name inside its file: ASCII letters, digits and ``_`` of the file's name."""
    return ascii_name(name_text(species_file.stem), "species")
