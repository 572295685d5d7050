"""A point cloud: an Nx3 array of points in metres, optional Nx3 uint8 colours, and the frame they are in.

An *organised* cloud (as a depth camera produces) keeps one point per pixel, row-major, with NaN where the
camera saw nothing; ``shape`` is then ``(height, width)``. Operations that drop points return an
unorganised cloud (``shape`` None).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from kinema.errors import PerceptionError


@dataclass(frozen=True)
class PointCloud:
    """Points (Nx3 float, m) in ``frame_id``, with optional colours (Nx3 uint8, RGB).

    Attributes:
        points: Nx3 array; NaN rows are "no return" in an organised cloud.
        colors: Nx3 uint8 array or None.
        frame_id: the frame the points are expressed in.
        stamp: time of capture, s (sim time for simulated cameras).
        shape: ``(height, width)`` of an organised cloud (``height * width == N``), else None.
    """

    points: np.ndarray
    colors: np.ndarray | None = None
    frame_id: str = ""
    stamp: float = 0.0
    shape: tuple[int, int] | None = field(default=None)

    def __post_init__(self) -> None:
        points = np.asarray(self.points)
        if points.ndim != 2 or points.shape[1] != 3:
            raise PerceptionError(f"a point cloud's points must be Nx3, got shape {points.shape}")
        object.__setattr__(self, "points", points)
        if self.colors is not None:
            colors = np.asarray(self.colors, dtype=np.uint8)
            if colors.shape != points.shape:
                raise PerceptionError(
                    f"a point cloud's colours must match its points ({points.shape}), got {colors.shape}"
                )
            object.__setattr__(self, "colors", colors)
        if self.shape is not None and self.shape[0] * self.shape[1] != len(points):
            raise PerceptionError(f"organised shape {self.shape} does not hold {len(points)} points")

    def __len__(self) -> int:
        return len(self.points)

    def finite(self) -> PointCloud:
        """The points that are not NaN/inf (an unorganised cloud)."""
        keep = np.isfinite(self.points).all(axis=1)
        return self.select(keep)

    def select(self, keep: np.ndarray) -> PointCloud:
        """The points where boolean mask ``keep`` is true (an unorganised cloud)."""
        return replace(
            self,
            points=self.points[keep],
            colors=None if self.colors is None else self.colors[keep],
            shape=None,
        )

    def transformed(self, target_T_source: np.ndarray, frame_id: str | None = None) -> PointCloud:
        """The points moved by the 4x4 transform ``target_T_source``, labelled ``frame_id``.

        NaN points stay NaN, so an organised cloud stays organised.
        """
        transform = np.asarray(target_T_source, dtype=float)
        if transform.shape != (4, 4):
            raise PerceptionError(f"a transform must be 4x4, got shape {transform.shape}")
        points = self.points @ transform[:3, :3].T + transform[:3, 3]
        return replace(
            self,
            points=points.astype(self.points.dtype, copy=False),
            frame_id=self.frame_id if frame_id is None else frame_id,
        )

    def centroid(self) -> np.ndarray:
        """The mean of the finite points (3,), m.

        Raises:
            PerceptionError: the cloud has no finite point.
        """
        finite = self.points[np.isfinite(self.points).all(axis=1)]
        if len(finite) == 0:
            raise PerceptionError("the point cloud has no points, so it has no centroid")
        return np.asarray(finite.mean(axis=0), dtype=float)
