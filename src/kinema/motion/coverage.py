"""Coverage paths: the back-and-forth (boustrophedon) raster that sweeps a tool over a rectangle.

The rectangle lies in the x-y plane of its *corner* pose, the corner being its bottom-right one as seen
looking down the pose's z axis from its +z side (x to the right, y up): the rectangle spans ``width`` along
the corner's -x and ``height`` along its +y. Passes run along the width, one every ``stride`` up the height
(the last one on the top edge, so the whole rectangle is swept), alternating direction; every pose keeps
the corner's orientation, so a tool whose z points along the corner's z faces the surface throughout.

Example: ``raster_poses(corner, 0.5, 0.2, 0.1)`` gives 6 poses: (0, 0) (-0.5, 0) (-0.5, 0.1) (0, 0.1)
(0, 0.2) (-0.5, 0.2) in the corner's frame, each pass's two ends (a straight-line planner joins them).
"""

from __future__ import annotations

import numpy as np

from kinema.errors import MotionError

__all__ = ["MAX_PASSES", "raster_poses"]

# More passes than this is a typo in the stride (1 mm over 10 m), not a path a robot should follow.
MAX_PASSES = 10_000


def raster_poses(corner: np.ndarray, width: float, height: float, stride: float) -> list[np.ndarray]:
    """The ends of each pass of the raster over the rectangle (see the module docstring), in order.

    Args:
        corner: ``frame_T_corner``, shape ``(4, 4)``; the poses are returned in the same ``frame``.
        width: length of each pass (m), > 0.
        height: distance the passes cover across (m), >= 0 (0: one pass).
        stride: distance between passes (m), > 0.

    Raises:
        MotionError: a size that is not finite and positive (height may be 0), or more than
            :data:`MAX_PASSES` passes.
    """
    corner = np.asarray(corner, dtype=float)
    if corner.shape != (4, 4) or not np.all(np.isfinite(corner)):
        raise MotionError("the corner must be a finite 4x4 pose")
    if not (np.isfinite(width) and width > 0):
        raise MotionError(f"width must be > 0 m, got {width}")
    if not (np.isfinite(height) and height >= 0):
        raise MotionError(f"height must be >= 0 m, got {height}")
    if not (np.isfinite(stride) and stride > 0):
        raise MotionError(f"stride_distance must be > 0 m, got {stride}")
    steps = int(np.floor(height / stride + 1e-9))
    levels = [k * stride for k in range(steps + 1)]
    if height - levels[-1] > 1e-9:
        levels.append(height)  # the top edge: the passes cover the whole height
    if len(levels) > MAX_PASSES:
        raise MotionError(
            f"a stride of {stride} m over {height} m makes {len(levels)} passes, more than {MAX_PASSES}"
        )
    poses = []
    for index, y in enumerate(levels):
        ends = (0.0, -width) if index % 2 == 0 else (-width, 0.0)
        for x in ends:
            offset = np.eye(4)
            offset[:3, 3] = (x, y, 0.0)
            poses.append(corner @ offset)
    return poses
