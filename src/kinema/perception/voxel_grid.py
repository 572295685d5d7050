"""Voxel-grid downsampling: one point per occupied cube of side ``resolution``, at the mean of the points
(and colours) that fall in it — what PCL's VoxelGrid does, and how MoveIt Pro's MergePointClouds thins
the union of several clouds."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from kinema.errors import PerceptionError
from kinema.perception.point_cloud import PointCloud


def voxel_downsample(cloud: PointCloud, resolution: float) -> PointCloud:
    """One point per occupied voxel (the centroid of its points); NaN points are dropped.

    Raises:
        PerceptionError: ``resolution`` is not a positive number.
    """
    if not resolution > 0 or not np.isfinite(resolution):
        raise PerceptionError(f"voxel grid resolution must be a positive length (m), got {resolution}")
    finite = cloud.finite()
    if len(finite) == 0:
        return finite
    points = finite.points.astype(np.float64)
    keys = np.floor(points / resolution).astype(np.int64)
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    sums = np.zeros((len(counts), 3))
    np.add.at(sums, inverse, points)
    merged = sums / counts[:, None]
    colors = None
    if finite.colors is not None:
        color_sums = np.zeros((len(counts), 3))
        np.add.at(color_sums, inverse, finite.colors.astype(np.float64))
        colors = np.round(color_sums / counts[:, None]).astype(np.uint8)
    return replace(finite, points=merged.astype(cloud.points.dtype), colors=colors, shape=None)


def merge_clouds(clouds: Sequence[PointCloud], resolution: float) -> PointCloud:
    """The union of ``clouds`` (all in one frame), voxel-downsampled at ``resolution``.

    Colours are kept only when every cloud has them. The result takes the latest stamp.

    Raises:
        PerceptionError: no clouds, or clouds in different frames.
    """
    if not clouds:
        raise PerceptionError("there are no point clouds to merge")
    frames = sorted({c.frame_id for c in clouds})
    if len(frames) > 1:
        raise PerceptionError(
            f"point clouds to merge must share a frame; got {', '.join(repr(f) for f in frames)} "
            "(transform them into one frame first)"
        )
    with_colors = all(c.colors is not None for c in clouds)
    union = PointCloud(
        np.concatenate([c.points for c in clouds]),
        np.concatenate([c.colors for c in clouds if c.colors is not None]) if with_colors else None,
        frame_id=frames[0],
        stamp=max(c.stamp for c in clouds),
    )
    return voxel_downsample(union, resolution)
