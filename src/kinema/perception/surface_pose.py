"""The surface at a point of a cloud: its normal from the points around it, and a pose standing on it.

:func:`surface_normal` is the normal of the plane that best fits a neighbourhood (principal component
analysis: the direction in which the points spread least), turned to face a viewpoint, as PCL's
NormalEstimation does with ``flipNormalTowardsViewpoint``. :func:`pose_on_surface` builds the pose at a
point whose z axis is that normal: z out of the surface, x the reference frame's x laid into the surface
(its y when x is almost along the normal), y completing a right-handed frame.
"""

from __future__ import annotations

import numpy as np

from kinema.errors import PerceptionError

__all__ = ["pose_on_surface", "surface_normal"]

# A neighbourhood whose second spread (eigenvalue) is below this fraction of its largest is a line, not a
# surface: its normal is any direction across the line.
_FLAT_LINE = 1e-6


def surface_normal(neighbours: np.ndarray, viewpoint: np.ndarray) -> np.ndarray:
    """The unit normal ``(3,)`` of the plane best fitting ``neighbours`` (Nx3, m), on ``viewpoint``'s side.

    The sign puts the normal towards ``viewpoint`` (a point, m) as seen from the neighbourhood's mean, so
    with the camera's position it points out of the surface the camera sees.

    Raises:
        PerceptionError: fewer than 3 neighbours, or neighbours on one line (no plane to fit).
    """
    points = np.asarray(neighbours, dtype=float).reshape(-1, 3)
    if len(points) < 3:
        raise PerceptionError(f"too few points to fit a surface: {len(points)} (3 at least)")
    centre = points.mean(axis=0)
    spread, axes = np.linalg.eigh(np.cov(points - centre, rowvar=False))
    if spread[1] <= _FLAT_LINE * max(float(spread[2]), 1e-300):
        raise PerceptionError(f"the {len(points)} points lie on a line, so they fit no surface")
    normal = axes[:, 0]
    if float(normal @ (np.asarray(viewpoint, dtype=float).reshape(3) - centre)) < 0.0:
        normal = -normal
    return np.asarray(normal / np.linalg.norm(normal), dtype=float)


def pose_on_surface(point: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """The ``(4, 4)`` pose at ``point`` (m) with z along ``normal``, in the frame both are given in.

    x is the frame's x axis projected onto the surface (the frame's y when the normal is within about
    25 degrees of the frame's x), y is z cross x.
    """
    z = np.asarray(normal, dtype=float).reshape(3)
    z = z / np.linalg.norm(z)
    hint = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = hint - z * float(hint @ z)
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    pose[:3, 3] = np.asarray(point, dtype=float).reshape(3)
    return pose
