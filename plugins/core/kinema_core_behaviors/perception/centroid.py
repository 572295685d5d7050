"""GetCentroidFromPointCloud: the mean of a cloud's points, as a pose."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior

from ..messages.conversions import POSE_STAMPED_TYPE, pose_stamped_message
from ..messages.ports import fails_on_bad_input, message_input, message_output, port_error, write_output
from .clouds import POINT_CLOUD, read_cloud


class GetCentroidFromPointCloud(SyncBehavior):
    """Writes the centroid of ``point_cloud``'s finite points as a pose in the cloud's frame (identity
    orientation). Fails when the cloud has no finite point."""

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud."),
            message_output("output_pose", POSE_STAMPED_TYPE, "{output_pose}", "Its centroid, in its frame."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        from kinema.errors import PerceptionError

        cloud = read_cloud(self, "point_cloud")
        try:
            centre = cloud.centroid()
        except PerceptionError as error:
            raise port_error(
                self, "point_cloud", str(error), "crop less away, or check the camera sees something"
            ) from None
        pose = np.eye(4)
        pose[:3, 3] = centre
        write_output(self, "output_pose", pose_stamped_message(cloud.frame_id, pose))
        return NodeStatus.SUCCESS
