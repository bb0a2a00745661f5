"""The fish's own frame: head on the left and the nose-to-tail midline level.

A photo may show the fish mirrored (head right) or a few degrees off level.
Measuring happens in this normalised frame; every point found is mapped back to
the photo's pixels, so the photo itself is used untouched as the texture.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import ndimage  # type: ignore[import-untyped]

from fishgen.authoring.photo import columns
from fishgen.errors import FishgenError

MARGIN = 4
#: Below this the photo is taken as level: measuring on its own pixels beats resampling them.
LEVEL_DEGREES = 0.25
#: A principal axis steeper than this is a deep fish (fins and all, taller than long), not a fish
#: standing on its head: side photos show fish about level, so it is taken as level.
STEEPEST_AXIS = 30.0
#: ...unless its tail is up or down: a peduncle (a narrow neck before the tail fin) along the
#: vertical this many times deeper than any along the horizontal says the fish stands on end. Such a
#: photo is refused: fish within STEEPEST_AXIS degrees of level are supported.
STANDING_NECK = 1.5
#: A midline still this many degrees off level once turned (the nose or tail base found on the
#: turned fish is another point than on the first turn) is levelled again, up to RELEVELS times.
#: Within it the fit's own turns (:data:`.run.TURNS`, up to 4 degrees) take the rest.
RELEVEL_DEGREES = 4.0
RELEVELS = 6
#: Two levels at least this many degrees apart are two readings of the fish, not one (other_level).
TWO_LEVELS = 8.0
#: The photo as it stands overrules the principal axis's turn on which end is the tail only where
#: one of its necks is at least this many times the other (:func:`_tail_left`).
TAIL_DECISIVE = 2.0


@dataclass(frozen=True)
class Frame:
    linear: np.ndarray     # 2x2: photo (x, y) -> frame (x, y), y down
    shift: np.ndarray      # frame = linear @ photo + shift
    mask: np.ndarray       # the silhouette in the frame
    angle: float           # degrees the photo's fish is turned from level (clockwise on screen)
    mirrored: bool         # head on the right in the photo
    flipped: int = 0       # the photo's width, if it was measured mirrored (see :func:`faces_right`)

    def to_photo(self, points: np.ndarray) -> np.ndarray:
        photo = (np.asarray(points, float) - self.shift) @ np.linalg.inv(self.linear).T
        if self.flipped:
            photo[:, 0] = self.flipped - photo[:, 0]
        return photo

    def level(self, mask: np.ndarray) -> np.ndarray:
        """Another mask of the photo (a true silhouette, say) turned as this frame turns the fish."""
        return _resample(mask[:, ::-1] if self.flipped else mask, self.linear)[0]

    def of_mirror(self, width: int) -> Frame:
        """This frame of a photo's mirror image (``width`` px wide) as a frame of the photo."""
        # R(-d) F = F R(d) for the mirror F: the fish's turn on the photo is the other way
        return replace(self, angle=-self.angle, mirrored=not self.mirrored, flipped=width)


def _rotation(degrees: float) -> np.ndarray:
    a = np.radians(degrees)
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def _resample(mask: np.ndarray, linear: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    ys, xs = np.nonzero(mask)
    q = np.stack([xs + 0.5, ys + 0.5], 1) @ linear.T
    lo = np.floor(q.min(axis=0)) - MARGIN
    shift = -lo
    size = np.ceil(q.max(axis=0) - lo).astype(int) + MARGIN
    inv = np.linalg.inv(linear)
    swap = np.array([[0.0, 1.0], [1.0, 0.0]])
    matrix = swap @ inv @ swap
    offset = swap @ (inv @ (0.5 - shift)) - 0.5
    # a mirror or no turn at all maps pixels onto pixels: sample them exactly
    exact = bool(np.allclose(np.abs(linear), np.round(np.abs(linear)))
                 and np.isclose(abs(np.linalg.det(linear)), 1.0))
    out = ndimage.affine_transform(mask.astype(np.float32), matrix, offset, output_shape=(size[1], size[0]),
                                   order=0 if exact else 1, cval=0.0)
    return out >= 0.5, shift


def faces_right(mask: np.ndarray) -> bool:
    """Whether :func:`fish_frame` would find the fish's head on the right. Such a photo is measured
    as its mirror image, so a fish facing right gives the files its mirror image gives: resampled
    mirrored and turned, its outline fell on other pixels, and a Blender photo's fits moved by up
    to 0.07 between facing left and right. A fish standing on end is not turned here:
    :func:`fish_frame` refuses it."""
    try:
        return _axis_and_facing(mask)[1]
    except FishgenError:
        return False


def _axis_and_facing(mask: np.ndarray) -> tuple[float, bool]:
    """(degrees the principal axis turns the fish, whether its head is then on the right)."""
    ys, xs = np.nonzero(mask)
    pts = np.stack([xs, ys], 1).astype(float)
    cov = np.cov((pts - pts.mean(axis=0)).T)
    vx, vy = np.linalg.eigh(cov)[1][:, -1]
    theta = float(np.degrees(np.arctan2(vy, vx)))
    theta = (theta + 90.0) % 180.0 - 90.0
    if abs(theta) > STEEPEST_AXIS:
        if _neck(mask.T) > STANDING_NECK * _neck(mask):
            raise FishgenError(f"expected a side view of a fish within {STEEPEST_AXIS:.0f} degrees of "
                               f"level, found one standing on end (its long axis {abs(theta):.0f} degrees "
                               "from level); turn the photo first")
        theta = 0.0
    first, _ = _resample(mask, _rotation(-theta))
    return theta, _tail_left(first, mask if theta else None)


def _leveller(mask: np.ndarray, mirrored: bool, tail_drop: float):
    """(levelled, midline) for ``mask``: ``midline(level)`` is the degrees its nose-to-tail line is
    off level; ``levelled(phi)`` the fish turned by phi and then levelled again on its own turn while
    it is RELEVEL_DEGREES off, up to RELEVELS times: (midline, phi, linear, mask, shift)."""
    from fishgen.authoring.photo.anatomy import nose_and_tail_base

    flip = np.diag([-1.0, 1.0]) if mirrored else np.eye(2)

    def midline(level: np.ndarray) -> float:
        (nx, ny), (px, py) = nose_and_tail_base(level, drop=tail_drop)
        return float(np.degrees(np.arctan2(py - ny, px - nx)))

    def levelled(phi: float) -> tuple[float, float, np.ndarray, np.ndarray, np.ndarray]:
        linear = flip @ _rotation(-phi)
        out, shift = _resample(mask, linear)
        best = (midline(out), phi, linear, out, shift)
        for _ in range(RELEVELS):
            if abs(best[0]) <= RELEVEL_DEGREES:
                break
            phi = best[1] - best[0] if mirrored else best[1] + best[0]
            linear = flip @ _rotation(-phi)
            out, shift = _resample(mask, linear)
            if abs(midline(out)) >= abs(best[0]):
                break
            best = (midline(out), phi, linear, out, shift)
        return best

    return levelled, midline


def fish_frame(mask: np.ndarray, tail_drop: float = 0.0) -> Frame:
    """Level the fish by its principal axis, turn its head left, then level its midline
    (nose to tail base) exactly, as Fixel's user would draw it."""
    theta, mirrored = _axis_and_facing(mask)
    levelled, midline = _leveller(mask, mirrored, tail_drop)
    flip = np.diag([-1.0, 1.0]) if mirrored else np.eye(2)
    level, _ = _resample(mask, flip @ _rotation(-theta))
    delta = midline(level)
    phi = theta - delta if mirrored else theta + delta
    if abs(phi) < LEVEL_DEGREES:
        phi = 0.0
    # The nose is the silhouette's first columns and the tail base its deepest neck, both read on
    # the fish as first turned; once turned by phi a blunt head's other corner, or another neck,
    # may lead, and the midline is then many degrees off level (704: turned 15 degrees, still 8
    # off; the principal axis, 21 degrees, was pulled off by tall fins on a fish nearly as tall as
    # long). Such a fish is levelled again on its own turn, and also from level (side photos show
    # fish about level): the turn whose midline ends nearest level, within STEEPEST_AXIS, is kept.
    settled = levelled(phi)
    if settled[1] != phi or abs(settled[1]) > STEEPEST_AXIS:
        tries = [settled, levelled(0.0)]
        settled = min(tries, key=lambda t: (abs(t[1]) > STEEPEST_AXIS, abs(t[0])))
    _, phi, linear, out, shift = settled
    return Frame(linear, shift, out, phi, mirrored)


def other_level(mask: np.ndarray, frame: Frame, tail_drop: float = 0.0) -> Frame | None:
    """A second reading of the level of the fish ``frame`` (:func:`fish_frame` of ``mask``) levels:
    the fish as it stands, corrected by its own midline, when ``frame`` turns it more than
    TWO_LEVELS degrees and as it stands its midline is also within RELEVEL_DEGREES of level, at
    least TWO_LEVELS nearer level; else None. Tall fins may give a fish two levels its nose and tail
    base agree with (3207: turned 30 degrees by its fins' axis, level as it stands, and the fit made
    at 30 scored 0.51-0.67 in Blender). The silhouette alone does not tell which is right (150
    random fish turned 3-14 degrees: each reading right 4 times where they differ): a fit tries both."""
    if abs(frame.angle) <= TWO_LEVELS:
        return None
    levelled, _ = _leveller(mask, frame.mirrored, tail_drop)
    stands = levelled(0.0)
    if abs(stands[0]) > RELEVEL_DEGREES or abs(stands[1]) > abs(frame.angle) - TWO_LEVELS:
        return None
    near = stands[1] - stands[0] if frame.mirrored else stands[1] + stands[0]
    again = levelled(near if abs(near) >= LEVEL_DEGREES else 0.0)
    _, phi, linear, out, shift = again if abs(again[0]) <= abs(stands[0]) else stands
    return Frame(linear, shift, out, phi, frame.mirrored)


def _tail_left(turned: np.ndarray, level: np.ndarray | None) -> bool:
    """Whether the tail is on the left: the end with the deeper neck, read on the fish turned by its
    principal axis; or, if that was a turn, on the photo as it stands (side photos show fish about
    level) where that reading is clearly decisive (one neck at least TAIL_DECISIVE times the other)
    and more so than the turned one. Tall fins pull the axis round: a sail-finned fish 2 degrees off
    level, turned 22 degrees by its axis, has its two ends' necks 1.3 times apart there and the
    tail's 10 times the head's as it stands (Blender photo 2407: read on the turn alone, it was fitted
    backwards). A weak reading as it stands does not overrule the turn: on small-tailed fish tilted a
    few degrees both are near 1, and the turned one is the better (a review's 1,800 drawn fish)."""
    right, left = columns.tail_necks(turned)
    if level is not None:
        stands = columns.tail_necks(level)
        if _decisive(stands) >= max(TAIL_DECISIVE, _decisive((right, left))):
            right, left = stands
    return left > right


def _decisive(necks: tuple[float, float]) -> float:
    """How many times the deeper neck is the other."""
    return max(necks) / max(min(necks), 1e-9)


def turned(mask: np.ndarray, frame: Frame, degrees: float) -> Frame:
    """``frame`` (of ``mask``) turned ``degrees`` further, counter-clockwise in the frame."""
    if degrees == 0.0:
        return frame
    linear = _rotation(-degrees) @ frame.linear
    out, shift = _resample(mask, linear)
    # R(-d) F = F R(d) for the mirror F: a mirrored fish's turn on the photo is the other way
    angle = frame.angle - degrees if frame.mirrored else frame.angle + degrees
    return replace(frame, linear=linear, shift=shift, mask=out, angle=angle)


def _neck(mask: np.ndarray) -> float:
    """The deepest neck near either end of the silhouette, column by column (a tail's peduncle)."""
    _, _, has = columns.extent(mask)
    cols = np.flatnonzero(has)
    top, bottom, _ = columns.extent(mask[:, cols[0]:cols[-1] + 1])
    thick = bottom - top
    reach = max(2, int(0.45 * thick.size))
    return float(max(columns.neck_depth(thick)[-reach:].max(),
                     columns.neck_depth(thick[::-1])[-reach:].max()))
