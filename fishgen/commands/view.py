"""`fishgen view`: write a self-contained three.js viewer page for an asset and serve it locally."""
from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import click

from fishgen.commands import QUIET, Command, Events, Inputs, Made, Output
from fishgen.options import Colour, instancing_option, option


@dataclass(frozen=True)
class ViewOptions:
    port: int = option(click.IntRange(0, 65535),
                       "Port on 127.0.0.1 to serve the page from; 0 picks a free one.",
                       8765)
    no_serve: bool = option(click.BOOL, "Only write the page (it works opened from disk "
                                        "too).", False, flag=True)
    background: tuple[int, int, int, int] = option(Colour(opaque=True),
                                                   "Background colour of the 3D view (#8cadcc, white: "
                                                   "opaque).",
                                                   (140, 173, 204, 255), shown_default="#8cadcc")
    instancing: bool = instancing_option()


PAGES = (".html", ".htm")

COMMAND = Command(
    name="view",
    summary="Open an asset in a self-contained three.js viewer page.",
    help="""Open ASSET (.glb, .gltf, .obj, .ply) in a self-contained three.js viewer.

    The page embeds three.js (bundled in fishgen, never fetched) and the asset:
    orbit with the mouse, play/pause, scrub the timeline, pick a clip, toggle
    wireframe; it shows vertex, triangle and particle counts. It is served on
    127.0.0.1 only (that one page, nothing else in its folder), until Ctrl-C.

    \b
    Examples:
      fishgen view out/bonybream.glb
      fishgen view out/school.glb --no-instancing --port 0
      fishgen view out/cloud.glb --no-serve -o out/cloud.html --background white
    """,
    options=ViewOptions,
    run="fishgen.commands.view:view",
    inputs=Inputs("ASSET", many=False),
    output=Output("Where to write the page.", required=False, metavar="PAGE",
                  shown_default="beside ASSET, as ASSET.html"),
)


def view(inputs: Sequence[Path], output: str | os.PathLike | None,
         options: ViewOptions = ViewOptions(),
         events: Events = QUIET) -> Made:
    """Write the page; unless ``no_serve``, also bind its server (the caller serves it)."""
    inputs = COMMAND.given(inputs, options)
    output = Path(output) if output is not None else None
    from fishgen.errors import FishgenError, SystemFailure
    from fishgen.viewer.page import write_page

    (asset,) = inputs
    from fishgen.atomic import protecting
    from fishgen.commands.paths import check_targets, suffix_of
    from fishgen.viewer.page import page_path

    if asset.is_dir():   # before its page's name: a folder such as `.` has none to take
        raise FishgenError("expected a file, found a directory", asset)
    page = output if output is not None else page_path(asset)
    suffix_of(page, PAGES, "a page")  # `-o -` too: a page is a file
    check_targets([page], [asset])
    colour = "#{:02x}{:02x}{:02x}".format(*options.background[:3])
    if options.no_serve:
        with protecting([asset]):
            page = Path(write_page(asset, page, colour, instancing=options.instancing))
        return Made((page,), (asset,), (f"wrote {page}",))
    from fishgen.viewer.server import make_server, url_of

    try:  # bound before the page is written: a taken port leaves no page behind
        server = make_server(page, options.port)  # that one page, never its folder
    except OSError as err:
        raise SystemFailure(f"expected a free port {options.port} on 127.0.0.1, found it taken "
                            f"({err.strerror}); try --port 0") from None
    try:
        with protecting([asset]):  # and the files it names, as they are read
            page = Path(write_page(asset, page, colour, instancing=options.instancing))
    except BaseException:
        server.server_close()
        raise
    return Made((page,), (asset,), (f"wrote {page}", f"serving {url_of(server, page)}  (Ctrl-C to stop)"),
                server=server)
