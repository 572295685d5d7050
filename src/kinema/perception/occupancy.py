"""Occupancy from a point cloud: the cubes of a grid that hold points, as obstacles for the planner.

This is what an octomap gives MoveIt at one resolution: space a camera saw a surface in is occupied.
Cells inside *keep-out* boxes (the robot's own links, seen by the camera, and obstacles the planning
scene already has) are dropped, so the robot does not collide with its own image and the table is not
doubled.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from kinema.errors import PerceptionError


def occupied_cells(points: np.ndarray, resolution: float, min_points: int = 1) -> np.ndarray:
    """Centres (Mx3, m) of the grid cubes of side ``resolution`` holding at least ``min_points`` points.

    NaN points are ignored. The grid is aligned with the points' frame, a cell corner at its origin.

    Raises:
        PerceptionError: ``resolution`` is not a positive length.
    """
    if not resolution > 0 or not np.isfinite(resolution):
        raise PerceptionError(f"occupancy resolution must be a positive length (m), got {resolution}")
    finite = np.asarray(points, dtype=float)
    finite = finite[np.isfinite(finite).all(axis=1)]
    if len(finite) == 0:
        return np.empty((0, 3))
    keys, counts = np.unique(np.floor(finite / resolution).astype(np.int64), axis=0, return_counts=True)
    return (keys[counts >= max(1, min_points)] + 0.5) * resolution


def outside_boxes(
    centres: np.ndarray, boxes: Sequence[tuple[np.ndarray, np.ndarray]], margin: float = 0.0
) -> np.ndarray:
    """The rows of ``centres`` not within ``margin`` of any axis-aligned box ``(lower, upper)`` corners."""
    keep = np.ones(len(centres), dtype=bool)
    for lower, upper in boxes:
        inside = np.all(
            (centres >= np.asarray(lower) - margin) & (centres <= np.asarray(upper) + margin), axis=1
        )
        keep &= ~inside
    return centres[keep]


def aabb_of_box(world_T_box: np.ndarray, half_extents: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """World-axis-aligned bounds ``(lower, upper)`` of a posed box of ``half_extents`` (m)."""
    transform = np.asarray(world_T_box, dtype=float)
    reach = np.abs(transform[:3, :3]) @ np.asarray(half_extents, dtype=float)
    return transform[:3, 3] - reach, transform[:3, 3] + reach
