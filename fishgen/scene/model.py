"""The neutral scene every asset passes through: assembly builds it, writers and the renderer read it.

It mirrors the parts of glTF 2.0 fishgen uses, with numpy arrays instead of
buffers: nodes (TRS, children, a mesh and a skin), meshes that many nodes can
share, primitives of triangles or points with any vertex attributes, skins and
morph targets, materials, images, and animation clips of node x path channels.
Conventions are glTF's: metres, +Y up, colours linear, UV origin top-left,
rotations as (x, y, z, w) quaternions. Nothing here knows a file format.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

if TYPE_CHECKING:  # numpy stays out of `fishgen --help`
    import numpy as np

AlphaMode = Literal["OPAQUE", "MASK", "BLEND"]
PrimitiveMode = Literal["TRIANGLES", "POINTS"]
Path_ = Literal["translation", "rotation", "scale", "weights"]
Interpolation = Literal["LINEAR", "STEP", "CUBICSPLINE"]

PATHS: tuple[Path_, ...] = ("translation", "rotation", "scale", "weights")
INTERPOLATIONS: tuple[Interpolation, ...] = ("LINEAR", "STEP", "CUBICSPLINE")


@dataclass
class Image:
    """A texture source: encoded PNG/JPEG ``data``, and/or ``pixels`` a reader already decoded."""

    name: str
    data: bytes
    mime_type: str = "image/png"
    pixels: np.ndarray | None = None    # (H, W, 4) uint8 RGBA, sRGB-encoded

    def encoded(self) -> bytes:
        """The picture as file bytes: ``data``, or ``pixels`` encoded as PNG when a reader kept only those."""
        if self.data or self.pixels is None:
            return self.data
        import io

        from PIL import Image as PILImage

        out = io.BytesIO()
        PILImage.fromarray(self.pixels, "RGBA").save(out, format="PNG")
        self.data, self.mime_type = out.getvalue(), "image/png"
        return self.data

    def rgba(self) -> np.ndarray:
        """The picture as (H, W, 4) uint8 RGBA, decoded once."""
        if self.pixels is None:
            import io

            import numpy as np
            from PIL import Image as PILImage

            with PILImage.open(io.BytesIO(self.data)) as img:
                self.pixels = np.asarray(img.convert("RGBA"))
        return self.pixels


@dataclass
class Material:
    """glTF metallic-roughness subset; ``base_color`` is linear RGBA."""

    name: str
    base_color: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)
    texture: int | None = None          # index into Scene.images (base colour, sRGB-encoded)
    alpha_mode: AlphaMode = "OPAQUE"
    alpha_cutoff: float | None = None   # MASK only; None means glTF's default 0.5
    double_sided: bool = False
    unlit: bool = False
    metallic: float = 0.0
    roughness: float = 0.55


@dataclass
class Primitive:
    """One draw: triangles (``indices`` (m, 3)) or points, with per-vertex attributes.

    ``attributes`` uses glTF semantics: POSITION (n, 3) float32 is required;
    NORMAL, TEXCOORD_0, COLOR_0 (float32 linear, or normalized uint8/uint16),
    JOINTS_0 (uint8/uint16) and WEIGHTS_0 (float32) are optional, and names
    starting with ``_`` are application data (``_RADIUS`` of a particle).
    ``targets`` are morph targets: displacement arrays keyed like attributes.
    """

    attributes: dict[str, np.ndarray]
    indices: np.ndarray | None = None   # (m, 3) for TRIANGLES; None for POINTS
    material: int | None = None         # index into Scene.materials
    mode: PrimitiveMode = "TRIANGLES"
    targets: list[dict[str, np.ndarray]] = field(default_factory=list)

    @property
    def positions(self) -> np.ndarray:
        return self.attributes["POSITION"]

    @property
    def vertex_count(self) -> int:
        return len(self.attributes["POSITION"])

    @property
    def triangle_count(self) -> int:
        return 0 if self.indices is None or self.mode != "TRIANGLES" else len(self.indices)


@dataclass
class Mesh:
    name: str
    primitives: list[Primitive]
    weights: list[float] = field(default_factory=list)  # default morph weights, one per target
    target_names: list[str] = field(default_factory=list)  # one per target (glTF extras.targetNames)


@dataclass
class Skin:
    """Joints (node indices) and their inverse bind matrices (j, 4, 4), column vectors."""

    name: str
    joints: list[int]
    inverse_bind_matrices: np.ndarray
    skeleton: int | None = None


@dataclass(frozen=True)
class Levels:
    """Levels of detail of one node, the finest (glTF: the ``MSFT_lod`` node extension).

    ``nodes``: the coarser levels' nodes, finest first; each stands in for the node in full, in
    its place. ``coverage``: the screen coverage (the object's height on screen over the screen's)
    down to which each level shows, the node's own first, so one more than ``nodes``, decreasing;
    below the last nothing is drawn (``extras.MSFT_screencoverage``). Empty: the client decides."""

    nodes: tuple[int, ...]
    coverage: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if not self.nodes:
            raise ValueError("expected at least one coarser level")
        if self.coverage and (len(self.coverage) != len(self.nodes) + 1
                              or any(a < b for a, b in zip(self.coverage, self.coverage[1:], strict=False))):
            raise ValueError(f"expected a decreasing screen coverage per level ({len(self.nodes) + 1}), "
                             f"found {list(self.coverage)}")


@dataclass
class Node:
    name: str = ""
    translation: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    children: list[int] = field(default_factory=list)
    mesh: int | None = None
    skin: int | None = None
    matrix: np.ndarray | None = None    # 4x4 column-vector local matrix; wins over TRS, not animatable
    extras: dict[str, Any] = field(default_factory=dict)       # application data (a sky cloud's bounds)
    lods: Levels | None = None          # the coarser levels that stand in for this node (Scene.add_levels)


@dataclass
class Sampler:
    """Keyframes: ``times`` (k,) seconds, ``values`` (k, width), or (3k, width) for CUBICSPLINE."""

    times: np.ndarray
    values: np.ndarray
    interpolation: Interpolation = "LINEAR"


@dataclass
class Channel:
    node: int
    path: Path_
    sampler: Sampler


@dataclass
class Clip:
    name: str
    channels: list[Channel]

    @property
    def duration(self) -> float:
        return max((float(c.sampler.times[-1]) for c in self.channels if len(c.sampler.times)), default=0.0)


@dataclass
class Instancer:
    """Many copies of a few prototypes, each copy placed anew every frame (USD's PointInstancer).

    ``prototypes`` are whole assets (a fish and its clip, which runs over ``times``); copy ``i`` is
    prototype ``proto_indices[i]``, at frame ``f`` moved to ``positions[f, i]``, turned by
    ``orientations[f, i]`` (x, y, z, w) and scaled by ``scales[i]``."""

    name: str
    prototypes: list[Scene]
    proto_indices: np.ndarray   # (N,) int
    times: np.ndarray           # (F,) seconds, one per frame
    positions: np.ndarray       # (F, N, 3) metres
    orientations: np.ndarray    # (F, N, 4) unit quaternions
    scales: np.ndarray          # (N,) uniform scale


@dataclass
class Scene:
    """A whole asset. ``roots`` are the top-level nodes. ``source`` is the file a reader read it
    from, and ``note`` what a reader wants the user told (a subsampled cloud); writers ignore both.
    What a builder knows about what it built travels beside the scene, typed
    (:class:`fishgen.assembly.fish.FishFacts`), never inside it. ``extras`` is application data the
    file keeps, as JSON values (a cloud's sunlight, a school's warm-up): glTF writes it as the scene's
    ``extras``. ``hidden_roots`` are written as a second glTF scene, which clients show only when
    asked: the coarser levels of detail a node's ``lods`` names (:meth:`add_levels`), kept out of
    sight of clients that know nothing of levels, yet in a scene (a node in none is an orphan).
    ``instancers`` are crowds of copies, which only formats that hold instances write (a school in
    USD). ``fps``: the frame rate the asset was made at, at which formats that key every frame
    (USD) sample its clips; None: 30."""

    name: str = ""
    nodes: list[Node] = field(default_factory=list)
    roots: list[int] = field(default_factory=list)
    meshes: list[Mesh] = field(default_factory=list)
    materials: list[Material] = field(default_factory=list)
    images: list[Image] = field(default_factory=list)
    skins: list[Skin] = field(default_factory=list)
    clips: list[Clip] = field(default_factory=list)
    source: str | None = None
    note: str | None = None
    extras: dict[str, Any] = field(default_factory=dict)
    hidden_roots: list[int] = field(default_factory=list)  # a second glTF scene's: coarser levels of detail
    instancers: list[Instancer] = field(default_factory=list)
    fps: float | None = None

    # -- building ------------------------------------------------------------------
    def add_node(self, node: Node, parent: int | None = None, *, root: bool = True) -> int:
        """The node's index; it is a child of ``parent``, else a root, else (``root=False``) in
        no node tree yet: a coarser level, until :meth:`add_levels` places it."""
        self.nodes.append(node)
        index = len(self.nodes) - 1
        if parent is not None:
            self.nodes[parent].children.append(index)
        elif root:
            self.roots.append(index)
        return index

    def add_levels(self, finest: int, coarser: Sequence[int], coverage: Sequence[float] = (), *,
                   needs: Sequence[int] = (), hidden: bool = True) -> None:
        """Levels of detail: the nodes ``coarser`` (finest first) stand in for node ``finest``
        (see :class:`Levels`) and go, after ``needs`` (the nodes they need in a scene: their skins'
        joints), into the hidden scene; ``hidden=False`` leaves them in no scene (orphans, which the
        glTF validator reports). ``coarser`` empty: nothing to do."""
        if not coarser:
            return
        self.nodes[finest].lods = Levels(tuple(coarser), tuple(float(c) for c in coverage))
        if hidden:
            self.hidden_roots += [*needs, *coarser]

    def add_mesh(self, mesh: Mesh) -> int:
        self.meshes.append(mesh)
        return len(self.meshes) - 1

    def add_material(self, material: Material) -> int:
        self.materials.append(material)
        return len(self.materials) - 1

    def add_image(self, image: Image) -> int:
        self.images.append(image)
        return len(self.images) - 1

    # -- questions -----------------------------------------------------------------
    def clip(self, name: str | None = None) -> Clip | None:
        """The named clip, else the first (fishgen fish carry one named ``swim``)."""
        for clip in self.clips:
            if name is None or clip.name == name:
                return clip
        return None

    def reachable(self) -> list[int]:
        """Nodes under the roots, parents before children (each once, cycles cut)."""
        order: list[int] = []
        seen: set[int] = set()
        stack = list(reversed(self.roots))
        while stack:
            i = stack.pop()
            if i in seen:
                continue
            seen.add(i)
            order.append(i)
            stack.extend(reversed(self.nodes[i].children))
        return order

    def drawn(self) -> list[tuple[int, Primitive]]:
        """(node, primitive) for every primitive a renderer draws, in node order."""
        return [(i, prim) for i in self.reachable() if self.nodes[i].mesh is not None
                for prim in self.meshes[self.nodes[i].mesh].primitives]  # type: ignore[index]

    def counts(self) -> dict[str, int]:
        """Vertices and triangles of drawn meshes, and particles of drawn point sets."""
        drawn = self.drawn()
        return {"vertices": sum(p.vertex_count for _, p in drawn if p.mode == "TRIANGLES"),
                "triangles": sum(p.triangle_count for _, p in drawn),
                "particles": sum(p.vertex_count for _, p in drawn if p.mode == "POINTS")}

    def has(self) -> set[str]:
        """What this scene holds, in the registry's words (see fishgen.exchange.registry)."""
        kinds = set()
        for _, prim in self.drawn():
            kinds.add("meshes" if prim.mode == "TRIANGLES" else "points")
            if prim.targets:
                kinds.add("morph targets")
        if any(m.texture is not None for m in self.materials):
            kinds.add("textures")
        if any(m.alpha_mode == "MASK" for m in self.materials):
            kinds.add("alpha cutoff")
        if any(m.double_sided for m in self.materials):
            kinds.add("double-sided faces")
        if self.skins:
            kinds.add("skins")
        if any(c.channels for c in self.clips):
            kinds.add("node animation")
        if sum(bool(c.channels) for c in self.clips) > 1:
            kinds.add("more than one clip")
        if any(n.lods is not None for n in self.nodes):
            kinds.add("levels of detail")
        if self.instancers:
            kinds.add("instances")
        return kinds
