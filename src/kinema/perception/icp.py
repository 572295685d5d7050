"""Rigid registration by point-to-point ICP: match each source point to its nearest target point (scipy's
cKDTree), keep pairs closer than ``max_correspondence_distance``, solve the best rigid motion for them
(Kabsch / SVD), repeat until the motion stops changing or ``max_iterations``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinema.errors import PerceptionError
from kinema.perception.point_cloud import PointCloud


@dataclass(frozen=True)
class IcpResult:
    """What ICP found.

    Attributes:
        target_T_source: 4x4 transform that moves the source cloud onto the target.
        fitness: fraction of source points with a correspondence at the end (0..1).
        rmse: root mean square distance of those correspondences, m.
        iterations: iterations run.
        converged: the last update moved less than the tolerance.
    """

    target_T_source: np.ndarray
    fitness: float
    rmse: float
    iterations: int
    converged: bool


def best_rigid_transform(source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The 4x4 rigid transform minimising the squared distances of paired rows (N x 3 each)."""
    source_mean, target_mean = source.mean(axis=0), target.mean(axis=0)
    covariance = (source - source_mean).T @ (target - target_mean)
    u, _, vt = np.linalg.svd(covariance)
    correction = np.eye(3)
    correction[2, 2] = np.sign(np.linalg.det(vt.T @ u.T))
    rotation = vt.T @ correction @ u.T
    transform = np.eye(4)
    transform[:3, :3] = rotation
    transform[:3, 3] = target_mean - rotation @ source_mean
    return transform


def register_icp(
    source: PointCloud,
    target: PointCloud,
    *,
    max_correspondence_distance: float,
    max_iterations: int = 30,
    initial: np.ndarray | None = None,
    tolerance: float = 1e-6,
) -> IcpResult:
    """Align ``source`` to ``target`` (same frame); start from ``initial`` (4x4, identity by default).

    Raises:
        PerceptionError: a cloud is empty, the distance is not positive, or no pair is close enough.
    """
    from scipy.spatial import cKDTree

    if not max_correspondence_distance > 0:
        raise PerceptionError(
            f"max_correspondence_distance must be a positive length (m), got {max_correspondence_distance}"
        )
    src = source.finite().points.astype(np.float64)
    dst = target.finite().points.astype(np.float64)
    if len(src) < 3 or len(dst) < 3:
        raise PerceptionError(
            f"ICP needs at least 3 points in each cloud (source has {len(src)}, target {len(dst)})"
        )
    tree = cKDTree(dst)
    transform = np.eye(4) if initial is None else np.asarray(initial, dtype=float).copy()
    converged = False
    iterations = 0
    distances = np.empty(0)
    for iterations in range(1, max(1, max_iterations) + 1):  # noqa: B007 - read after the loop
        moved = src @ transform[:3, :3].T + transform[:3, 3]
        distances, indices = tree.query(moved, distance_upper_bound=max_correspondence_distance)
        paired = np.isfinite(distances)
        if paired.sum() < 3:
            raise PerceptionError(
                f"ICP found {int(paired.sum())} point pairs closer than {max_correspondence_distance} m; "
                "the clouds do not overlap from this start (give a better initial pose or a larger distance)"
            )
        step = best_rigid_transform(moved[paired], dst[indices[paired]])
        transform = step @ transform
        if np.abs(step[:3, :3] - np.eye(3)).max() < tolerance and np.abs(step[:3, 3]).max() < tolerance:
            converged = True
            break
    moved = src @ transform[:3, :3].T + transform[:3, 3]
    distances, _ = tree.query(moved, distance_upper_bound=max_correspondence_distance)
    paired = np.isfinite(distances)
    rmse = float(np.sqrt(np.mean(distances[paired] ** 2))) if paired.any() else float("inf")
    return IcpResult(transform, float(paired.mean()), rmse, iterations, converged)
