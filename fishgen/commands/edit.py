"""`fishgen edit`: RekAwan's cloud cube editor as a local web page, writing .awn and .awa files."""
from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import click

from fishgen.clouds.lighting import Lighting
from fishgen.commands import QUIET, Command, Events, Inputs, Made
from fishgen.options import cloud_textures_option, group, option, seed_option


@dataclass(frozen=True)
class EditOptions:
    port: int = option(click.IntRange(0, 65535), "Port on 127.0.0.1 to serve the editor from; 0 picks a "
                       "free one.", 0, manifest=False)
    no_open: bool = option(click.BOOL, "Do not open the system's web browser; only print the page's "
                           "address.", False, flag=True, manifest=False)
    textures: Path | None = cloud_textures_option()
    seed: int = seed_option("The preview is filled as `fishgen clouds FILE --seed SEED` fills the file.", 0)
    lighting: Lighting = group(Lighting)


COMMAND = Command(
    name="edit",
    summary="Edit a cloud cube file (.awn, .awa) in a local web page, with a live lit preview.",
    help="""Edit FILE (.awn, or a texture cloud .awa) in RekAwan's cloud cube editor, as a web page.

    A FILE that does not exist yet starts an empty workspace; Save writes it.
    The page has the controls of RekAwan's user manual, by their names: add,
    move (handles or numbers), size and delete cubes; Preview fills and lights
    them on this machine with `fishgen clouds`' own code (Generate Billboards
    for a texture cloud); Save parses the file back before writing it
    atomically; undo and redo, duplicate, snapping.

    It serves that one page on 127.0.0.1 only, behind a random token in the
    address (the first line it prints), until Ctrl-C. Through the page it reads
    and writes only cube files in FILE's folder (no .., no absolute paths, no
    links out) and reads only textures in the texture folders.

    \b
    Examples:
      fishgen edit out/mycloud.awn
      fishgen edit params/clouds/sky.awa --sun 1,0.4,0.2
      fishgen edit params/clouds/table_4_3.awn --port 8766 --no-open
    """,
    options=EditOptions,
    run="fishgen.commands.edit:edit",
    inputs=Inputs("FILE.awn|FILE.awa", many=False),
)


def edit(inputs: Sequence[Path], output: str | os.PathLike | None = None,
         options: EditOptions = EditOptions(), events: Events = QUIET) -> Made:
    """Check FILE (a bad existing file is its one-line error), bind the editor's server and open the
    browser; the caller serves the server (``Made.server``) until Ctrl-C. The first summary line is
    the page's address."""
    inputs = COMMAND.given(inputs, options)
    from fishgen.commands.paths import check_inputs
    from fishgen.editor.session import Session
    from fishgen.errors import FishgenError, SystemFailure
    from fishgen.exchange.registry import FORMATS

    (file,) = (Path(p) for p in inputs)
    check_inputs([file], "edit", [FORMATS["cubes"], FORMATS["texture cubes"]])
    session = Session(file, textures=options.textures, lighting=options.lighting, seed=options.seed)
    if os.path.lexists(file):
        try:
            session.initial()  # a file that does not parse is refused now, in one line
        except FishgenError as err:  # the session reads the file's real path: say the one given
            if err.file is None or os.path.realpath(err.file) != os.path.realpath(file):
                raise
            raise err.naming(file) from None
        state = "editing"
    elif not session.workspace.folder.is_dir():
        raise FishgenError(f"expected an existing folder for {file.name}, found none", file.parent)
    else:
        state = "new file, empty workspace:"
    try:
        server = session.server(options.port)
    except OSError as err:
        raise SystemFailure(f"expected a free port {options.port} on 127.0.0.1, found it taken "
                            f"({err.strerror}); try --port 0") from None
    url = server.url("/")
    if not options.no_open:
        _open_browser(url)
    lines = (url, f"{state} {file}; serving until Ctrl-C")
    return Made((), (file,), lines, server=server)


def _open_browser(url: str) -> None:
    """Open ``url`` in the system's browser, off the main thread (some browsers block their caller).

    The browser is given a private file that forwards to ``url``, not ``url`` itself: a browser
    started with the address on its command line showed the token to every local user (`ps`), and
    with it the folder's cube files (QA pass 15). The file is 0600 in a 0700 folder, removed when
    fishgen exits; the browser has read it long before (Jupyter opens its pages the same way)."""
    import atexit
    import html
    import shutil
    import tempfile
    import threading
    import webbrowser

    folder = tempfile.mkdtemp(prefix="fishgen-edit-")
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    forward = Path(folder) / "open.html"
    shown = html.escape(url, quote=True)
    fd = os.open(forward, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    with os.fdopen(fd, "w", encoding="utf-8") as handle:
        handle.write(f'<!DOCTYPE html><meta charset="utf-8"><meta http-equiv="refresh" '
                     f'content="0;url={shown}"><title>fishgen edit</title>'
                     f'<a href="{shown}">Open the editor</a>\n')
    threading.Thread(target=webbrowser.open, args=(forward.as_uri(),), daemon=True).start()
