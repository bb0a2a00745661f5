"""Write the self-contained viewer page: fishgen's page (fishgen/web/page.py) with the asset in it.

Everything the page needs is inside it - three.js and the minified viewer
(app.js), built by tools/bundle_viewer.py, as inline scripts, the asset as
base64 - so it works opened from disk, served on loopback, or mailed to
someone, and never touches the network.
"""
from __future__ import annotations

import base64
import json
import re
from pathlib import Path
from urllib.parse import unquote

from fishgen.errors import FishgenError, not_a_file
from fishgen.exchange.registry import FORMATS, formats
from fishgen.exchange.sidefiles import map_file_name, mtl_libraries, side_file
from fishgen.file_names import name_text
from fishgen.viewer import MAX_EMBED_BYTES
from fishgen.web.page import page_html

KINDS = {ext: fmt.name for fmt in formats(viewer=True) for ext in fmt.extensions}
"""What three.js's loaders show, from the format registry: extension -> loader kind."""
_MTL_MAPS = re.compile(r"^\s*(?:map_\w+|bump|disp|decal|refl|norm)\s+(.+?)\s*$", re.M | re.I)


def page_path(asset: Path) -> Path:
    """Where the page goes by default: beside the asset, named after it in full."""
    return asset.with_name(asset.name + ".html")


def sidecars(asset: Path) -> tuple[dict[str, Path], str | None]:
    """Files the asset refers to (glTF buffers/images, OBJ materials and textures), and the MTL."""
    found: dict[str, Path] = {}
    mtl_name = None
    ext = asset.suffix.lower()

    def add(ref: str, uri: bool = False) -> Path | None:
        # Only files in the asset's folder: a reference to "../x" or "/etc/x" must not end up in the page.
        if ref.strip().startswith("data:"):
            return None  # inline already
        target = side_file(asset, ref, uri=uri, must_exist=True)
        key = ref.strip().replace("\\", "/")
        found[unquote(key) if uri else key] = target  # the page's loader looks files up by decoded name
        return target

    if ext == ".gltf":
        try:
            doc = json.loads(asset.read_text(encoding="utf-8"))
        except (ValueError, UnicodeDecodeError) as err:
            raise FishgenError(f"expected glTF JSON, found unreadable text ({err})", asset) from None
        if not isinstance(doc, dict):
            raise FishgenError(f"expected a glTF JSON object, found {type(doc).__name__}", asset)
        for key in ("buffers", "images"):
            items = doc.get(key, [])
            for item in items if isinstance(items, list) else []:
                if isinstance(item, dict) and isinstance(item.get("uri"), str):
                    add(item["uri"], uri=True)
    elif ext == ".obj":
        text = asset.read_text(encoding="utf-8", errors="replace")
        for line in re.findall(r"^\s*mtllib\s+(.+?)\s*$", text, re.M):
            for lib in mtl_libraries(asset, line):  # one mtllib statement may name several files
                mtl = add(lib)
                if mtl is None:
                    continue
                mtl_name = mtl_name or lib
                for ref in _MTL_MAPS.findall(mtl.read_text(encoding="utf-8", errors="replace")):
                    add(map_file_name(asset, ref))   # resolved in the asset's folder, as add() does
    return found, mtl_name


def build_page(asset: str | Path, background: str = "#8cadcc", *, instancing: bool = True) -> str:
    """The viewer page for ``asset`` as HTML text; ``instancing``: draw a school one instanced mesh per
    species and material (fishgen/web/schools.js), else fish by fish."""
    asset = Path(asset)
    kind = KINDS.get(asset.suffix.lower())
    if kind is None:
        found = asset.suffix or "no extension"       # named: the page's one input is the file at fault
        raise FishgenError(f"expected an asset ending in {', '.join(KINDS)}, found {found!r}", asset)
    if asset.is_dir():
        raise FishgenError("expected a file, found a directory", asset)
    if not asset.is_file():
        raise not_a_file("an asset file", asset)
    if asset.stat().st_size > MAX_EMBED_BYTES:  # before reading a byte of it
        raise FishgenError(f"expected at most {MAX_EMBED_BYTES >> 20} MiB to embed in a page, "
                           f"found {asset.stat().st_size / 2**20:.0f} MiB", asset)
    # Parse it as `fishgen preview` does: a truncated or garbage asset is refused, not embedded.
    FORMATS[kind].read(asset)
    extra, mtl = sidecars(asset)
    main = name_text(asset.name)      # the page names it as text, whatever the locale
    files = {main: asset, **extra}
    total = sum(p.stat().st_size for p in files.values())
    if total > MAX_EMBED_BYTES:
        raise FishgenError(f"expected at most {MAX_EMBED_BYTES >> 20} MiB to embed in a page, "
                           f"found {total / 2**20:.0f} MiB", asset)
    payload = {"main": main, "kind": kind, "mtl": mtl, "background": background,
               "instancing": instancing,
               "files": {name: base64.b64encode(p.read_bytes()).decode("ascii") for name, p in files.items()}}
    return page_html("viewer", main, ("fishgen-asset", payload))


def write_page(asset: str | Path, page: str | Path | None = None, background: str = "#8cadcc", *,
               instancing: bool = True) -> Path:
    """Write the page (atomically) and return its path."""
    from fishgen.atomic import write_bytes

    asset = Path(asset)
    out = Path(page) if page is not None else page_path(asset)
    write_bytes(out, build_page(asset, background, instancing=instancing).encode("utf-8"))
    return out
