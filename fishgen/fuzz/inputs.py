"""What a fuzz case is: its input files, the seed corpus they grow from, and the folder a case
writes them into.

The seed corpus ships inside the package (``fishgen/fuzz/seeds/``, package data), so an
installed fishgen fuzzes itself: ``python -m fishgen.fuzz`` needs no source tree.
"""
from __future__ import annotations

import json
import random
import shutil
from dataclasses import dataclass, field
from pathlib import Path

#: The seed corpus shipped with the package; ``python -m fishgen.fuzz.corpus`` remakes it.
DEFAULT_CORPUS = Path(__file__).resolve().parent / "seeds"


@dataclass
class Case:
    target: str
    index: int
    text: str | None = None                 # species
    data: bytes | None = None               # cubes
    files: dict[str, bytes | int] = field(default_factory=dict)  # readers/CLI: name -> bytes or sparse size
    main: str = ""                          # readers: the file load_input opens
    argv: list[str] = field(default_factory=list)  # CLI
    requests: list[bytes] = field(default_factory=list)  # editor: raw HTTP requests, one connection each

    def save(self, folder: Path) -> list[Path]:
        """Write this case's input(s) into ``folder`` (made); returns the paths written."""
        folder.mkdir(parents=True, exist_ok=True)
        written = []
        if self.text is not None:
            p = folder / "input.txt"
            p.write_bytes(self.text.encode("utf-8", "surrogatepass"))
            written.append(p)
        if self.data is not None:
            p = folder / "input.awn"
            p.write_bytes(self.data)
            written.append(p)
        written += write_files(folder, self.files)
        if self.argv:
            p = folder / "argv.json"
            p.write_text(json.dumps(self.argv) + "\n")
            written.append(p)
        for k, request in enumerate(self.requests):
            p = folder / f"request-{k}.http"
            p.write_bytes(request)
            written.append(p)
        return written


def write_files(folder: Path, files: dict[str, bytes | int]) -> list[Path]:
    out = []
    for name, content in files.items():
        if not name or name in (".", "..") or "/" in name or "\\" in name or "\0" in name:
            continue  # a mutated reference such as "../x.png" names no file the case may write
        p = folder / name
        p.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, int):  # a sparse file of this many bytes: huge, but no disk
            with open(p, "wb") as f:
                f.truncate(content)
        else:
            p.write_bytes(content)
        out.append(p)
    return out


@dataclass
class Seeds:
    species: list[str]
    cubes: list[bytes]
    assets: dict[str, list[tuple[str, dict[str, bytes | int]]]]  # target -> [(main, files)]
    new: dict[str, dict[str, bytes]] = field(default_factory=dict)  # issue 26's: folder -> {name: bytes}

    def texts(self, folder: str, suffix: str) -> list[str]:
        return [v.decode("utf-8") for k, v in sorted(self.new[folder].items()) if k.endswith(suffix)]

    def count(self, target: str) -> int:
        if target == "species":
            return len(self.species)
        if target == "cubes":
            return len(self.cubes)
        if target in ("cli", "options", "editor", "photo"):
            return 0
        if target in ("scene", "manifest"):
            return len(self.texts(target, ".toml"))
        if target == "paths":
            return 1
        if target == "fxl":
            return len(self.texts("fxl", ".fxl"))
        if target == "awa":
            return 1
        return len(self.assets[target])


def load_seeds(corpus: Path = DEFAULT_CORPUS) -> Seeds:
    species = [p.read_bytes().decode("utf-8") for p in sorted((corpus / "species").glob("*.txt"))]
    cubes = [p.read_bytes() for p in sorted((corpus / "cubes").glob("*.awn"))]
    assets: dict[str, list[tuple[str, dict[str, bytes | int]]]] = {}
    for target, exts in (("gltf", (".glb", ".gltf")), ("obj", (".obj",)), ("ply", (".ply",))):
        assets[target] = []
        for folder in sorted(p for p in (corpus / target).iterdir() if p.is_dir()):
            files: dict[str, bytes | int] = {p.name: p.read_bytes() for p in sorted(folder.iterdir())
                                             if p.is_file()}
            mains = [n for n in files if n.endswith(exts)]
            if len(mains) != 1:
                raise ValueError(f"{folder}: expected one {'/'.join(exts)} file, found {mains}")
            assets[target].append((mains[0], files))
    new = {sub: {p.name: p.read_bytes() for p in sorted((corpus / sub).iterdir()) if p.is_file()}
           for sub in ("scene", "manifest", "fxl", "photo", "awa") if (corpus / sub).is_dir()}
    if not species or not cubes or not all(assets.values()) or len(new) != 5 or not all(new.values()):
        raise ValueError(f"{corpus}: incomplete seed corpus")
    return Seeds(species, cubes, assets, new)


def case_rng(seed: int, target: str, index: int) -> random.Random:
    return random.Random(f"{seed}:{target}:{index}")


def fresh_folder(workdir: Path) -> Path:
    """An empty ``case`` folder in ``workdir`` (the previous case's removed)."""
    case_dir = workdir / "case"
    if case_dir.exists():
        shutil.rmtree(case_dir)
    case_dir.mkdir(parents=True)
    return case_dir
