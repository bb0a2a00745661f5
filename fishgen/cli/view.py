"""`fishgen view`: write a self-contained three.js viewer page for an asset and serve it locally."""
from __future__ import annotations

import click


@click.command(context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("asset", metavar="ASSET")
@click.option("-o", "--output", default=None, metavar="PAGE",
              help="Where to write the page  [default: beside ASSET, as ASSET.html]")
@click.option("--port", type=click.IntRange(0, 65535), default=8765, show_default=True,
              help="Port on 127.0.0.1 to serve the page from; 0 picks a free one.")
@click.option("--no-serve", is_flag=True, default=False,
              help="Only write the page (it works opened from disk too).  [default: serve]")
@click.option("--background", default="#8cadcc", show_default=True, metavar="COLOUR",
              help="Background colour of the 3D view (a CSS colour).")
def view(asset, output, port, no_serve, background):
    """Open ASSET (.glb, .gltf, .obj, .ply) in a self-contained three.js viewer.

    The page embeds three.js (bundled in fishgen, never fetched) and the asset:
    orbit with the mouse, play/pause, scrub the timeline, pick a clip, toggle
    wireframe; it shows vertex, triangle and particle counts. It is served on
    127.0.0.1 only (that one page, nothing else in its folder), until Ctrl-C.
    """
    from pathlib import Path

    from fishgen.errors import FishgenError
    from fishgen.preview.pipeline import parse_background
    from fishgen.viewer.page import write_page

    rgba = parse_background(background)  # the same colour syntax as `fishgen preview`
    colour = "#{:02x}{:02x}{:02x}".format(*rgba[:3])
    page = write_page(asset, output, colour)
    click.echo(f"wrote {page}")
    if no_serve:
        return
    from fishgen.viewer.server import make_server, url_of

    try:
        server = make_server(Path(page), port)  # that one page, never its folder
    except OSError as err:
        raise FishgenError(f"expected a free port {port} on 127.0.0.1, found it taken ({err.strerror}); "
                           "try --port 0") from None
    click.echo(f"serving {url_of(server, Path(page))}  (Ctrl-C to stop)")
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
