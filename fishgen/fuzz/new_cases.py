"""Issue 26's targets: how a case is generated and run (the judging is :mod:`fishgen.fuzz.verdict`').

| target   | runs |
|----------|------|
| scene    | ``load_scene_file`` on a mutated scene TOML (species files beside it) |
| paths    | ``load_scene_file`` on a scene whose [target]/[predator] read a mutated path CSV |
| manifest | ``load_manifest`` on a mutated batch manifest |
| fxl      | ``parse_fxl`` on a mutated .FXL file |
| photo    | ``fishgen texture PHOTO -s BASE.txt`` (the CLI, in-process) on a generated photo |
| awa      | ``load_cubes`` on a mutated .awa file in the shipped layout, then a fill when small |
| editor   | raw HTTP requests to the editor's routes behind a LocalServer, handled in-process |
| options  | ``fishgen sky/fly/build`` with mutated options (the CLI, in-process; fly never serves) |
"""

from __future__ import annotations

import contextlib
import os
import random
import socket
import threading
from pathlib import Path

from fishgen.fuzz import structured
from fishgen.fuzz.cli_run import run_cli
from fishgen.fuzz.inputs import Case, Seeds, fresh_folder, write_files
from fishgen.fuzz.verdict import Outcome, classify, innermost_fishgen_frame


def make_new_case(seeds: Seeds, target: str, rng: random.Random, index: int, verbatim: bool) -> Case:
    new = seeds.new
    if target in ("scene", "paths"):
        files: dict[str, bytes | int] = {k: v for k, v in new["scene"].items() if k.endswith(".txt")}
        scenes = seeds.texts("scene", ".toml")
        if target == "scene":
            text = scenes[index] if verbatim else structured.scene_text(scenes, rng)
            files["scene.toml"] = text.encode("utf-8", "surrogatepass")
            files["path.csv"] = new["scene"]["path.csv"]
        else:
            full = new["scene"]["full.toml"].decode()
            if not verbatim and rng.random() < 0.3:
                full = full.replace('path = "figure8"', 'path = "path.csv"')
            files["scene.toml"] = full.encode()
            files["path.csv"] = new["scene"]["path.csv"] if verbatim else structured.path_csv(rng)
        return Case(target, index, files=files, main="scene.toml")
    if target == "manifest":
        manifests = seeds.texts("manifest", ".toml")
        text = manifests[index] if verbatim else structured.manifest_text(manifests, rng)
        return Case(
            target, index, files={"assets.toml": text.encode("utf-8", "surrogatepass")}, main="assets.toml"
        )
    if target == "fxl":
        texts = seeds.texts("fxl", ".fxl")
        return Case(target, index, text=texts[index] if verbatim else structured.fxl_text(texts, rng))
    if target == "photo":
        from fishgen.fuzz.cli_gen import texture_case

        files, argv = texture_case(seeds, rng)
        return Case(target, index, files=files, argv=argv)
    if target == "awa":
        data = new["awa"]["sky.awa"]
        return Case(
            target,
            index,
            files={"sky.awa": data if verbatim else structured.awa_bytes([data], rng)},
            main="sky.awa",
        )
    if target == "editor":
        files = {
            "sky.awa": new["awa"]["sky.awa"],
            "small.awn": new["awa"]["small.awn"],
            "bad.awn": b"3\n1\n1, 2, 3\n",
        }
        return Case(
            target,
            index,
            files=files,
            requests=structured.editor_requests(_edit_cubes(seeds), rng),
            main=rng.choice(["sky.awa", "small.awn", "new.awn", "new.awa", "bad.awn"]),
        )
    if target == "options":
        from fishgen.fuzz.cli_gen import options_case

        files, argv = options_case(seeds, rng)
        return Case(target, index, files=files, argv=argv)
    raise ValueError(f"unknown target {target!r}")


_CUBES: dict[str, list[dict]] = {}


def _edit_cubes(seeds: Seeds) -> dict[str, list[dict]]:
    """The seed files' cubes as the page sends them (``/api/save`` and ``/api/fill`` bodies)."""
    if not _CUBES:
        for mode, name in (("particles", "small.awn"), ("texture", "sky.awa")):
            rows = seeds.new["awa"][name].decode().splitlines()[2:]
            cubes = []
            for row in rows:
                cells = [c.strip() for c in row.replace(",", " , ").replace(" , ", ",").split(",")]
                cells = [c for c in ",".join(cells).replace(" ", ",").split(",") if c]
                values = [float(c) for c in cells[:8]]
                cubes.append(
                    {
                        "particles": int(values[0]),
                        "size": values[1:4],
                        "centre": values[4:7],
                        "radius": values[7],
                        "texture": cells[8] if len(cells) > 8 else None,
                    }
                )
            _CUBES[mode] = cubes
    return _CUBES


# -- running -----------------------------------------------------------------------------------------
def run_new_case(case: Case, workdir: Path) -> Outcome:
    if case.target in ("scene", "paths"):
        from fishgen.school.scene_file import load_scene_file

        folder = fresh_folder(workdir)
        write_files(folder, case.files)
        load_scene_file(folder / case.main)
        return Outcome("ok")
    if case.target == "manifest":
        from fishgen.batch.manifest import load_manifest
        from fishgen.commands.batch import job_kinds

        folder = fresh_folder(workdir)
        write_files(folder, case.files)
        load_manifest(folder / case.main, kinds=job_kinds())
        return Outcome("ok")
    if case.target == "fxl":
        from fishgen.authoring.photo.fxl import parse_fxl

        parse_fxl(case.text or "", "<fuzz>.FXL")
        return Outcome("ok")
    if case.target == "awa":
        return _run_awa(case, workdir)
    if case.target == "editor":
        return _run_editor(case, workdir)
    return run_cli(case, workdir)


def _awa_layout(folder: Path, files: dict[str, bytes | int]) -> None:
    """The shipped layout: params/clouds/X.awa, textures/clouds/*.png two folders up, plus a folder
    named like a texture and a link to a file outside (both must be refused)."""
    clouds = folder / "params" / "clouds"
    textures = folder / "textures" / "clouds"
    clouds.mkdir(parents=True)
    textures.mkdir(parents=True)
    for name, data in files.items():
        target = textures if name.endswith(".png") else clouds
        write_files(target, {name: data})
    (textures / "dir.png").mkdir()
    (folder / "outside.png").write_bytes(b"not a texture")
    os.symlink(folder / "outside.png", textures / "link.png")


def _run_awa(case: Case, workdir: Path) -> Outcome:
    import warnings

    import numpy as np

    from fishgen.clouds.fill import fill_cloud
    from fishgen.clouds.parser import load_cubes

    folder = fresh_folder(workdir)
    _awa_layout(folder, {**_awa_textures(), **case.files})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cubes = load_cubes(folder / "params" / "clouds" / case.main, max_particles=10_000_000)
    if cubes.total <= 2000:
        cloud = fill_cloud(cubes, seed=case.index)
        for name in ("centers", "radii", "density"):
            values = getattr(cloud, name, None)
            if values is not None and not np.isfinite(np.asarray(values, float)).all():
                return Outcome("finding", f"non-finite cloud {name} from a .awa file's fill", "")
    return Outcome("ok")


def _awa_textures() -> dict[str, bytes | int]:
    from fishgen.fuzz.mutate import png_bytes

    return {f"{n}.png": png_bytes(8, 8) for n in ("billow", "cumulus", "wisp")}


# -- the editor --------------------------------------------------------------------------------------
TOKEN = "fuzz-token-0123456789abcdef"
SLOW = b"SLOW"


def _snapshot(root: Path, skip: Path) -> dict[str, tuple[int, int]]:
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        here = Path(dirpath)
        if here == skip or skip in here.parents:
            dirnames[:] = []
            continue
        for n in dirnames:  # a folder's own mtime changes when the editor writes inside it
            out[str(here / n)] = (0, 0)
        for n in filenames:
            try:
                st = (here / n).lstat()
            except OSError:
                continue
            out[str(here / n)] = (st.st_size, st.st_mtime_ns)
    return out


def _run_editor(case: Case, workdir: Path) -> Outcome:
    """Each request on its own connection to a LocalServer's handler, run in this thread: an exception
    escaping the handler (which the real server would swallow, dropping the connection) is a finding,
    as is a 5xx answer or any file written outside the editor's folder."""
    from fishgen.editor.session import MAX_REQUEST, Session
    from fishgen.web.server import LocalServer, _Handler

    folder = fresh_folder(workdir)
    edit = folder / "edit"
    edit.mkdir()
    outside = folder / "outside"
    outside.mkdir()
    write_files(edit, case.files)
    textures = folder / "textures" / "clouds"
    textures.mkdir(parents=True)
    write_files(textures, _awa_textures())
    os.symlink(folder / "secret.awn", edit / "link.awn")
    (folder / "secret.awn").write_bytes(b"60\n1\n60, 1, 1, 1, 0, 0, 0, 1\n")
    with contextlib.suppress(OSError):
        os.mkfifo(edit / "fifo.awn")
    before = _snapshot(workdir, edit)
    session = Session(edit / case.main)
    server = LocalServer(session.routes(), 0, max_body=MAX_REQUEST, token=TOKEN, timeout=0.2)
    try:
        for k, raw in enumerate(case.requests):
            data = (
                raw.replace(b"{PORT}", str(server.port).encode())
                .replace(b"{TOKEN}", TOKEN.encode())
                .replace(b"{OUTSIDE}", str(outside).encode())
            )
            answer, err = _exchange(server, _Handler, data)
            if err is None and server.bugs:     # answered with a 500: where it was raised is the finding
                err = server.bugs.pop()
            if err is not None:
                where = innermost_fishgen_frame(err.__traceback__)

                judged = classify(err)
                key = (
                    judged.key
                    if judged.key.startswith(("budget", "RecursionError"))
                    else f"editor: {type(err).__name__} escaped the handler at {where}"
                )
                return Outcome("finding", key, f"request {k}: {data[:300]!r}\n"
                               f"{judged.detail if judged.status == 'finding' else repr(err)}")
            status = _status(answer)
            if status >= 500 and not _protocol_answer(status, data):
                return Outcome(
                    "finding",
                    f"editor: {status} answer to {_route_of(data)}",
                    f"request {k}: {data[:300]!r}\n{answer[:500]!r}",
                )
    finally:
        server.server_close()
    after = _snapshot(workdir, edit)
    changed = sorted(p for p, st in after.items() if before.get(p) != st)
    if changed:
        return Outcome(
            "finding",
            "editor: a file written outside the editor's folder",
            f"{changed[:5]} after {[r[:200] for r in case.requests]}",
        )
    return Outcome("ok")


def _exchange(server, handler_class, data: bytes) -> tuple[bytes, BaseException | None]:
    client, conn = socket.socketpair()
    received: list[bytes] = []
    slow = data.startswith(SLOW)
    payload = data[len(SLOW) :] if slow else data

    def talk() -> None:
        try:
            client.sendall(payload)
            if not slow:
                client.shutdown(socket.SHUT_WR)
        except OSError:
            pass
        try:
            while chunk := client.recv(1 << 16):
                received.append(chunk)
        except OSError:
            pass

    thread = threading.Thread(target=talk, daemon=True)
    thread.start()
    error: BaseException | None = None
    try:
        handler_class(conn, ("127.0.0.1", 40000), server)
    except Exception as err:  # the point: what escapes the handler
        error = err
    finally:
        with contextlib.suppress(OSError):
            conn.shutdown(socket.SHUT_RDWR)
        conn.close()
        thread.join(5)
        client.close()
    return b"".join(received), error


def _status(answer: bytes) -> int:
    parts = answer.split(b" ", 2)
    if len(parts) >= 2 and parts[0].startswith(b"HTTP/") and parts[1].isdigit():
        return int(parts[1])
    return 0


def _protocol_answer(status: int, data: bytes) -> bool:
    """http.server's own correct answers: 501 to a method it has no handler for, 505 to an HTTP
    version it does not speak. Not fishgen's 5xx."""
    words = data.split(b"\r\n", 1)[0].split()
    method = words[0].decode("latin-1") if words else ""
    version = words[-1] if len(words) == 3 else b""
    if status == 501 and method not in ("GET", "HEAD", "POST", "PUT", "DELETE"):
        return True
    return status == 505 and version not in (b"HTTP/1.0", b"HTTP/1.1")


def _route_of(data: bytes) -> str:
    words = data.split(b"\r\n", 1)[0].split()
    return " ".join(w.decode("latin-1")[:40].split("?")[0] for w in words[:2])
