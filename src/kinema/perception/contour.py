"""The contour of a slice of a point cloud: the outline a tool follows along a surface at one height.

:func:`slice_contour` takes the points within ``thickness`` of a plane (given as a pose: the plane is its
x-y plane, its origin the centre angles are measured about), projects them onto the plane and outlines
them: the convex hull, or with ``alpha`` > 0 a concave hull (the boundary of the Delaunay triangles whose
circumradius is at most ``alpha`` m, as PCL's ConcaveHull reads its alpha). The outline runs
anticlockwise about the plane's z; it may be cropped to the part between two angles about the plane's
origin, and is resampled so no two poses are further apart than ``max_spacing``.

Each pose of the result lies on the plane with its z axis along the outline's inward normal (toward the
inside of the outline: a tool whose z points along it faces the surface) and its x axis along the
direction of travel; its y axis is then the plane's -z.
"""

from __future__ import annotations

import itertools

import numpy as np

from kinema.errors import PerceptionError

__all__ = ["slice_contour"]

TWO_PI = 2.0 * np.pi


def _convex_hull(points: np.ndarray) -> np.ndarray:
    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = ConvexHull(points)
    except QhullError as error:
        raise PerceptionError(
            f"the slice's points are all on one line, so they outline nothing: {error}"
        ) from None
    return points[hull.vertices]  # anticlockwise in 2D


def _concave_hull(points: np.ndarray, alpha: float) -> np.ndarray:
    from scipy.spatial import Delaunay, QhullError

    try:
        triangles = Delaunay(points).simplices
    except QhullError as error:
        raise PerceptionError(
            f"the slice's points are all on one line, so they outline nothing: {error}"
        ) from None
    a, b, c = (points[triangles[:, k]] for k in range(3))
    ab, bc, ca = (np.linalg.norm(u - v, axis=1) for u, v in ((a, b), (b, c), (c, a)))
    area = 0.5 * np.abs((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        radius = ab * bc * ca / (4.0 * area)
    kept = triangles[np.isfinite(radius) & (radius <= alpha)]
    if not len(kept):
        raise PerceptionError(
            f"no triangle of the slice is within hull_alpha = {alpha} m; give a larger alpha (or -1 for the "
            "convex hull)"
        )
    edges: dict[tuple[int, int], int] = {}
    for tri in kept:
        for i, j in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            key = (min(i, j), max(i, j))
            edges[key] = edges.get(key, 0) + 1
    boundary = [edge for edge, count in edges.items() if count == 1]
    neighbours: dict[int, list[int]] = {}
    for i, j in boundary:
        neighbours.setdefault(i, []).append(j)
        neighbours.setdefault(j, []).append(i)
    # walk the loops; keep the longest (the outer outline)
    best: list[int] = []
    unvisited = set(neighbours)
    while unvisited:
        start = unvisited.pop()
        loop, previous, current = [start], None, start
        while True:
            options = [n for n in neighbours[current] if n != previous and (n in unvisited or n == start)]
            if not options:
                break
            following = options[0]
            if following == start:
                break
            loop.append(following)
            unvisited.discard(following)
            previous, current = current, following
        if len(loop) > len(best):
            best = loop
    outline = points[best]
    signed = np.sum(outline[:, 0] * np.roll(outline[:, 1], -1) - np.roll(outline[:, 0], -1) * outline[:, 1])
    return outline if signed > 0 else outline[::-1]


def _crop(outline: np.ndarray, start: float, span: float) -> tuple[np.ndarray, bool]:
    """The part of the anticlockwise ``outline`` whose angle about the origin lies in [start, start + span],
    from ``start`` on; and whether it is the whole closed outline."""
    if span >= TWO_PI - 1e-3:  # 2 pi as a port's text gives it (6.2832)
        return outline, True
    angles = np.mod(np.arctan2(outline[:, 1], outline[:, 0]) - start, TWO_PI)
    inside = angles <= span
    if not inside.any():
        raise PerceptionError(
            f"no point of the outline lies between {start:.3f} and {start + span:.3f} rad about the plane's "
            "origin; check contour_crop_angle_start and contour_crop_angle_span"
        )
    # begin at the inside point that follows an outside one (the crop's start), then go round
    n = len(outline)
    first = next((k for k in range(n) if inside[k] and not inside[k - 1]), int(np.argmin(angles)))
    order = [(first + k) % n for k in range(n)]
    kept = []
    for k in order:
        if not inside[k]:
            break
        kept.append(k)
    return outline[kept], False


def _resample(path: np.ndarray, max_spacing: float) -> np.ndarray:
    points = [path[0]]
    for a, b in itertools.pairwise(path):
        pieces = max(1, int(np.ceil(np.linalg.norm(b - a) / max_spacing - 1e-9)))
        for k in range(1, pieces + 1):
            points.append(a + (b - a) * (k / pieces))
    return np.asarray(points)


def slice_contour(
    points: np.ndarray,
    plane: np.ndarray,
    thickness: float,
    *,
    alpha: float = -1.0,
    max_spacing: float = 0.2,
    angle_start: float = 0.0,
    angle_span: float = TWO_PI,
) -> list[np.ndarray]:
    """Poses along the outline of the points near ``plane`` (see the module docstring).

    Args:
        points: the cloud, shape ``(N, 3)``, in the frame ``plane`` is given in (non-finite points ignored).
        plane: ``frame_T_plane``, shape ``(4, 4)``.
        thickness: points within this distance (m) of the plane count.
        alpha: <= 0 for the convex hull; > 0 the largest circumradius (m) of a triangle inside the hull.
        max_spacing: the largest distance (m) between consecutive poses, > 0.
        angle_start: where the kept part of the outline begins, an angle (rad) about the plane's z
            measured from its x axis.
        angle_span: how far (rad) the kept part reaches from ``angle_start``, anticlockwise; 2 pi or more
            keeps the whole outline, closed (its first pose repeated at the end).

    Returns:
        ``frame_T_pose`` of each pose, in order of travel.

    Raises:
        PerceptionError: fewer than 3 points in the slice, points on one line, a bad size or angle, or
            nothing of the outline in the angle range.
    """
    cloud = np.asarray(points, dtype=float).reshape(-1, 3)
    plane = np.asarray(plane, dtype=float)
    for name, value in (("thickness", thickness), ("max_spacing", max_spacing)):
        if not (np.isfinite(value) and value > 0):
            raise PerceptionError(f"{name} must be > 0 m, got {value}")
    if not (np.isfinite(angle_start) and np.isfinite(angle_span) and angle_span > 0):
        raise PerceptionError(f"the angle span must be > 0 rad, got {angle_span} (start {angle_start})")
    local = (cloud[np.all(np.isfinite(cloud), axis=1)] - plane[:3, 3]) @ plane[:3, :3]
    near = local[np.abs(local[:, 2]) <= thickness][:, :2]
    if len(near) < 3:
        raise PerceptionError(
            f"{len(near)} point(s) of the cloud lie within {thickness} m of the plane; a contour needs 3 or "
            "more (move the plane into the cloud, or slice thicker)"
        )
    outline = _concave_hull(near, alpha) if alpha > 0 else _convex_hull(near)
    path, closed = _crop(outline, float(angle_start), float(angle_span))
    if closed:
        path = np.vstack([path, path[:1]])
    if len(path) < 2:
        raise PerceptionError(
            "only one point of the outline lies in the angle range; widen contour_crop_angle_span"
        )
    path = _resample(path, float(max_spacing))
    poses = []
    for k, point in enumerate(path):
        tangent = path[min(k + 1, len(path) - 1)] - path[max(k - 1, 0)]
        length = float(np.linalg.norm(tangent))
        if length < 1e-12:
            continue
        x = np.array([tangent[0], tangent[1], 0.0]) / length
        z = np.array([-x[1], x[0], 0.0])  # left of the travel: inward for an anticlockwise outline
        y = np.cross(z, x)
        local_pose = np.eye(4)
        local_pose[:3, :3] = np.column_stack([x, y, z])
        local_pose[:3, 3] = (point[0], point[1], 0.0)
        poses.append(plane @ local_pose)
    return poses
