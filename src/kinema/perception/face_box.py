"""The box of an object a camera sees one face of: the face's plane, its extent, and the depth behind it.

A segmentation mask's points are mostly the face of the object towards the camera, plus what the camera saw
through gaps (the wall behind a handle), a little of the sides and stray depth at the edges.
:func:`fit_face_box` finds the face as the plane fitting the points best (RANSAC through triples of points
scored as MSAC, a seeded generator so the same points give the same box), refits it to its inliers
(:func:`~kinema.perception.surface_normal`), and keeps the points between just in front of the face and
``separation`` behind it. The box's z axis is the face's normal pointing away from the viewpoint (into the
object: the direction a tool approaches it from the camera's side), x the face's longest extent (turned so
its largest component is positive), y completing a right-handed frame. The box reaches from the face back
to the deepest point kept, at least ``inlier_distance`` thick.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinema.errors import PerceptionError

from .surface_pose import surface_normal

__all__ = ["FaceBox", "fit_face_box"]

# Triples of points tried for the face's plane; with half the points on it, 0.875**200 is the chance of
# never drawing three of them.
_TRIES = 200


@dataclass(frozen=True)
class FaceBox:
    """A fitted box: its ``pose`` (4x4, centre and axes), full ``size`` ``(3,)`` (m) and the visible face's
    area (m², its x extent times its y extent)."""

    pose: np.ndarray
    size: np.ndarray
    face_area: float


def fit_face_box(
    points: np.ndarray, viewpoint: np.ndarray, inlier_distance: float, separation: float, seed: int = 0
) -> FaceBox:
    """The box of the object whose points (Nx3, m; non-finite rows ignored) ``viewpoint`` (m) sees.

    ``inlier_distance`` (m) is how far from the face's plane a point still belongs to the face;
    ``separation`` (m) how far behind the face a point may lie and still be the object's.

    Raises:
        PerceptionError: fewer than 3 points, or points on a line (no face to fit).
    """
    cloud = np.asarray(points, dtype=float).reshape(-1, 3)
    cloud = cloud[np.isfinite(cloud).all(axis=1)]
    eye = np.asarray(viewpoint, dtype=float).reshape(3)
    if len(cloud) < 3:
        raise PerceptionError(f"too few points to fit a face: {len(cloud)} (3 at least)")
    on_plane = _largest_plane(cloud, inlier_distance, seed)
    inward = -surface_normal(cloud[on_plane], eye)
    offsets = (cloud - cloud[on_plane].mean(axis=0)) @ inward
    kept = (offsets >= -inlier_distance) & (offsets <= separation)
    face = cloud[kept & (np.abs(offsets) <= inlier_distance)]
    cloud = cloud[kept]
    # The face's longest extent: the principal axis of its points laid into the plane.
    flat = face - face.mean(axis=0)
    flat -= np.outer(flat @ inward, inward)
    _, _, axes = np.linalg.svd(flat, full_matrices=False)
    x = axes[0] - inward * float(axes[0] @ inward)
    x /= np.linalg.norm(x)
    if x[np.argmax(np.abs(x))] < 0.0:
        x = -x
    rotation = np.column_stack([x, np.cross(inward, x), inward])
    local, face_local = cloud @ rotation, face @ rotation
    lower, upper = local.min(axis=0), local.max(axis=0)
    lower[2] = face_local[:, 2].min()
    upper[2] = max(upper[2], lower[2] + inlier_distance)
    extent = np.ptp(face_local[:, :2], axis=0)
    pose = np.eye(4)
    pose[:3, :3] = rotation
    pose[:3, 3] = rotation @ ((lower + upper) / 2)
    return FaceBox(pose, upper - lower, float(extent[0] * extent[1]))


def _largest_plane(cloud: np.ndarray, inlier_distance: float, seed: int) -> np.ndarray:
    """Which points (bool, N) lie within ``inlier_distance`` of the plane that fits them best.

    Planes are scored as MSAC does (the sum of squared distances, each capped at the inlier distance), not
    by inlier count alone: through an object smaller than twice the distance, a tilted plane holds every
    point too, but lies further from them than the face itself.
    """
    rng = np.random.default_rng(seed)
    cap = max(inlier_distance, 1e-12) ** 2
    best, best_cost = np.zeros(len(cloud), dtype=bool), np.inf
    for _ in range(_TRIES):
        a, b, c = cloud[rng.choice(len(cloud), size=3, replace=False)]
        normal = np.cross(b - a, c - a)
        length = float(np.linalg.norm(normal))
        if length == 0.0:
            continue
        squared = ((cloud - a) @ (normal / length)) ** 2
        cost = float(np.minimum(squared, cap).sum())
        if cost < best_cost:
            best, best_cost = squared <= inlier_distance**2, cost
    if best.sum() < 3:
        raise PerceptionError(f"the {len(cloud)} points lie on a line, so they fit no face")
    return best
