"""The editor's server side: the routes the page calls, on fishgen's one local server.

| route | does |
|---|---|
| ``GET /`` | the page (three.js and the editor inlined) |
| ``GET /api/document`` | the file ``fishgen edit`` was given: its cubes, or none if it does not exist yet |
| ``POST /api/open`` ``{name}`` | another .awn/.awa file of the folder |
| ``POST /api/save`` ``{name, mode, cubes, stamp}`` | write, parsed back, atomically; 409 if changed since |
| ``POST /api/fill`` ``{name, mode, cubes, seed, sun}`` | fill and light them as `fishgen clouds` does |
| ``GET /api/texture?name=`` | a texture's PNG, from the allowed texture folders only |
| ``GET /api/lists`` | the folder's cube files and the textures a .awa file may use |

Every route runs behind :class:`fishgen.web.server.LocalServer`'s checks (loopback, Host, token,
body cap); bad input from the page is a :class:`~fishgen.errors.FishgenError`, which the server
answers with its one line (422). What is written and read is decided by
:class:`~fishgen.editor.workspace.Workspace`.
"""
from __future__ import annotations

import hashlib
import json
import os
import struct
import threading
import time
import warnings
from dataclasses import dataclass, field, replace
from http import HTTPStatus
from pathlib import Path
from typing import Any

from fishgen.clouds.lighting import Lighting
from fishgen.clouds.model import DEFAULT_MAX_PARTICLES, CubeFile
from fishgen.clouds.pipeline import PREVIEW_PARTICLES
from fishgen.editor.document import (
    MODES,
    PARTICLES,
    SUFFIX,
    TEXTURE,
    cube_text,
    cubes_from_json,
    document_json,
    mode_of,
    read_back,
)
from fishgen.editor.workspace import Workspace
from fishgen.errors import describe, expected
from fishgen.options import SEED_MAX
from fishgen.web.server import MAX_BODY, LocalServer, Refused, Request, Response

PREVIEW_BILLBOARDS = 20_000
"""Most billboards a texture fill for the page holds: each is three textured quads, 408 bytes of GLB.
(A particle fill holds at most PREVIEW_PARTICLES, as `fishgen preview`'s.) A bigger cloud is previewed
with every cube's count scaled down alike, and the page says so."""
MAX_REQUEST = MAX_BODY
"""Largest request body (16 MiB): a cube file is at most 16 MiB and 100,000 cubes."""


@dataclass
class Session:
    """One `fishgen edit` run: the file, the folder's rules, and the light and seed it fills with."""

    file: Path
    textures: Path | None = None
    lighting: Lighting = field(default_factory=Lighting)
    seed: int = 0
    max_particles: int = DEFAULT_MAX_PARTICLES
    workspace: Workspace = field(init=False)
    _fill_lock: threading.Lock = field(init=False, default_factory=threading.Lock)
    _save_lock: threading.Lock = field(init=False, default_factory=threading.Lock)

    def __post_init__(self) -> None:
        self.file = Path(self.file)
        self.workspace = Workspace(self.file, self.textures)

    # -- the server ---------------------------------------------------------------------------------
    def routes(self) -> dict[tuple[str, str], Any]:
        return {("GET", "/"): self.page, ("GET", "/api/document"): self.document,
                ("POST", "/api/open"): self.open, ("POST", "/api/save"): self.save,
                ("POST", "/api/fill"): self.fill, ("GET", "/api/texture"): self.texture,
                ("GET", "/api/lists"): self.lists}

    def server(self, port: int = 0) -> LocalServer:
        """The bound server (the caller serves it until Ctrl-C); OSError if the port is taken."""
        return LocalServer(self.routes(), port, max_body=MAX_REQUEST)

    # -- routes -------------------------------------------------------------------------------------
    def page(self, request: Request) -> Response:
        from fishgen.editor.page import build_page

        return Response.of_html(build_page(self.workspace.name))

    def document(self, request: Request) -> Response:
        return Response.of_json(self.initial())

    def open(self, request: Request) -> Response:
        return Response.of_json(self.opened(_member(request.json(), "name")))

    def initial(self) -> dict[str, Any]:
        """The given file as the page starts with it: its cubes, or an empty workspace if it does
        not exist yet (a file that does not parse is its one-line error)."""
        ws = self.workspace
        if not os.path.lexists(ws.given):
            return {"name": ws.name, "exists": False, "mode": mode_of(ws.name), "cubes": [], "warnings": [],
                    "stamp": None, **self._settings(), **self._lists(ws.given)}
        return self.opened(ws.name)

    def opened(self, name: object) -> dict[str, Any]:
        """Cube file ``name`` of the folder as the page holds it, with the parser's warnings."""
        from fishgen.clouds.parser import CubeFileWarning, load_cubes

        path = self.workspace.cube_file(name, must_exist=True)
        shown = str(name)
        stamp = _stamp(path)    # before the read: a change made during it is caught at the save
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", CubeFileWarning)  # the file keeps them: they go to the page
            cubes = load_cubes(path, max_particles=self.max_particles, textures_dir=self.textures)
        doc = document_json(cubes, self.workspace.roots(path))
        doc["warnings"] = [w.replace(str(path), shown, 1) for w in doc["warnings"]]
        return {"name": shown, "exists": True, "stamp": stamp, **doc, **self._settings(),
                **self._lists(path)}

    def save(self, request: Request) -> Response:
        """Write the page's cubes under ``name``: checked, parsed back, then written atomically.
        A file that would not parse is never written; the page gets the parser's one line."""
        from fishgen.atomic import write_bytes

        body = request.json()
        name, mode = _member(body, "name"), _mode(body)
        path = self.workspace.cube_file(name, must_exist=False)
        if Path(str(name)).suffix.lower() != SUFFIX[mode]:
            what = "a texture cloud" if mode == TEXTURE else "a particle cloud"
            raise expected(f"a name ending in {SUFFIX[mode]} for {what}", describe(str(name)))
        cubes = cubes_from_json(_member(body, "cubes"))
        text = cube_text(cubes, mode, str(name))
        parsed = read_back(text, mode, str(name), cubes, roots=self.workspace.roots(path),
                           max_particles=self.max_particles)
        data = text.encode("utf-8")
        with self._save_lock:
            # the page says which bytes it read (or last wrote) under this name: another program's
            # change since is refused, not overwritten (QA pass 15: it was lost without a word)
            found = _stamp(path)
            if "stamp" in body and found != body["stamp"]:
                raise Refused(HTTPStatus.CONFLICT, _conflict(str(name), body["stamp"], found))
            write_bytes(path, data)
        return Response.of_json({"saved": name, "particles": parsed.total, "cubes": len(parsed.cubes),
                                 "bytes": len(data), "stamp": _digest(data),
                                 **self._lists(path)})

    def fill(self, request: Request) -> Response:
        """The page's cubes filled and lit as `fishgen clouds NAME --seed SEED --sun SUN` fills and
        lights that file, as GLB (points, or a texture cloud's billboards), after a little JSON:
        ``[uint32 little-endian length][JSON: particles, cubes, ms, note][GLB]``."""
        body = request.json()
        started = time.perf_counter()
        name, mode = _member(body, "name"), _mode(body)
        path = self.workspace.cube_file(name, must_exist=False)
        cubes = cubes_from_json(_member(body, "cubes"))
        seed = body.get("seed", self.seed)
        if type(seed) is not int or not 0 <= seed <= SEED_MAX:
            raise expected(f"a seed from 0 to {SEED_MAX}", describe(repr(seed)))
        lighting = self.lighting
        if body.get("sun") is not None:
            sun = body["sun"]
            if not isinstance(sun, list) or len(sun) != 3 or any(type(v) not in (int, float) for v in sun):
                raise expected("the sun as three numbers", describe(repr(sun)))
            lighting = replace(lighting, sun=(float(sun[0]), float(sun[1]), float(sun[2])))
        text = cube_text(cubes, mode, str(name))
        parsed = read_back(text, mode, str(name), cubes, roots=self.workspace.roots(path),
                           max_particles=self.max_particles)
        with self._fill_lock:
            glb, facts = fill_glb(parsed, mode, seed, lighting)
        facts["ms"] = round((time.perf_counter() - started) * 1000, 1)
        meta = json.dumps(facts).encode("utf-8")
        return Response(200, struct.pack("<I", len(meta)) + meta + glb, "application/octet-stream")

    def texture(self, request: Request) -> Response:
        return Response(200, self.workspace.texture(request.query.get("name")), "image/png")

    def lists(self, request: Request) -> Response:
        return Response.of_json(self._lists(self.workspace.given))

    # -- helpers ------------------------------------------------------------------------------------
    def _lists(self, path: Path) -> dict[str, Any]:
        return {"files": self.workspace.cube_files(), "textures": self.workspace.texture_names(path)}

    def _settings(self) -> dict[str, Any]:
        return {"folder": _shown(self.workspace.folder), "seed": self.seed,
                "light": self.lighting.extras(), "sun": list(self.lighting.sun),
                "limits": {"particles": PREVIEW_PARTICLES, "billboards": PREVIEW_BILLBOARDS}}


def fill_glb(cube_file: CubeFile, mode: str, seed: int, lighting: Lighting) -> tuple[bytes, dict[str, Any]]:
    """Fill and light ``cube_file`` as `fishgen clouds` does (one input: seed ``seed``), as the GLB
    `fishgen clouds -o x.glb` would hold (points; billboards for a texture cloud), and its facts.
    Above the preview's limits every cube's count is scaled down alike, and ``note`` says so."""
    from fishgen.clouds.pipeline import cube_clouds
    from fishgen.clouds.scene import cloud_scene
    from fishgen.exchange.gltf import glb_bytes

    most = PREVIEW_BILLBOARDS if mode == TEXTURE else PREVIEW_PARTICLES
    made = cube_clouds([cube_file], seed=seed, most=most, lighting=lighting)
    glb = glb_bytes(cloud_scene(made.cloud, billboards=mode == TEXTURE, name="cloud"))
    note = made.note and f"{made.note}, every cube scaled alike"
    return glb, {"particles": made.particles, "whole": made.whole, "cubes": len(cube_file.cubes),
                 "note": note, "seed": seed, "mode": mode}


def _conflict(name: str, expected: str | None, found: str | None) -> str:
    """Why a save was refused: the file is not as the page last saw it."""
    if expected is None:     # a name the page saw free (a new file, or another than the one open)
        return f"expected no file {name} (this page saw none), found one made since; Save again to replace it"
    if found is None:
        return (f"expected {name} as this page read it, found it removed since (by another program or "
                "another page of this editor); Save again to write it anew")
    return (f"expected {name} as this page read it, found it changed on disk since (by another program or "
            "another page of this editor); open it again, save under another name, or Save again to "
            "replace it")


def _stamp(path: Path) -> str | None:
    """The file's :func:`_digest`, or None where there is none."""
    try:
        return _digest(path.read_bytes())
    except (FileNotFoundError, NotADirectoryError):
        return None


def _digest(data: bytes) -> str:
    """What the page sends back with a save: the SHA-256 of the bytes it read or last wrote."""
    return hashlib.sha256(data).hexdigest()


def _shown(folder: Path) -> str:
    """A folder as the page names it: relative to where fishgen runs when below it, else whole (the
    page said "In ." of the folder it runs in)."""
    here = Path.cwd().resolve()
    inside = folder.is_relative_to(here) and folder != here
    return folder.relative_to(here).as_posix() if inside else str(folder)


def _member(body: Any, key: str) -> Any:
    if not isinstance(body, dict) or key not in body:
        raise expected(f"a JSON object with {key!r}", describe(repr(body)))
    return body[key]


def _mode(body: Any) -> str:
    mode = _member(body, "mode")
    if mode not in MODES:
        raise expected(f"the system as {PARTICLES!r} or {TEXTURE!r}", describe(repr(mode)))
    return str(mode)

