"""`fishgen build`: species files -> textured, fin-animated fish assets."""
from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import click

from fishgen.assembly.fish_options import FishOptions
from fishgen.commands import QUIET, Command, Events, Inputs, Made, Output, each_input
from fishgen.errors import either, plural
from fishgen.exchange.registry import MESHES, extensions, formats
from fishgen.options import option, textures_option

FISH_FORMATS = formats(writable=True, holding=[MESHES])


@dataclass(frozen=True)
class BuildOptions(FishOptions):
    """How each fish is built (:class:`FishOptions`, checked when made), and where its files go."""

    # None: not given, so that one given with -o naming a file of another format can be refused
    format: str | None = option(click.Choice([f.name for f in FISH_FORMATS]), "Format of each file written "
                                "into a folder (-o FOLDER/).", shown_default="glb", manifest=False)
    textures: Path | None = textures_option("the species file's folder, then the textures/ folder beside "
                                            "that folder")


def check_options(options: BuildOptions, output: str | os.PathLike | None = None) -> None:
    """Options that would be ignored, refused before any work (and at a manifest job's line)."""
    from fishgen.errors import UsageError

    if options.speed is not None and options.swim == "fins":
        raise UsageError(f"expected --swim body with --speed (it sets the body wave's tail beat, which "
                         f"--swim fins does not have), found --swim fins with --speed {options.speed:g}")
    if options.format is not None and output is not None:
        from fishgen.commands.paths import names_folder
        from fishgen.exchange.registry import FORMATS

        suffix = Path(output).suffix.lower()
        if not names_folder(output) and suffix not in FORMATS[options.format].extensions:
            raise UsageError(f"expected --format with -o naming a folder, or a file of that format's "
                             f"extension (a file's extension picks its format), found -o "
                             f"{os.fspath(output)!r} with --format {options.format}")


COMMAND = Command(
    name="build",
    summary="Build a species file into a textured, fin-animated fish asset.",
    help="""Build SPECIES_FILE (VRFish parameter files) into game-ready fish.

    glTF and USD outputs carry the node hierarchy, materials, textures and a
    looping `swim` clip (USD needs pip install 'fishgen[usd]'); OBJ and PLY
    carry the rest pose. Axes: +Y up, head towards +Z,
    metres. Outputs are written atomically: a failed run leaves no file. With
    several species every good file is built, each bad one is reported on its
    own line, and the exit status is non-zero if any failed.

    \b
    Examples:
      fishgen build params/bonybream.txt -o out/bonybream.glb
      fishgen build params/*.txt -o out/fish/ --format gltf
    """,
    options=BuildOptions,
    run="fishgen.commands.build:build",
    inputs=Inputs("SPECIES_FILE..."),
    output=Output(f"Output file for one species (its extension picks the format: "
                  f"{', '.join(extensions(FISH_FORMATS))}), or a folder: an existing one, or a name "
                  "ending in /.", required=False, shown_default="out/<species file stem>.<format>",
                  holds=(MESHES,), folder=True),
    batch=True,
    check=check_options,
)


def build(inputs: Sequence[Path], output: str | os.PathLike | None,
          options: BuildOptions = BuildOptions(),
          events: Events = QUIET) -> Made:
    """Build each species file into a fish asset; with several inputs, a bad one is reported
    through ``events.failed`` and the others are built."""
    inputs = COMMAND.given(inputs, options)
    from fishgen.assembly.fish import fish_of
    from fishgen.atomic import protecting
    from fishgen.commands.paths import check_inputs, check_targets, targets
    from fishgen.exchange import export
    from fishgen.exchange.registry import FORMATS
    from fishgen.species.parser import load_species

    check_options(options, output)
    check_inputs(inputs, "build", [FORMATS["species"]], default=FORMATS["species"])
    outputs = targets(inputs, output, fmt=options.format or "glb", holding=[MESHES], noun="species file")
    check_targets(outputs, inputs)
    loaded = _loadable(inputs, options.textures) if len(inputs) > 1 else {}
    textures = tuple(dict.fromkeys(path for species in loaded.values() for path in species.side_files))
    written: list[Path] = []
    read: list[Path] = []
    lines: list[str] = []
    facts = []
    errors: list = []
    # a bar for several inputs: `fishgen build params/*.txt` of hundreds of species takes minutes
    with events.progress("building", len(inputs) if len(inputs) > 1 else 0) as progress:
        for source, target in zip(inputs, outputs, strict=True):
            with each_input(events, errors, len(inputs) > 1):
                species = loaded.get(source) or load_species(source, options.textures)
                fish = fish_of(species, options)
                # every input's textures are inputs (b.txt may name a_skin.png, which a.glb writes),
                # and only the side files of the images the fish holds count
                theirs = (*species.side_files, *textures)
                check_targets([target], theirs, [image.name for image in fish.scene.images])
                with protecting(theirs):
                    files = export(fish.scene, target, require=[MESHES])
                read += [source, *species.side_files]
                written += files
                facts.append(fish.facts)
                lines.append(summary(fish, target, files))
            progress.update(1)
    return Made(tuple(written), tuple(read), tuple(lines), tuple(facts), tuple(errors))


def _loadable(inputs: Sequence[Path], folder: Path | None) -> dict:
    """Every input that loads, by path, read once before any is built: each one's textures are then
    known to all (an unreadable input is loaded again, and reported, when its turn comes)."""
    from fishgen.errors import FishgenError
    from fishgen.species.parser import load_species

    found = {}
    for source in inputs:
        try:
            found[source] = load_species(source, folder)
        except (FishgenError, OSError):
            continue
    return found


def _lost(fins: tuple[str, ...]) -> str:
    """``; no anal or adipose fin``: the fins a level is too coarse to hold, said where it is listed."""
    if not fins:
        return ""
    names = [name.removesuffix("_fin").replace("_fin_", " ").replace("_", " ") for name in fins]
    kinds = list(dict.fromkeys(n.split(" ")[0] for n in names))     # a pair is named once
    return f"; no {either(kinds)} fin" + "s" * (len(names) > 1)


def summary(fish, target: Path, written: list[Path]) -> str:
    """One line: what was built, and what the format could not keep (said once)."""
    from fishgen.exchange.registry import by_extension, lost

    scene, facts = fish.scene, fish.facts
    fmt = by_extension(target)
    dropped = lost(fmt, scene) if fmt is not None else []
    animated = bool(facts.clips) and "node animation" not in dropped
    motion = (f"swim loop {facts.clip_seconds:.2f} s" if animated and facts.clip_seconds is not None
              else "rest pose only" if facts.clips else "no animation")
    if animated and facts.tail_beat_hz is not None:
        motion += f", body wave {facts.tail_beat_hz:.2f} Hz"
        if facts.capped_hz is not None:   # a faster --speed would give the same file
            motion += f" (--speed {facts.speed:g} capped at {facts.capped_hz:g} Hz)"
    others = [c for c in facts.clips if c.name != "swim"]
    if animated and others and "more than one clip" not in dropped:
        motion += ", clips " + ", ".join(f"{c.name} {c.seconds:.2f} s" for c in others)
    if len(facts.levels) > 1 and fmt is not None and fmt.name in ("glb", "gltf"):
        motion += ", levels " + ", ".join(f"{lv.bodies}x{lv.circles} ({lv.triangles}{_lost(lv.missing)})"
                                          for lv in facts.levels)
    elif facts.levels and facts.levels[0].missing:   # the one level written: `--lods 8x6` too
        level = facts.levels[0]
        motion += f", {level.bodies}x{level.circles} ({_lost(level.missing).removeprefix('; ')})"
    if facts.merged:
        motion += f", merged ({facts.draw_calls} draw calls)"
    note = f" ({fmt.extensions[0][1:].upper()} holds no {either(dropped)})" if dropped and fmt else ""
    return (f"{target}: {scene.name}, {scene.counts()['triangles']} triangles, "
            f"{facts.body_length:.3f} m long, fins {facts.fin_mode}, {motion}{note}"
            + (f" (+{plural(len(written) - 1, 'file')})" if len(written) > 1 else ""))
