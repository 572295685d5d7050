"""A pinhole camera's intrinsics, in ROS's convention (``sensor_msgs/CameraInfo``: pixel centres at integers).

MuJoCo renders with a symmetric frustum given by the vertical field of view ``fovy`` and square pixels,
so ``fy = (height / 2) / tan(fovy / 2)``, ``fx = fy`` and the principal point is the image centre, which
in pixel-centre coordinates is ``((width - 1) / 2, (height - 1) / 2)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CameraIntrinsics:
    """Image size (pixels) and pinhole parameters (pixels): ``u = fx X/Z + cx``, ``v = fy Y/Z + cy``."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @classmethod
    def from_fovy(cls, width: int, height: int, fovy_degrees: float) -> CameraIntrinsics:
        """Intrinsics of a symmetric frustum with square pixels and vertical field of view ``fovy``."""
        f = (height / 2.0) / math.tan(math.radians(fovy_degrees) / 2.0)
        return cls(width, height, f, f, (width - 1) / 2.0, (height - 1) / 2.0)

    @property
    def k(self) -> np.ndarray:
        """The 3x3 camera matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def project(self, points: np.ndarray) -> np.ndarray:
        """Pixel coordinates (Nx2: u, v) of Nx3 points in the optical frame (z forward, y down)."""
        points = np.asarray(points, dtype=float)
        z = points[:, 2]
        return np.stack([self.fx * points[:, 0] / z + self.cx, self.fy * points[:, 1] / z + self.cy], axis=1)
