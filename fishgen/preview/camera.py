"""Named views and framing: where the camera stands so the whole subject fits.

Fishgen assets are +Y up with the head toward +Z; the named views are chosen
so a fish faces left in side, top and three-quarter views, as field guides draw it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# view name -> (direction from subject to camera, camera up)
VIEWS: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "side": ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    "top": ((0.0, 1.0, 0.0), (-1.0, 0.0, 0.0)),
    "front": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "three-quarter": ((1.0, 0.45, 0.7), (0.0, 1.0, 0.0)),
}
FOV_Y = math.radians(30.0)
FILL = 0.88
"""Fraction of the frame the subject may fill along its tighter axis."""


@dataclass
class Camera:
    eye: np.ndarray
    target: np.ndarray
    up: np.ndarray
    fov_y: float
    aspect: float
    near: float
    far: float
    ortho: bool = False
    """Orthographic: the frame spans the view cone's width at the target's distance, so a side
    view reads as a field-guide photo with no perspective (what `fishgen texture` measures)."""

    def view(self) -> np.ndarray:
        f = _unit(self.target - self.eye)
        r = _unit(np.cross(f, self.up))
        u = np.cross(r, f)
        m = np.eye(4)
        m[0, :3], m[1, :3], m[2, :3] = r, u, -f
        m[:3, 3] = -m[:3, :3] @ self.eye
        return m

    def projection(self) -> np.ndarray:
        t = 1.0 / math.tan(self.fov_y / 2)
        n, f = self.near, self.far
        if self.ortho:
            half = float(np.linalg.norm(self.target - self.eye)) / t
            return np.array([[1 / (half * self.aspect), 0, 0, 0], [0, 1 / half, 0, 0],
                             [0, 0, 2 / (n - f), (f + n) / (n - f)], [0, 0, 0, 1]])
        return np.array([[t / self.aspect, 0, 0, 0], [0, t, 0, 0],
                         [0, 0, (f + n) / (n - f), 2 * f * n / (n - f)], [0, 0, -1, 0]])


def _unit(v) -> np.ndarray:
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def view_basis(view: str, azimuth: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(direction to camera, up) of a named view, turned ``azimuth`` radians about +Y."""
    direction, up = (np.asarray(v, float) for v in VIEWS[view])
    c, s = math.cos(azimuth), math.sin(azimuth)
    turn = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return _unit(turn @ direction), _unit(turn @ up)


def frame(points: np.ndarray, view: str, aspect: float, azimuths=(0.0,),
          target: np.ndarray | None = None, ortho: bool = False,
          reach: np.ndarray | None = None) -> Camera:
    """A camera on ``view`` that keeps every point of ``points`` (N, 3) in frame, and with ``reach``
    (N,) everything within that distance of it across the view: a particle's camera-facing quad.

    With several ``azimuths`` (a turntable), one distance and target serve them all.
    """
    points = np.asarray(points, float).reshape(-1, 3)
    r = np.zeros(len(points)) if reach is None else np.asarray(reach, float).ravel()
    if len(points) == 0:
        points, r = np.zeros((1, 3)), np.zeros(1)
    lo, hi = (points - r[:, None]).min(0), (points + r[:, None]).max(0)
    tan_y = math.tan(FOV_Y / 2) * FILL
    tan_x = tan_y * aspect
    fixed_target = target is not None or len(azimuths) > 1
    best: tuple[float, np.ndarray] | None = None
    for az in azimuths:
        d, up = view_basis(view, az)
        right = _unit(np.cross(-d, up))
        up = np.cross(right, -d)
        x, y, z = points @ right, points @ up, points @ d
        if fixed_target:
            centre = (lo + hi) / 2 if target is None else np.asarray(target, float)
            cx, cy = centre @ right, centre @ up
        else:
            cx, cy = ((x - r).min() + (x + r).max()) / 2, ((y - r).min() + (y + r).max()) / 2
            centre = right * cx + up * cy + d * ((z.min() + z.max()) / 2)
        zc = centre @ d
        # a quad lies at its centre's depth, r either side of it across the view
        dist = float(np.max(np.maximum((np.abs(x - cx) + r) / tan_x, (np.abs(y - cy) + r) / tan_y)
                            + (z - zc)))
        if best is None or dist > best[0]:
            best = (dist, centre)
    if best is None:
        raise ValueError("frame needs at least one azimuth")
    dist, centre = best
    span = float(np.linalg.norm(hi - lo)) or 1.0
    dist = max(dist, 1e-3 * span)
    d0, up0 = view_basis(view, azimuths[0])
    depth = max(span * 1.5, dist * 1e-3)  # never a depth range of nothing (near == far)
    return Camera(eye=centre + d0 * dist, target=centre, up=up0, fov_y=FOV_Y, aspect=aspect,
                  near=max(dist - depth, dist * 0.01), far=dist + depth, ortho=ortho)


def turned(camera: Camera, view: str, azimuth: float) -> Camera:
    """The same framing seen from ``azimuth`` radians about +Y (turntable frames)."""
    d, up = view_basis(view, azimuth)
    dist = float(np.linalg.norm(camera.eye - camera.target))
    return Camera(eye=camera.target + d * dist, target=camera.target, up=up, fov_y=camera.fov_y,
                  aspect=camera.aspect, near=camera.near, far=camera.far, ortho=camera.ortho)
