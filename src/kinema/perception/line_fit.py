"""The line segment a cloud's points lie along: RANSAC for the line, then the inliers' extent along it.

:func:`fit_line_segment` tries lines through pairs of points (a seeded generator, so the same points give
the same segment), keeps the one fitting best as MSAC scores it (the sum of squared distances, each capped
at the inlier distance: of two lines holding the same points, the nearer wins), refits it to those
inliers (principal axis) and returns the segment between the outermost inliers. Its direction is turned so
its largest component is positive: a vertical segment runs upwards, one along x runs towards +x.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinema.errors import PerceptionError

__all__ = ["LineSegment", "fit_line_segment"]

# Pairs of points tried; with half the points inliers, 0.75**200 is the chance of never drawing two of them.
_TRIES = 200


@dataclass(frozen=True)
class LineSegment:
    """A fitted segment: its ends ``start``, ``end`` ``(3,)`` (m) and how many points lie along it."""

    start: np.ndarray
    end: np.ndarray
    inliers: int

    @property
    def direction(self) -> np.ndarray:
        """The unit vector ``(3,)`` from ``start`` to ``end``."""
        along = self.end - self.start
        return np.asarray(along / np.linalg.norm(along), dtype=float)


def _distances(points: np.ndarray, origin: np.ndarray, direction: np.ndarray) -> np.ndarray:
    offsets = points - origin
    return np.asarray(np.linalg.norm(offsets - np.outer(offsets @ direction, direction), axis=1))


def fit_line_segment(points: np.ndarray, inlier_distance: float, seed: int = 0) -> LineSegment:
    """The segment best fitting ``points`` (Nx3, m; non-finite rows ignored).

    A point is an inlier when it lies within ``inlier_distance`` (m) of the line.

    Raises:
        PerceptionError: fewer than 2 distinct finite points, or a negative or non-finite distance.
    """
    if not np.isfinite(inlier_distance) or inlier_distance < 0.0:
        raise PerceptionError(f"the inlier distance must be a distance >= 0 (m), got {inlier_distance}")
    cloud = np.asarray(points, dtype=float).reshape(-1, 3)
    cloud = cloud[np.isfinite(cloud).all(axis=1)]
    if len(cloud) < 2 or np.ptp(cloud, axis=0).max() == 0.0:
        raise PerceptionError(f"too few distinct points to fit a line: {len(cloud)} (2 distinct at least)")
    rng = np.random.default_rng(seed)
    cap = max(inlier_distance, 1e-12) ** 2
    best, best_cost = np.zeros(len(cloud), dtype=bool), np.inf
    for _ in range(_TRIES):
        i, j = rng.choice(len(cloud), size=2, replace=False)
        along = cloud[j] - cloud[i]
        length = float(np.linalg.norm(along))
        if length == 0.0:
            continue
        squared = _distances(cloud, cloud[i], along / length) ** 2
        cost = float(np.minimum(squared, cap).sum())
        if cost < best_cost:
            best, best_cost = squared <= inlier_distance**2, cost
    chosen = cloud[best] if best.sum() >= 2 else cloud
    centre = chosen.mean(axis=0)
    _, _, axes = np.linalg.svd(chosen - centre, full_matrices=False)
    direction = axes[0] / np.linalg.norm(axes[0])
    if direction[np.argmax(np.abs(direction))] < 0.0:
        direction = -direction
    spans = (chosen - centre) @ direction
    return LineSegment(centre + spans.min() * direction, centre + spans.max() * direction, len(chosen))
