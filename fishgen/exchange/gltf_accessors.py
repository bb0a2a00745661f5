"""Accessor decoding: the bytes a checked glTF document points to, as numpy arrays.

Only a :class:`~fishgen.exchange.gltf_checks.Document` is decoded, so every index, offset,
stride and count is already known to fit the bytes there. What only the bytes can tell is
checked here: non-finite floats, sparse indices past the accessor, a side file that changed
size since it was checked, broken base64, and each base colour texture's picture.
"""
from __future__ import annotations

from typing import cast

import numpy as np

from fishgen.errors import describe, expected
from fishgen.exchange.gltf_checks import COMPONENT_DTYPES, TYPE_WIDTHS, Document, item_name
from fishgen.exchange.gltf_container import data_uri, side_path
from fishgen.exchange.guards import check_picture


class Decoder:
    """Decodes accessors and images of one checked document; each buffer is read once."""

    def __init__(self, document: Document):
        self.document = document
        self.lists = document.lists
        self._buffers: dict[int, bytes | memoryview] = {}

    def buffer(self, i: int) -> bytes | memoryview:
        """Buffer ``i``'s bytes: the GLB's BIN chunk, a side file or a data: URI."""
        if i not in self._buffers:
            buf = self.lists["buffers"][i]
            where = f"buffers[{i}]"
            if buf.get("uri") is None:
                data: bytes | memoryview = cast(memoryview, self.document.blob)
            elif i in self.document.files:
                data = self.document.files[i].read_bytes()
                if len(data) != buf["byteLength"]:  # changed since the check
                    raise expected(f"{buf['byteLength']:,} bytes in {describe(buf['uri'])}", f"{len(data):,}")
            else:
                data = data_uri(buf["uri"], where)
                if len(data) != buf["byteLength"]:
                    raise expected(f"{buf['byteLength']:,} bytes in the data URI of {where}",
                                   f"{len(data):,}")
            self._buffers[i] = data
        return self._buffers[i]

    def _view(self, i: int) -> tuple[bytes | memoryview, int]:
        view = self.lists["bufferViews"][i]
        return self.buffer(view["buffer"]), view.get("byteOffset", 0)

    def accessor(self, i: int) -> np.ndarray:
        """The accessor's values, (count, components); normalized integers as float32."""
        acc = self.lists["accessors"][i]
        dtype = np.dtype(COMPONENT_DTYPES[acc["componentType"]])
        width, count = TYPE_WIDTHS[acc["type"]], acc["count"]
        if acc.get("bufferView") is None:
            out = np.zeros((count, width), dtype)
        else:
            raw, offset = self._view(acc["bufferView"])
            offset += acc.get("byteOffset", 0)
            item = dtype.itemsize * width
            stride = self.lists["bufferViews"][acc["bufferView"]].get("byteStride") or item
            if stride == item:
                out = np.frombuffer(raw, dtype, count * width, offset).reshape(count, width)
            else:  # interleaved: view the rows through a strided window
                rows = np.frombuffer(raw, np.uint8, stride * (count - 1) + item, offset)
                out = np.lib.stride_tricks.as_strided(rows, (count, item), (stride, 1))
                out = np.ascontiguousarray(out).view(dtype).reshape(count, width)
        sparse = acc.get("sparse")
        if sparse is not None:
            out = out.copy()
            n, idx_part, val_part = sparse["count"], sparse["indices"], sparse["values"]
            raw, offset = self._view(idx_part["bufferView"])
            idx = np.frombuffer(raw, COMPONENT_DTYPES[idx_part["componentType"]], n,
                                offset + idx_part.get("byteOffset", 0))
            if int(idx.max()) >= count:
                raise expected(f"sparse indices below {count:,} at accessors[{i}]", str(int(idx.max())))
            raw, offset = self._view(val_part["bufferView"])
            out[idx] = np.frombuffer(raw, dtype, n * width,
                                     offset + val_part.get("byteOffset", 0)).reshape(n, width)
        if dtype.kind == "f" and not np.isfinite(out).all():
            bad = out[~np.isfinite(out)].ravel()[0]
            raise expected(f"finite numbers in accessors[{i}]", str(bad))
        if acc.get("normalized") and dtype.kind in "iu":
            out = np.maximum(out.astype(np.float32) / np.iinfo(dtype).max, -1.0)
        return out

    def image_bytes(self, i: int) -> bytes:
        """Image ``i``'s encoded bytes; a base colour texture's picture is checked first."""
        img = self.lists["images"][i]
        if img.get("bufferView") is not None:
            raw, offset = self._view(img["bufferView"])
            data = bytes(raw[offset: offset + self.lists["bufferViews"][img["bufferView"]]["byteLength"]])
        elif img["uri"].strip().startswith("data:"):
            data = data_uri(img["uri"], f"images[{i}]")
        else:
            data = side_path(self.document.asset, img["uri"]).read_bytes()
        if i in self.document.textured:
            check_picture(data, f"images[{i}] ({item_name(img, 'unnamed')!r})")
        return data
