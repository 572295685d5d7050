"""Depth image → organised point cloud in the camera's optical frame (z forward, x right, y down)."""

from __future__ import annotations

import numpy as np

from kinema.errors import PerceptionError
from kinema.perception.intrinsics import CameraIntrinsics
from kinema.perception.point_cloud import PointCloud


def depth_to_cloud(
    depth: np.ndarray,
    intrinsics: CameraIntrinsics,
    colors: np.ndarray | None = None,
    *,
    frame_id: str = "",
    stamp: float = 0.0,
    max_depth: float = np.inf,
) -> PointCloud:
    """One point per pixel of ``depth`` (HxW, m along the optical axis); NaN where depth is 0, NaN or ≥ max.

    Args:
        depth: HxW depth image, metres (z, not ray length).
        intrinsics: the camera that took it (its size must be WxH).
        colors: HxWx3 uint8 RGB image aligned with ``depth``, or None.
        frame_id: the optical frame's name.
        stamp: capture time, s.
        max_depth: depths at or beyond this (the far plane, "nothing seen") become NaN.

    Raises:
        PerceptionError: the image sizes do not match the intrinsics.
    """
    depth = np.asarray(depth)
    height, width = intrinsics.height, intrinsics.width
    if depth.shape != (height, width):
        raise PerceptionError(f"depth image is {depth.shape[::-1]} (W, H), the camera is {(width, height)}")
    if colors is not None and np.asarray(colors).shape != (height, width, 3):
        raise PerceptionError(
            f"colour image has shape {np.asarray(colors).shape}, expected {(height, width, 3)}"
        )
    z = depth.astype(np.float32, copy=True)
    z[~np.isfinite(z) | (z <= 0.0) | (z >= max_depth)] = np.nan
    u = (np.arange(width, dtype=np.float32) - np.float32(intrinsics.cx)) / np.float32(intrinsics.fx)
    v = (np.arange(height, dtype=np.float32) - np.float32(intrinsics.cy)) / np.float32(intrinsics.fy)
    points = np.empty((height, width, 3), dtype=np.float32)
    np.multiply(z, u[np.newaxis, :], out=points[..., 0])
    np.multiply(z, v[:, np.newaxis], out=points[..., 1])
    points[..., 2] = z
    return PointCloud(
        points.reshape(-1, 3),
        None if colors is None else np.asarray(colors, dtype=np.uint8).reshape(-1, 3),
        frame_id=frame_id,
        stamp=stamp,
        shape=(height, width),
    )
