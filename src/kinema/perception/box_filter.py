"""Keep or drop the points inside a box posed in the cloud's frame (MoveIt Pro's CropPointsInBox and
RemovePointsInBox do this on PointCloud2 messages)."""

from __future__ import annotations

import numpy as np

from kinema.errors import PerceptionError
from kinema.perception.point_cloud import PointCloud


def inside_box(cloud: PointCloud, cloud_T_box: np.ndarray, size: tuple[float, float, float]) -> np.ndarray:
    """Boolean mask of the points within the box of full extents ``size`` (m) centred at ``cloud_T_box``.

    NaN points are never inside. Points on a face count as inside.

    Raises:
        PerceptionError: a size is negative or the pose is not 4x4.
    """
    extents = np.asarray(size, dtype=float)
    if extents.shape != (3,) or np.any(extents < 0):
        raise PerceptionError(f"a box size needs three lengths >= 0 (m), got {tuple(np.ravel(size))}")
    transform = np.asarray(cloud_T_box, dtype=float)
    if transform.shape != (4, 4):
        raise PerceptionError(f"a box pose must be 4x4, got shape {transform.shape}")
    rotation, centre = transform[:3, :3], transform[:3, 3]
    local = (cloud.points - centre) @ rotation  # rows: R^T (p - c)
    with np.errstate(invalid="ignore"):
        return np.all(np.abs(local) <= extents / 2.0, axis=1)


def crop_box(cloud: PointCloud, cloud_T_box: np.ndarray, size: tuple[float, float, float]) -> PointCloud:
    """The points inside the box (an unorganised cloud)."""
    return cloud.select(inside_box(cloud, cloud_T_box, size))


def remove_box(cloud: PointCloud, cloud_T_box: np.ndarray, size: tuple[float, float, float]) -> PointCloud:
    """The finite points outside the box (an unorganised cloud)."""
    finite = np.isfinite(cloud.points).all(axis=1)
    return cloud.select(finite & ~inside_box(cloud, cloud_T_box, size))
