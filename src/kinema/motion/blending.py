"""Corner blending: a waypoint path as straight pieces joined by circular arcs at its interior corners.

Pure geometry (:mod:`kinema.transforms`), no robot model: :func:`blended_pieces` turns poses into pieces
that the Cartesian planner samples and solves IK along.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from kinema.transforms import (
    angle_between,
    quaternion_from_matrix,
    rotation_from_rotvec,
    rotation_matrix,
    slerp,
)

# Corners straighter than this (rad of turning) need no blend; ones turning back by more than pi minus it
# cannot be blended with a circle (the arc would shrink to a point), so the path stops there instead.
_ANGLE_EPS = 1e-6


@dataclass(frozen=True, eq=False)  # holds numpy arrays
class PathPiece:
    """One piece of a tool path: a straight line or a circular arc, with orientation slerped along it.

    Attributes:
        start: position where the piece starts (3,).
        end: position where it ends (3,).
        q_start: orientation (quaternion x, y, z, w) at the start.
        q_end: orientation at the end.
        center: the arc's centre (3,), or None for a straight line.
        axis: unit axis the arc turns about (right-handed, from start to end), None for a line.
        turn: the arc's angle (rad), 0 for a line.
    """

    start: np.ndarray
    end: np.ndarray
    q_start: np.ndarray
    q_end: np.ndarray
    center: np.ndarray | None = None
    axis: np.ndarray | None = None
    turn: float = 0.0

    @property
    def length(self) -> float:
        """Length of the tool's path along the piece (m)."""
        if self.center is None:
            return float(np.linalg.norm(self.end - self.start))
        return float(np.linalg.norm(self.start - self.center)) * self.turn

    @property
    def rotation(self) -> float:
        """How far the orientation turns along the piece (rad)."""
        return angle_between(self.q_start, self.q_end)

    def pose_at(self, t: float) -> np.ndarray:
        """The pose (4, 4) at fraction ``t`` in [0, 1] of the piece (uniform in arc length)."""
        pose = np.eye(4)
        if self.center is None or self.axis is None:
            pose[:3, 3] = self.start + t * (self.end - self.start)
        else:
            spin = rotation_from_rotvec(self.axis * (t * self.turn))
            pose[:3, 3] = self.center + spin @ (self.start - self.center)
        pose[:3, :3] = rotation_matrix(slerp(self.q_start, self.q_end, t))
        return pose


def _corner_blend(a: np.ndarray, p: np.ndarray, b: np.ndarray, radius: float) -> float:
    """How far before and after corner ``p`` (between ``a`` and ``b``) its blend starts and ends (m)."""
    if radius <= 0:
        return 0.0
    before, after = p - a, b - p
    la, lb = float(np.linalg.norm(before)), float(np.linalg.norm(after))
    if la < 1e-9 or lb < 1e-9:
        return 0.0  # a pure rotation on one side: no corner in the tool's path
    turning = float(np.arccos(np.clip(np.dot(before / la, after / lb), -1.0, 1.0)))
    if turning < _ANGLE_EPS or turning > np.pi - _ANGLE_EPS:
        return 0.0  # straight on, or straight back: pass through the waypoint
    return min(radius, la / 2, lb / 2)


def blended_pieces(poses: Sequence[np.ndarray], radius: float) -> list[PathPiece]:
    """The tool path through ``poses`` (each (4, 4); the first is where the tool starts) as pieces.

    Every interior corner is rounded by a circular arc tangent to both neighbouring lines: the path leaves
    the incoming line ``radius`` metres before the waypoint and joins the outgoing one ``radius`` metres
    after it (clamped to half of the shorter neighbouring line, so blends never overlap). For a 90-degree
    corner the arc's radius is ``radius`` and it passes ``radius * (sqrt(2) - 1)`` from the waypoint. Over
    a blend the orientation turns from the incoming line's orientation at the blend's start to the outgoing
    line's at its end. The first and last poses are reached exactly; ``radius`` 0 gives straight lines
    through every pose.

    Raises:
        ValueError: ``radius`` is negative.
    """
    if radius < 0:
        raise ValueError(f"the blending radius must be >= 0, got {radius}")
    points = [np.asarray(T, dtype=float)[:3, 3] for T in poses]
    quats = [quaternion_from_matrix(T) for T in poses]
    # Distance of each waypoint's blend from the waypoint (0 at the ends and at unblended corners).
    cut = [0.0] * len(points)
    for i in range(1, len(points) - 1):
        cut[i] = _corner_blend(points[i - 1], points[i], points[i + 1], radius)

    pieces: list[PathPiece] = []
    for i, (a, b) in enumerate(itertools.pairwise(points)):
        length = float(np.linalg.norm(b - a))
        t0 = cut[i] / length if cut[i] > 0 else 0.0
        t1 = 1.0 - cut[i + 1] / length if cut[i + 1] > 0 else 1.0
        if t1 > t0 + 1e-12 or length < 1e-9:
            pieces.append(
                PathPiece(
                    a + t0 * (b - a),
                    a + t1 * (b - a),
                    slerp(quats[i], quats[i + 1], t0),
                    slerp(quats[i], quats[i + 1], t1),
                )
            )
        if cut[i + 1] > 0:
            pieces.append(_arc(points[i : i + 3], quats[i : i + 3], cut[i + 1]))
    return pieces


def _arc(points: Sequence[np.ndarray], quats: Sequence[np.ndarray], cut: float) -> PathPiece:
    """The circular arc rounding the corner at ``points[1]``, tangent to both lines ``cut`` from it."""
    a, p, b = points
    la, lb = float(np.linalg.norm(p - a)), float(np.linalg.norm(b - p))
    u1, u2 = (p - a) / la, (b - p) / lb
    turning = float(np.arccos(np.clip(np.dot(u1, u2), -1.0, 1.0)))
    # A circle inscribed in the interior angle (pi - turning), touching both lines ``cut`` from the corner.
    arc_radius = cut * np.tan((np.pi - turning) / 2)
    axis = np.cross(u1, u2)
    axis /= np.linalg.norm(axis)
    start = p - cut * u1
    center = start + arc_radius * np.cross(axis, u1)
    return PathPiece(
        start,
        p + cut * u2,
        slerp(quats[0], quats[1], 1.0 - cut / la),
        slerp(quats[1], quats[2], cut / lb),
        center=center,
        axis=axis,
        turn=turning,
    )
