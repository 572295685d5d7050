"""MergePointClouds: several clouds of one frame as one, thinned by a voxel grid."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import PerceptionError

from ..messages.ports import (
    fails_on_bad_input,
    message_output,
    port_error,
    read_input,
    read_vector,
)
from .clouds import POINT_CLOUD, frame_of, write_cloud


class MergePointClouds(SyncBehavior):
    """Merges the clouds of ``point_clouds`` (all in one frame: TransformPointCloudFrame them first) into
    one with a point per occupied cube of side ``grid_resolution_meters`` (the mean of its points).

    With ``align_point_clouds`` each cloud is first aligned to the ones before it by point-to-point ICP
    (pairs closer than ``icp_correspondence_distance``, at most ``icp_max_iterations`` rounds), for views
    whose poses are a little off; a cloud ICP cannot align is merged as it is, with a warning. Fails naming
    the clouds' frames when they differ, and on an empty vector.
    """

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            # Untyped, as PlanCartesianPath's path: vectors built by ResetVector/PushBackVector hold Any.
            input_port(
                "point_clouds", None, "{point_clouds}", "The clouds to merge (std::vector<PointCloud2>)."
            ),
            input_port("grid_resolution_meters", float, 0.01, "Side of the voxel grid's cubes (m)."),
            input_port(
                "align_point_clouds", bool, False, "Align each cloud to the previous ones by ICP first."
            ),
            input_port(
                "icp_correspondence_distance",
                float,
                0.05,
                "With align_point_clouds: points further apart (m) are not paired by ICP (MoveIt Pro's "
                "default is not public; Kinema's: 0.05, what its objectives give).",
            ),
            input_port(
                "icp_max_iterations",
                int,
                20,
                "With align_point_clouds: most ICP rounds per cloud (MoveIt Pro's default is not public; "
                "Kinema's: 20, what its objectives give).",
            ),
            message_output("merged_cloud", POINT_CLOUD, "{merged_cloud}", "The merged cloud."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        from kinema.perception import merge_clouds, register_icp
        from kinema.perception.ros_messages import from_point_cloud2

        messages = read_vector(self, "point_clouds")
        if not messages:
            raise port_error(
                self, "point_clouds", "is an empty vector", "add clouds with PushBackVector first"
            )
        clouds = []
        for index, message in enumerate(messages):
            if getattr(message, "__msgtype__", None) != POINT_CLOUD:
                raise port_error(
                    self, "point_clouds", f"element {index} is not a {POINT_CLOUD}", "push point clouds only"
                )
            clouds.append(from_point_cloud2(message))
        resolution = float(read_input(self, "grid_resolution_meters"))
        if not resolution > 0:
            raise port_error(
                self, "grid_resolution_meters", f"= {resolution}", "give a length > 0 m, e.g. 0.01"
            )
        frames = sorted({frame_of(c) for c in clouds})
        if len(frames) > 1:
            raise port_error(
                self,
                "point_clouds",
                f"holds clouds in frames {', '.join(frames)}",
                "bring them into one frame with TransformPointCloudFrame before merging",
            )
        clouds = [c if c.frame_id else c.transformed(np.eye(4), "world") for c in clouds]
        if bool(read_input(self, "align_point_clouds")) and len(clouds) > 1:
            distance = float(read_input(self, "icp_correspondence_distance"))
            if not distance > 0:
                raise port_error(self, "icp_correspondence_distance", f"= {distance}", "give a length > 0 m")
            iterations = int(read_input(self, "icp_max_iterations"))
            if iterations < 1:
                raise port_error(self, "icp_max_iterations", f"= {iterations}", "give 1 or more")
            aligned = [clouds[0].finite()]
            for cloud in clouds[1:]:
                reference = merge_clouds(aligned, resolution)
                try:
                    result = register_icp(
                        cloud, reference, max_correspondence_distance=distance, max_iterations=iterations
                    )
                    cloud = cloud.transformed(result.target_T_source)
                except PerceptionError as error:
                    self.logger.publish_warn(f"MergePointClouds: a cloud was merged unaligned: {error}")
                aligned.append(cloud.finite())
            clouds = aligned
        write_cloud(self, "merged_cloud", merge_clouds(clouds, resolution))
        return NodeStatus.SUCCESS
