"""FindMaskedObjects: each masked object of a camera's cloud as a box-shaped graspable object."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    port_error,
    read_input,
    read_message,
    read_vector,
    write_output,
)
from .clouds import CAMERA_INFO, POINT_CLOUD, frame_of, read_cloud, target_T_source
from .graspable_objects import graspable_box
from .masks import mask_image


def fit_box(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(pose 4x4, full sizes 3)`` of the box around ``points`` (Nx3) aligned with their principal axes
    in the horizontal plane and with the frame's z (objects stand on a table)."""
    import numpy as np

    centre_xy = points[:, :2].mean(axis=0)
    flat = points[:, :2] - centre_xy
    _, _, axes = np.linalg.svd(flat, full_matrices=False)
    x_axis = np.append(axes[0], 0.0)
    x_axis /= np.linalg.norm(x_axis)
    rotation = np.column_stack([x_axis, np.cross([0.0, 0.0, 1.0], x_axis), [0.0, 0.0, 1.0]])
    local = (points - np.append(centre_xy, 0.0)) @ rotation
    lower, upper = local.min(axis=0), local.max(axis=0)
    pose = np.eye(4)
    pose[:3, :3] = rotation
    pose[:3, 3] = np.append(centre_xy, 0.0) + rotation @ ((lower + upper) / 2)
    return pose, upper - lower


# Width (pixels) of the ring around a mask whose points give the surface the object stands on.
SUPPORT_RING_PIXELS = 6


def down_to_support(
    pose: np.ndarray, size: np.ndarray, support: float | None, tolerance: float
) -> tuple[np.ndarray, np.ndarray]:
    """The box extended down to height ``support`` (z of the frame) when its bottom is above it."""
    bottom = pose[2, 3] - size[2] / 2
    if support is None or support >= bottom - tolerance:
        return pose, size
    top = pose[2, 3] + size[2] / 2
    pose, size = pose.copy(), size.copy()
    pose[2, 3], size[2] = (top + support) / 2, top - support
    return pose, size


class FindMaskedObjects(SyncBehavior):
    """For each 2D mask of ``masks2d``, the points of ``point_cloud`` on it, in ``base_frame``, as a
    GraspableObject: a box around them aligned with their principal horizontal axes and the frame's z.

    Points further than ``plane_inlier_threshold`` beyond the 2nd-98th percentile of the object's extent
    are dropped as stray depth at its edges. A camera looking down sees only an object's top, so the box
    reaches down to the surface around the mask (the median height of the pixels just outside it) when
    that surface is lower. A mask whose box has a largest face smaller than
    ``minimum_face_area`` is skipped. ``face_separation_threshold`` is accepted for MoveIt Pro's files;
    Kinema fits one box an object rather than separating its faces.
    """

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The camera's cloud."),
            message_input("camera_info", CAMERA_INFO, "{camera_info}", "The camera's intrinsics."),
            input_port("masks2d", None, "{masks2d}", "The image masks (std::vector<Mask2D>)."),
            input_port("base_frame", str, "world", "The frame the objects are expressed in."),
            input_port("plane_inlier_threshold", float, 0.01, "Tolerance (m) around an object's extent."),
            input_port("minimum_face_area", float, 0.000625, "Smallest largest-face area (m²) kept."),
            input_port("face_separation_threshold", float, 0.01, "MoveIt Pro's face split distance (m)."),
            output_port(
                "detected_shapes", None, "{detected_shapes}", "The objects (std::vector<GraspableObject>)."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        from kinema.perception.ros_messages import intrinsics_of

        cloud = read_cloud(self, "point_cloud")
        camera = intrinsics_of(read_message(self, "camera_info", CAMERA_INFO))
        if cloud.shape != (camera.height, camera.width):
            raise port_error(
                self,
                "point_cloud",
                f"is not an organised {camera.width}x{camera.height} cloud (shape {cloud.shape})",
                "give the camera's own cloud from GetPointCloud",
            )
        base = str(read_input(self, "base_frame"))
        tolerance = float(read_input(self, "plane_inlier_threshold"))
        minimum_area = float(read_input(self, "minimum_face_area"))
        read_input(self, "face_separation_threshold")
        moved = cloud.transformed(target_T_source(self, frame_of(cloud), base, "base_frame"), base)
        objects: list[Any] = []
        for index, mask in enumerate(read_vector(self, "masks2d")):
            pixels = mask_image(self, "masks2d", index, mask, camera.width, camera.height).reshape(-1)
            points = moved.points[pixels].astype(float)
            points = points[np.isfinite(points).all(axis=1)]
            if len(points) < 10:
                continue
            low, high = np.percentile(points, 2, axis=0), np.percentile(points, 98, axis=0)
            points = points[np.all((points >= low - tolerance) & (points <= high + tolerance), axis=1)]
            pose, size = fit_box(points)
            pose, size = down_to_support(pose, size, self._support_height(moved, pixels, camera), tolerance)
            largest_face = max(size[0] * size[1], size[1] * size[2], size[0] * size[2])
            if largest_face < minimum_area:
                continue
            objects.append(graspable_box(base, f"object_{index}", pose, size))
        write_output(self, "detected_shapes", objects)
        return NodeStatus.SUCCESS

    @staticmethod
    def _support_height(cloud: Any, pixels: np.ndarray, camera: Any) -> float | None:
        import numpy as np
        from scipy.ndimage import binary_dilation

        mask = pixels.reshape(camera.height, camera.width)
        ring = binary_dilation(mask, iterations=SUPPORT_RING_PIXELS) & ~mask
        heights = cloud.points[ring.reshape(-1), 2].astype(float)
        heights = heights[np.isfinite(heights)]
        return float(np.median(heights)) if len(heights) else None
