"""A small ICC v2 RGB profile (matrix and gamma curves), built here so the photo tests can tag a
picture with a colour space other than sRGB without shipping a profile file."""
from __future__ import annotations

import struct

import numpy as np

D50 = np.array([0.9642, 1.0, 0.8249])
P3_PRIMARIES = ((0.680, 0.320), (0.265, 0.690), (0.150, 0.060))
SRGB_PRIMARIES = ((0.64, 0.33), (0.30, 0.60), (0.15, 0.06))
D65 = (0.3127, 0.3290)
_BRADFORD = np.array([[0.8951, 0.2664, -0.1614], [-0.7502, 1.7135, 0.0367], [0.0389, -0.0685, 1.0296]])


def _xyz(xy) -> np.ndarray:
    return np.array([xy[0] / xy[1], 1.0, (1 - xy[0] - xy[1]) / xy[1]])


def rgb_to_xyz(primaries, white) -> np.ndarray:
    """3x3: linear RGB -> XYZ for a space of these primaries and white point (chromaticities)."""
    m = np.stack([_xyz(p) for p in primaries], 1)
    return m * np.linalg.solve(m, _xyz(white))


def _s15(v: float) -> bytes:
    return struct.pack(">i", int(round(v * 65536)))


def _tag_xyz(v) -> bytes:
    return b"XYZ " + bytes(4) + b"".join(_s15(x) for x in v)


def profile(name: str, primaries, white, gamma: float) -> bytes:
    """An ICC v2 display profile: ``primaries`` and ``white`` (chromaticities), one ``gamma`` curve."""
    source = _BRADFORD @ _xyz(white)
    adapt = np.linalg.inv(_BRADFORD) @ np.diag(_BRADFORD @ D50 / source) @ _BRADFORD
    m = adapt @ rgb_to_xyz(primaries, white)
    text = name.encode("ascii") + b"\0"
    curve = b"curv" + bytes(4) + struct.pack(">IH", 1, int(round(gamma * 256))) + bytes(2)
    tags = [(b"desc", b"desc" + bytes(4) + struct.pack(">I", len(text)) + text + bytes(8 + 3 + 67)),
            (b"cprt", b"text" + bytes(4) + b"test data\0"), (b"wtpt", _tag_xyz(D50)),
            (b"rXYZ", _tag_xyz(m[:, 0])), (b"gXYZ", _tag_xyz(m[:, 1])), (b"bXYZ", _tag_xyz(m[:, 2])),
            (b"rTRC", curve), (b"gTRC", curve), (b"bTRC", curve)]
    body, table, start = b"", b"", 128 + 4 + 12 * len(tags)
    for sig, data in tags:
        data += bytes(-len(data) % 4)
        table += sig + struct.pack(">II", start + len(body), len(data))
        body += data
    header = (struct.pack(">I", start + len(body)) + bytes(4) + struct.pack(">I", 0x02100000)
              + b"mntrRGB XYZ " + bytes(12) + b"acsp" + bytes(28) + b"".join(_s15(v) for v in D50)
              + bytes(48))
    return header + struct.pack(">I", len(tags)) + table + body


def p3_to_srgb(rgb, gamma: float = 2.2) -> np.ndarray:
    """8-bit Display P3 values (``gamma`` curves) as 8-bit sRGB, computed here, not by LittleCMS."""
    linear = (np.asarray(rgb, float) / 255) ** gamma
    to_srgb = np.linalg.solve(rgb_to_xyz(SRGB_PRIMARIES, D65), rgb_to_xyz(P3_PRIMARIES, D65))
    s = np.clip(linear @ to_srgb.T, 0, 1)
    return np.round(255 * np.where(s <= 0.0031308, 12.92 * s, 1.055 * s ** (1 / 2.4) - 0.055))
