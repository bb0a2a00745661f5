"""The bounds fishgen computed for an asset, and the comparison of a client's bounds with them.

Counts alone miss a client that reads the numbers wrong: Godot 3.2 imports
normalized 16-bit positions as raw integers (±32767) without an error, and a
client that misreads a morph target or an animation key still has the right
number of them. So the Godot and Babylon.js cells also compare, at rest:

- every drawn primitive's box in world space (any client's surfaces must match
  them as a multiset, so a client that splits or merges meshes differently is
  still checked part by part);
- every morph target's box (rest position + displacement) in the mesh's space;
- the range of every kind of animation key: morph weights, node translations
  (an animated node without a translation channel keeps its rest translation,
  as engines store whole transforms per key), rotation quaternion norms and scales.

The expected side is fishgen's own scene: for the fish and the clouds, the scene
built in-process exactly as the CLI builds it (`fishgen build`, `fishgen clouds`
with their defaults); for the school, the scene fishgen's glTF reader gets back
from the file (a school is a simulation: re-running it here would only repeat
`fishgen school`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

    from fishgen.scene.model import Channel, Scene

Box = tuple[tuple[float, float, float], tuple[float, float, float]]


def _box(points) -> Box:
    import numpy as np

    p = np.asarray(points, float).reshape(-1, 3)
    return tuple(map(float, p.min(0))), tuple(map(float, p.max(0)))  # type: ignore[return-value]


def _union(boxes: list[Box]) -> Box:
    import numpy as np

    return _box(np.array([corner for b in boxes for corner in b]))


@dataclass(frozen=True)
class PrimitiveBounds:
    node: str
    mode: str                   # TRIANGLES or POINTS
    world: Box                  # at rest, after every node transform
    local: Box                  # in the mesh's own space
    targets: tuple[Box, ...]    # each morph target at full weight, in the mesh's space


@dataclass(frozen=True)
class ClipBounds:
    name: str
    duration: float
    trs_nodes: int              # nodes with any translation/rotation/scale channel
    rotation_channels: int
    translation_channels: int
    scale_channels: int
    weight_channels: int
    weight_tracks: int          # one per morph target of each weights channel


@dataclass(frozen=True)
class Bounds:
    primitives: tuple[PrimitiveBounds, ...]
    world: Box
    clip: ClipBounds | None = None
    scene: Scene | None = field(default=None, compare=False, repr=False)   # for ClipTruth


def scene_bounds(scene: Scene) -> Bounds:
    """Rest-pose bounds of every drawn primitive, and the key ranges of the scene's first clip."""
    import numpy as np

    from fishgen.scene.pose import pose

    rest = pose(scene)
    prims = []
    for node, prim in scene.drawn():
        p = np.asarray(prim.positions, float)
        world = rest.matrix(node)
        moved = p @ world[:3, :3].T + world[:3, 3]
        targets = tuple(_box(p + np.asarray(t["POSITION"], float)) for t in prim.targets if "POSITION" in t)
        prims.append(PrimitiveBounds(scene.nodes[node].name, prim.mode, _box(moved), _box(p), targets))
    clip = scene.clip()
    return Bounds(tuple(prims), _union([b.world for b in prims]),
                  _clip_bounds(scene, clip) if clip else None, scene)


def merged(bounds: Bounds, name: str) -> Bounds:
    """The bounds of a format that writes every part as one mesh at rest (PLY)."""
    one = PrimitiveBounds(name, bounds.primitives[0].mode, bounds.world, bounds.world, ())
    return Bounds((one,), bounds.world, None, bounds.scene)


def clip_bounds(scene: Scene, name: str) -> ClipBounds:
    """The counts of the scene's clip ``name`` (an engine fish carries several)."""
    clip = scene.clip(name)
    assert clip is not None, f"no clip {name}"
    return _clip_bounds(scene, clip)


def _clip_bounds(scene: Scene, clip) -> ClipBounds:
    paths = [ch.path for ch in clip.channels]
    targets = 0
    for ch in clip.channels:
        mesh = scene.nodes[ch.node].mesh
        if ch.path == "weights" and mesh is not None:
            targets += len(scene.meshes[mesh].primitives[0].targets)
    return ClipBounds(clip.name, clip.duration,
                      len({ch.node for ch in clip.channels if ch.path != "weights"}),
                      paths.count("rotation"), paths.count("translation"), paths.count("scale"),
                      paths.count("weights"), targets)


class ClipTruth:
    """fishgen's clip, asked the way a client's keys are compared with it: by node path and time.

    A client's track names a node by its path of names from the asset's root ("fish/body");
    engines that need unique names add a number ("bonybream 2"), which ``node`` forgives.
    """

    def __init__(self, scene: Scene, clip_name: str):
        self.scene = scene
        clip = scene.clip(clip_name)
        assert clip is not None, f"no clip {clip_name}"
        self.channels: dict[tuple[int, str], Channel] = {(ch.node, ch.path): ch for ch in clip.channels}
        self.paths: dict[str, int] = {}
        # the coarser levels of detail (MSFT_lod) hang outside the default scene: their tracks name them too
        children = {c for n in scene.nodes for c in n.children}
        outside = [i for i in range(len(scene.nodes)) if i not in children and i not in scene.roots]
        stack = [(i, scene.nodes[i].name) for i in [*outside, *scene.roots]]   # the scene's own first
        while stack:
            i, path = stack.pop()
            self.paths.setdefault(path, i)
            stack += [(c, f"{path}/{scene.nodes[c].name}") for c in scene.nodes[i].children]

    def node(self, path: str) -> int | None:
        import re

        if path in self.paths:
            return self.paths[path]
        plain = "/".join(re.sub(r" \d+$", "", part) for part in path.split("/"))
        if plain in self.paths:
            return self.paths[plain]
        # a client may hang the asset under a root of its own: try each tail of the path
        parts = plain.split("/")
        return next((self.paths["/".join(parts[k:])] for k in range(1, len(parts))
                     if "/".join(parts[k:]) in self.paths), None)

    def trs(self, node: int, times) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The node's translation, rotation (x, y, z, w) and scale at each of ``times``, (n, 3|4|3):
        sampled where animated, its rest value where not."""
        import numpy as np

        n = self.scene.nodes[node]
        times = np.asarray(times, float)
        out = []
        for path, rest in (("translation", n.translation), ("rotation", n.rotation), ("scale", n.scale)):
            ch = self.channels.get((node, path))
            out.append(sample_many(ch, times) if ch is not None
                       else np.tile(np.asarray(rest, float), (len(times), 1)))
        return out[0], out[1], out[2]

    def weight(self, node: int, target: int, times) -> np.ndarray | None:
        ch = self.channels.get((node, "weights"))
        return None if ch is None else sample_many(ch, times)[:, target]


def sample_many(channel, times) -> np.ndarray:
    """fishgen.scene.pose.sample at many times at once (LINEAR and STEP vectorised; slerp for rotations)."""
    import numpy as np

    from fishgen.scene.pose import sample

    smp = channel.sampler
    times = np.asarray(times, float)
    if smp.interpolation == "CUBICSPLINE":
        return np.array([sample(channel, t) for t in times])
    keys = np.asarray(smp.times, float).ravel()
    values = np.asarray(smp.values, float).reshape(len(keys), -1)
    k = np.clip(np.searchsorted(keys, times, side="right") - 1, 0, len(keys) - 1)
    k1 = np.minimum(k + 1, len(keys) - 1)
    span = keys[k1] - keys[k]
    s = np.where(span > 0, (np.clip(times, keys[0], keys[-1]) - keys[k]) / np.where(span > 0, span, 1),
                 0.0)[:, None]
    if smp.interpolation == "STEP":
        s = np.zeros_like(s)
    a, b = values[k], values[k1]
    if channel.path != "rotation":
        return (1 - s) * a + s * b
    a = a / np.linalg.norm(a, axis=1, keepdims=True)
    b = b / np.linalg.norm(b, axis=1, keepdims=True)
    d = np.sum(a * b, axis=1, keepdims=True)
    b = np.where(d < 0, -b, b)  # the short arc
    d = np.abs(d)
    theta = np.arccos(np.clip(d, -1, 1))
    sin = np.sin(theta)
    near = d > 0.9995   # nearly parallel: lerp, as pose.slerp does
    wa = np.where(near, 1 - s, np.sin((1 - s) * theta) / np.where(near, 1, sin))
    wb = np.where(near, s, np.sin(s * theta) / np.where(near, 1, sin))
    q = wa * a + wb * b
    return q / np.linalg.norm(q, axis=1, keepdims=True)


@dataclass
class KeyErrors:
    """The largest differences between a client's keys and fishgen's clip at the same times."""

    keys: int = 0
    translation: float = 0.0    # metres
    rotation: float = 0.0       # degrees
    scale: float = 0.0
    weight: float = 0.0
    worst: dict[str, str] = field(default_factory=dict)   # what -> where it was largest

    def note(self, what: str, value: float, where: str) -> None:
        if value > getattr(self, what):
            setattr(self, what, value)
            self.worst[what] = where


def key_errors(truth: ClipTruth, tracks: list[dict]) -> KeyErrors:
    """Compare a client's keys with fishgen's clip at the same times.

    ``tracks``: {"node": path, "kind": "trs" with keys [t, x, y, z, qx, qy, qz, qw, sx, sy, sz]
    (None for a part the client's track does not hold), or "weight" with "target" and keys [t, w]}.
    A track that names no node of fishgen's raises AssertionError.
    """
    import numpy as np

    errors = KeyErrors()
    for track in tracks:
        node = truth.node(track["node"])
        if node is None:
            raise AssertionError(f"track {track['node']!r} names no node of fishgen's")
        if not track["keys"]:
            continue
        keys = np.array([[np.nan if v is None else v for v in key] for key in track["keys"]], float)
        t = keys[:, 0]
        errors.keys += len(t)

        if track["kind"] == "weight":
            want = truth.weight(node, track["target"], t)
            if want is None:
                raise AssertionError(f"{track['node']}: morph weights fishgen does not animate")
            found = {"weight": np.abs(keys[:, 1] - want)}
        else:
            loc, rot, scale = truth.trs(node, t)
            q = keys[:, 4:8] / np.linalg.norm(keys[:, 4:8], axis=1, keepdims=True)
            found = {"translation": np.abs(keys[:, 1:4] - loc).max(axis=1),
                     "rotation": np.degrees(2 * np.arccos(np.clip(np.abs(np.sum(q * rot, axis=1)), 0, 1))),
                     "scale": np.abs(keys[:, 8:11] - scale).max(axis=1)}
        for what, err in found.items():  # NaN where the client's track does not hold that part
            if np.isfinite(err).any():
                i = int(np.nanargmax(err))
                morph = f", morph {track['target']}" if what == "weight" else ""
                errors.note(what, float(err[i]), f"{track['node']} at {t[i]:.3f} s{morph}")
    return errors


def expect_same_keys(errors: KeyErrors, tol: float, what: str = "key") -> None:
    """A client's own keys must be fishgen's values: float precision, nothing more."""
    for name, value, limit in (("translation", errors.translation, tol), ("rotation", errors.rotation, 0.05),
                               ("scale", errors.scale, 1e-4), ("weight", errors.weight, 1e-4)):
        if value > limit:
            unit = {"translation": " m", "rotation": "°"}.get(name, "")
            raise AssertionError(f"{what} {name} off by {value:.3g}{unit} ({errors.worst[name]})")


# --------------------------------------------------------------------------- comparing

def tolerance(expected: Bounds) -> float:
    """How far a client's box may be from fishgen's: a thousandth of a millimetre plus 1e-5 of the
    asset's size (clients store float32, and print some digits less)."""
    lo, hi = expected.world
    diagonal = sum((b - a) ** 2 for a, b in zip(lo, hi, strict=True)) ** 0.5
    return 1e-6 + 1e-5 * diagonal


def as_box(pair) -> Box:
    """A client's [[min], [max]] as a Box."""
    return tuple(map(float, pair[0])), tuple(map(float, pair[1]))  # type: ignore[return-value]


def box_close(a: Box | None, b: Box | None, tol: float) -> bool:
    if a is None or b is None:
        return a is b
    return all(abs(x - y) <= tol for ca, cb in zip(a, b, strict=True) for x, y in zip(ca, cb, strict=True))


def show(box: Box | None) -> str:
    if box is None:
        return "none"
    return ("[" + ", ".join(f"{v:.4g}" for v in box[0]) + "] to ["
            + ", ".join(f"{v:.4g}" for v in box[1]) + "]")


def pair_primitives(found: list[Box], expected: Bounds, what: str = "surface") -> list[int]:
    """For each client box (world space, at rest), the index of the expected primitive it is.

    Boxes pair as a multiset: each expected primitive is used once, and every one must be used.
    A mismatch raises AssertionError naming the box and fishgen's nearest one.
    """
    tol = tolerance(expected)
    left = list(range(len(expected.primitives)))
    pairs = []
    for i, box in enumerate(found):
        hit = next((j for j in left if box_close(box, expected.primitives[j].world, tol)), None)
        if hit is None:
            nearest = min(left or range(len(expected.primitives)),
                          key=lambda j: _distance(box, expected.primitives[j].world))
            raise AssertionError(f"{what} {i} bounds {show(box)}, fishgen's nearest "
                                 f"({expected.primitives[nearest].node}) "
                                 f"is {show(expected.primitives[nearest].world)}")
        left.remove(hit)
        pairs.append(hit)
    if left:
        raise AssertionError(f"{len(left)} of fishgen's primitives have no {what} "
                             f"(first: {expected.primitives[left[0]].node})")
    return pairs


def _distance(a: Box, b: Box) -> float:
    return max(abs(x - y) for ca, cb in zip(a, b, strict=True) for x, y in zip(ca, cb, strict=True))
