"""Fin construction (thesis 4.2) in scaled thesis space, with Fixel's texture-point order.

Each builder takes the fin's measurements as a small parameter record of plain
numbers (:class:`CaudalParams`, :class:`VerticalParams`, :class:`PectoralParams`,
:class:`PelvicParams`; lengths in thesis units, angles in degrees, section numbers
as indices into ``rings``), the body's ``rings`` and ``scale`` as arrays, and
optional texture points. It returns a :class:`Fin`: its mesh (vertices in exactly
the order of the species file's texture points, so UVs map one to one) and, for
moving fins, the pivot the thesis names in 7.1. Mapping a species file's records
onto these parameters is :mod:`fishgen.assembly.fins`' job.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from fishgen.geometry.body import midline_points
from fishgen.geometry.mesh import Mesh, strip_faces

#: Paired fins stand off the flank by this angle instead of lying in it (decisions.md).
SPLAY_DEGREES = 20.0


@dataclass(frozen=True)
class CaudalParams:
    """Tail fin (Figure 4.9): two fans from ``connection`` (unit body space, x y z)."""
    top_line: float
    middle_line: float
    top_angle: float          # degrees between top and middle line
    top_triangles: int
    connection: tuple[float, float, float]
    rotation_angle: float     # degrees, tilts the whole fin about the z-axis
    bottom_line: float
    bottom_angle: float       # degrees between bottom and middle line
    bottom_triangles: int
    movement_angle: float = 0.0   # degrees, swing amplitude
    step_size: float = 0.0        # degrees per frame


@dataclass(frozen=True)
class VerticalParams:
    """Dorsal, adipose or anal fin over ring sections ``start_section..end_section``."""
    start_section: int
    end_section: int
    start_length: float
    end_length: float
    start_angle: float        # degrees from the horizontal; the sign is ignored
    proportion: float


@dataclass(frozen=True)
class PectoralParams:
    """Pectoral fin (Figure 4.14): based on ring ``start_section`` from point ``start_circle``."""
    start_section: int
    start_circle: int
    triangles: int
    start_length: float
    start_angle: float        # degrees from the horizontal
    proportion: float
    movement_angle: float = 0.0
    step_size: float = 0.0


@dataclass(frozen=True)
class PelvicParams:
    """Pelvic fin (Figure 4.16): based on ring point ``start_circle`` of sections start..end."""
    start_circle: int
    start_section: int
    end_section: int
    start_length: float
    end_length: float
    end_angle: float          # degrees below the horizontal
    movement_angle: float = 0.0
    step_size: float = 0.0


@dataclass(frozen=True)
class Fin:
    name: str
    mesh: Mesh
    pivot: np.ndarray | None = None      # rotation centre for animated fins
    movement_angle: float = 0.0          # degrees
    step_size: float = 0.0               # degrees per frame
    mirror_of: str | None = None         # set on a right-hand fin
    axis: np.ndarray | None = None       # unit hinge axis through the pivot; None: the y-axis


def _uv(points: ArrayLike | None, n: int) -> np.ndarray:
    if points is None:
        return np.zeros((n, 2))
    return np.asarray(points, dtype=np.float64).reshape(n, 2)


def _scaled(dx: float, dy: float, scale: np.ndarray) -> np.ndarray:
    """A fin vector in thesis units to scaled space: uniformly by scaleY, the body's depth,
    so the angles the file gives are the angles one sees (docs/decisions.md)."""
    return np.array([dx, dy, 0.0]) * scale[1]


def caudal_fin(fin: CaudalParams, scale: np.ndarray, uv: ArrayLike | None = None,
               tail_x: float | None = None) -> Fin:
    """Two fans of triangles from the connection point (Figure 4.9).

    Vertex order as Fixel writes it: connection point; the top edge from the top
    tip to the middle line's end; the bottom edge from the bottom tip to it.
    The thesis swings the fin about its connection point (7.1), which lies inside the
    body; given the body's tail end ``tail_x``, it hinges where its middle line leaves
    the body instead, so the part of the fin that meets the body stays on it.
    """
    origin = np.asarray(fin.connection, dtype=np.float64) * scale
    ta, ba = np.radians(fin.top_angle), np.radians(fin.bottom_angle)
    top = _scaled(fin.top_line * np.cos(ta), fin.top_line * np.sin(ta), scale)
    bottom = _scaled(fin.bottom_line * np.cos(ba), -fin.bottom_line * np.sin(ba), scale)
    middle = _scaled(fin.middle_line, 0.0, scale)
    t_top = np.linspace(0.0, 1.0, fin.top_triangles + 1)[:, None]
    t_bot = np.linspace(0.0, 1.0, fin.bottom_triangles + 1)[:, None]
    top_edge = top + t_top * (middle - top)
    bottom_edge = bottom + t_bot * (middle - bottom)
    offsets = np.concatenate([np.zeros((1, 3)), top_edge, bottom_edge])
    rot = np.radians(fin.rotation_angle)
    c, s = np.cos(rot), np.sin(rot)
    offsets = offsets @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]).T
    n_top = fin.top_triangles + 1
    top_idx = 1 + np.arange(n_top)
    bot_idx = 1 + n_top + np.arange(fin.bottom_triangles + 1)
    faces = np.concatenate([
        np.stack([np.zeros(n_top - 1, int), top_idx[1:], top_idx[:-1]], axis=1),
        np.stack([np.zeros(len(bot_idx) - 1, int), bot_idx[:-1], bot_idx[1:]], axis=1),
    ])
    mesh = Mesh(origin + offsets, faces.astype(np.int64), _uv(uv, len(offsets)))
    pivot = origin
    middle_end = origin + offsets[n_top]
    if tail_x is not None and middle_end[0] > origin[0]:
        s = np.clip((tail_x - origin[0]) / (middle_end[0] - origin[0]), 0.0, 1.0)
        pivot = origin + s * (middle_end - origin)
    return Fin("caudal_fin", mesh, pivot, fin.movement_angle, fin.step_size)


def vertical_fin(name: str, fin: VerticalParams, rings: np.ndarray, scale: np.ndarray, side: float,
                 uv: ArrayLike | None = None) -> Fin:
    """Dorsal/adipose (side=+1) or anal (side=-1) fin over BodySections start..end.

    Base points B_k sit on the body's top (or bottom) line. The tip of the start
    line is T_0 = B_0 + startLength at startAngle; each next top vertex lies at
    ``proportion`` of the way up the previous triangle's side, T_k = B_k + p (T_{k-1} - B_k);
    the end line stands at 90 degrees with endLength (Figure 4.12). The angle's
    sign is ignored: ``side`` says whether the fin stands up or hangs down.
    Fixel order: T_0, B_0, B_n, T_n, B_1..B_{n-1}, T_1..T_{n-1}.
    """
    sections = np.arange(fin.start_section, fin.end_section + 1)
    n = sections.size
    base = midline_points(rings, sections, side)
    a = np.radians(abs(fin.start_angle))
    top = np.empty_like(base)
    top[0] = base[0] + _scaled(fin.start_length * np.cos(a), side * fin.start_length * np.sin(a), scale)
    for k in range(1, n):
        top[k] = base[k] + fin.proportion * (top[k - 1] - base[k])
    top[-1] = base[-1] + _scaled(0.0, side * fin.end_length, scale)
    return _strip_fin(name, base, top, side_up=side > 0, uv=uv)


def _strip_fin(name: str, base: np.ndarray, top: np.ndarray, side_up: bool, uv: ArrayLike | None) -> Fin:
    n = len(base)
    middle = np.arange(1, n - 1)
    order = np.concatenate([[n + 0, 0, n - 1, 2 * n - 1], middle, n + middle])  # Fixel order
    positions = np.concatenate([base, top])[order]
    where = np.empty(2 * n, dtype=np.int64)
    where[order] = np.arange(2 * n)
    faces = strip_faces(where[:n], where[n:])
    if not side_up:
        faces = faces[:, ::-1]
    return Fin(name, Mesh(positions, faces, _uv(uv, 2 * n)))


def _splay(vector: np.ndarray, side: float) -> np.ndarray:
    """Tilt a fin direction out of the flank, away from the body's mid-plane."""
    out = vector.copy()
    out[2] += side * np.hypot(vector[0], vector[1]) * np.tan(np.radians(SPLAY_DEGREES))
    return out


def pectoral_fin(fin: PectoralParams, rings: np.ndarray, scale: np.ndarray,
                 uv: ArrayLike | None = None) -> Fin:
    """Left pectoral fin (Figure 4.14): base on ring startBodySection from startCircleSection
    down through ``triangles`` CircleSections; like a vertical fin whose end line is zero.

    Fixel order: T_0, B_0, B_n, B_1..B_{n-1}, T_1..T_{n-1}. The fin hinges along its base line,
    B_0 to B_n (the thesis pivots it on one point, 7.1, which lifts the rest of the base off the
    body; docs/decisions.md).
    """
    circles = rings.shape[1]
    n = fin.triangles
    idx = (fin.start_circle - np.arange(n + 1)) % circles
    base = rings[fin.start_section, idx]
    side = 1.0 if base[:, 2].mean() >= 0 else -1.0
    a = np.radians(fin.start_angle)
    top = np.empty_like(base)
    start = _scaled(fin.start_length * np.cos(a), fin.start_length * np.sin(a), scale)
    top[0] = base[0] + _splay(start, side)
    for k in range(1, n + 1):
        top[k] = base[k] + fin.proportion * (top[k - 1] - base[k])
    top[n] = base[n]
    middle = np.arange(1, n)
    # vertex list: B_0..B_n then T_0..T_{n-1}; T_n is B_n
    positions_all = np.concatenate([base, top[:n]])
    order = np.concatenate([[n + 1, 0, n], middle, n + 1 + middle])
    positions = positions_all[order]
    where = np.empty(2 * n + 1, dtype=np.int64)
    where[order] = np.arange(2 * n + 1)
    top_idx = np.concatenate([where[n + 1:], [where[n]]])
    faces = strip_faces(where[: n + 1], top_idx)
    faces = faces[_nondegenerate(positions, faces)]
    faces = _face_outward(positions, faces, side)
    pivot, axis = _hinge(base)
    return Fin("pectoral_fin_left", Mesh(positions, faces, _uv(uv, 2 * n + 1)), pivot,
               fin.movement_angle, fin.step_size, axis=axis)


def pelvic_fin(fin: PelvicParams, rings: np.ndarray, scale: np.ndarray, uv: ArrayLike | None = None) -> Fin:
    """Left pelvic fin (Figure 4.16): base along CircleSection startCircleSection over
    BodySections start..end; the start line hangs straight down with start_length,
    the end line leaves at end_angle below the horizontal with end_length, and the
    outer edge runs straight between their tips.

    Fixel order: B_0, B_n, O_0, O_n, B_1..B_{n-1}, O_1..O_{n-1}. The fin hinges along its base
    line, B_0 to B_n (the thesis pivots it on its highest base point, 7.1, which swings the rear of
    the base up to 2 % of the body length off the body; docs/decisions.md).
    """
    sections = np.arange(fin.start_section, fin.end_section + 1)
    n = sections.size
    base = rings[sections, fin.start_circle]
    side = 1.0 if base[:, 2].mean() >= 0 else -1.0
    a = np.radians(fin.end_angle)
    start_tip = base[0] + _splay(_scaled(0.0, -fin.start_length, scale), side)
    end_tip = base[-1] + _splay(_scaled(fin.end_length * np.cos(a), -fin.end_length * np.sin(a), scale), side)
    t = np.linspace(0.0, 1.0, n)[:, None] if n > 1 else np.zeros((1, 1))
    outer = start_tip + t * (end_tip - start_tip)
    middle = np.arange(1, n - 1)
    order = np.concatenate([[0, n - 1, n, 2 * n - 1], middle, n + middle])
    positions = np.concatenate([base, outer])[order]
    where = np.empty(2 * n, dtype=np.int64)
    where[order] = np.arange(2 * n)
    faces = strip_faces(where[:n], where[n:])
    faces = faces[_nondegenerate(positions, faces)]
    faces = _face_outward(positions, faces, side)
    pivot, axis = _hinge(base)
    return Fin("pelvic_fin_left", Mesh(positions, faces, _uv(uv, 2 * n)), pivot,
               fin.movement_angle, fin.step_size, axis=axis)


def _hinge(base: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """Pivot and unit axis of a fin hinged along its base line (first to last base point);
    a base of one point (or none long enough) swings about the y-axis through it."""
    line = base[-1] - base[0]
    length = float(np.linalg.norm(line))
    if length <= 1e-9 * max(1.0, float(np.abs(base).max())):
        return base[0].copy(), None
    return base[0].copy(), line / length


def _nondegenerate(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    tri = positions[faces]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    return area > 1e-12 * max(1.0, float(np.abs(positions).max()) ** 2)


def _face_outward(positions: np.ndarray, faces: np.ndarray, side: float) -> np.ndarray:
    """Wind a paired fin so its front faces away from the body (+z on the left)."""
    if faces.size == 0:
        return faces
    tri = positions[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]).sum(axis=0)
    return faces if normal[2] * side >= 0 else faces[:, ::-1].copy()


def mirrored(fin: Fin) -> Fin:
    """The right-hand twin of a left paired fin: a mirror image in z."""
    flip = np.array([1.0, 1.0, -1.0])
    pivot = None if fin.pivot is None else fin.pivot * flip
    axis = None if fin.axis is None else fin.axis * flip
    return Fin(fin.name.replace("_left", "_right"), fin.mesh.mirrored_z(), pivot,
               fin.movement_angle, fin.step_size, mirror_of=fin.name, axis=axis)
