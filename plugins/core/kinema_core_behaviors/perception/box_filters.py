"""CropPointsInBox and RemovePointsInBox: keep or drop the points inside a posed box."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from ..messages.conversions import POSE_STAMPED_TYPE
from ..messages.ports import fails_on_bad_input, message_input, message_output, port_error, read_floats
from .clouds import POINT_CLOUD, frame_of, pose_in_frame, read_cloud, write_cloud


def _box(behavior: SyncBehavior, cloud: object, pose_port: str, size_port: str) -> tuple[np.ndarray, tuple]:
    import numpy as np

    size = read_floats(behavior, size_port, 3, "x;y;z (m)")
    if not all(np.isfinite(v) and v >= 0 for v in size):
        raise port_error(behavior, size_port, f"= {size}", "each size must be a length >= 0 m")
    return pose_in_frame(behavior, pose_port, frame_of(cloud)), (size[0], size[1], size[2])


class CropPointsInBox(SyncBehavior):
    """Keeps the points of ``point_cloud`` inside a box (full sizes ``crop_box_size``, x;y;z in metres)
    centred at ``crop_box_centroid_pose`` and aligned with it; the pose may be in any frame of the cell."""

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud to crop."),
            message_input(
                "crop_box_centroid_pose",
                POSE_STAMPED_TYPE,
                "{crop_box_centroid_pose}",
                "The box's centre and axes.",
            ),
            input_port("crop_box_size", list[float], "1.0;1.0;1.0", "Full size x;y;z of the box (m)."),
            message_output("point_cloud_cropped", POINT_CLOUD, "{point_cloud_cropped}", "The points inside."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.perception import crop_box

        cloud = read_cloud(self, "point_cloud")
        pose, size = _box(self, cloud, "crop_box_centroid_pose", "crop_box_size")
        write_cloud(self, "point_cloud_cropped", crop_box(cloud, pose, size))
        return NodeStatus.SUCCESS


class RemovePointsInBox(SyncBehavior):
    """Drops the points of ``point_cloud`` inside a box (full sizes ``remove_box_size``) centred at
    ``remove_box_centroid_pose``; the rest (and no NaN points) go to ``point_cloud_culled``."""

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud to cull."),
            message_input(
                "remove_box_centroid_pose",
                POSE_STAMPED_TYPE,
                "{remove_box_centroid_pose}",
                "The box's centre and axes.",
            ),
            input_port("remove_box_size", list[float], "1.0;1.0;1.0", "Full size x;y;z of the box (m)."),
            message_output("point_cloud_culled", POINT_CLOUD, "{point_cloud_culled}", "The points outside."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.perception import remove_box

        cloud = read_cloud(self, "point_cloud")
        pose, size = _box(self, cloud, "remove_box_centroid_pose", "remove_box_size")
        write_cloud(self, "point_cloud_culled", remove_box(cloud, pose, size))
        return NodeStatus.SUCCESS
