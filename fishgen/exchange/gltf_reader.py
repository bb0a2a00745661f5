"""Read a glTF 2.0 asset (.glb / .gltf, or GLB bytes) into the scene model.

The reader parses the GLB container and the JSON itself and decodes the
accessors itself, so that alpha modes, double-sidedness, POINTS primitives
with ``_RADIUS``, skins, morph targets and every animation channel survive
(general mesh loaders drop some of them). Side files are read only from the
asset's own folder.

Everything read is checked against the glTF 2.0 rules before the scene is
built (the renderer and the posing code only ever see a well-formed scene):
indices in range, node trees without cycles or second parents, the sizes of
TRS, matrices and colour factors, accessor types and counts per semantic,
animation sampler counts, skins, morph targets and finite numbers. Declared
sizes are checked against the bytes really there, and against the caps,
before anything is read or allocated. Every fault is one ``FishgenError``
reading ``expected ..., found ...``.

This module is the entry. Each step has a module of its own, which imports
only the steps above it in this table (and ``guards``, which the OBJ/PLY
reader shares):

=====================  =====================================================
``gltf_container``     the file's bytes under the size caps, GLB chunks, the
                       JSON, and what buffers and images point to
``gltf_checks``        the document against the glTF 2.0 rules: a Document
``gltf_accessors``     a checked Document's accessors and images, decoded
``gltf_scene``         the decoded Document as a Scene
=====================  =====================================================
"""
from __future__ import annotations

from pathlib import Path

from fishgen.errors import FishgenError
from fishgen.exchange.gltf_checks import check_document
from fishgen.exchange.gltf_container import read_capped, unpack
from fishgen.exchange.gltf_scene import build_scene
from fishgen.exchange.guards import what_was_found
from fishgen.scene.model import Scene


def read_gltf(path: str | Path | None = None, *, data: bytes | None = None,
              label: str | None = None) -> Scene:
    """Load a .glb/.gltf file (or GLB ``data``) as a Scene; bad files raise FishgenError."""
    where = str(path) if path is not None else "<glb>"
    try:
        if data is None:
            if path is None:
                raise FishgenError("expected a file or GLB bytes to read, found neither")
            data = read_capped(Path(path), where)
        doc, blob = unpack(data)
        del data  # the BIN chunk is a view; a .gltf's text is no longer needed
        document = check_document(doc, blob, Path(path) if path is not None else None)
        return build_scene(document, label if label is not None else (Path(path).stem if path else ""), where)
    except FishgenError as err:
        if err.file is None:
            err.file = where
            err.args = (str(err),)
        raise
    except MemoryError:
        raise FishgenError("expected an asset that fits in memory, found it does not", where) from None
    except Exception as err:  # a fault the checks above missed: still one line, never a traceback
        raise FishgenError(f"expected a well-formed glTF 2.0 asset, found {what_was_found(err, 'glTF')}",
                           where) from None
