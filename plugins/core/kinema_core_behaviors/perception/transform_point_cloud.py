"""TransformPointCloudFrame and TransformPointCloud: the same points in another frame, or moved by a pose."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from ..messages.conversions import POSE_STAMPED_TYPE, pose_matrix
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_output,
    port_error,
    read_input,
    read_message,
)
from .clouds import POINT_CLOUD, frame_of, read_cloud, target_T_source, write_cloud


class TransformPointCloudFrame(SyncBehavior):
    """Writes ``input_cloud`` expressed in ``target_frame`` (the same points in the world, other frame).

    Frames are those TransformPoseFrame knows (robot links, camera optical frames, simulated objects,
    planning-scene objects), with the robot's joints as they were at the cloud's stamp, as TF looks up a
    transform at a message's stamp: a wrist camera's cloud lands where the camera was when it was taken.
    An organised cloud stays organised. Fails naming the frame when either frame is unknown.
    """

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("input_cloud", POINT_CLOUD, "{point_cloud}", "The cloud to re-express."),
            input_port("target_frame", str, "world", "The frame to express it in."),
            message_output("output_cloud", POINT_CLOUD, "{point_cloud}", "The cloud in target_frame."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        cloud = read_cloud(self, "input_cloud")
        target = str(read_input(self, "target_frame")).strip()
        if not target:
            raise port_error(self, "target_frame", "is empty", "give a frame, e.g. world")
        transform = target_T_source(self, frame_of(cloud), target, "target_frame", at=cloud.stamp)
        write_cloud(self, "output_cloud", cloud.transformed(transform, target))
        return NodeStatus.SUCCESS


class TransformPointCloud(SyncBehavior):
    """Moves every point of ``input_cloud`` by the rigid transform ``transform_pose``.

    The pose is read as a transform in its own frame: the cloud is first expressed in that frame (when
    it is another one), then each point ``p`` becomes ``T p``. A model cloud in ``world`` moved by a pose
    in ``world`` lands where the pose says.
    """

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("input_cloud", POINT_CLOUD, "{point_cloud}", "The cloud to move."),
            message_input(
                "transform_pose",
                POSE_STAMPED_TYPE,
                "{transform_pose}",
                "The transform to apply to the points.",
            ),
            message_output("output_cloud", POINT_CLOUD, "{output_cloud}", "The moved cloud."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        cloud = read_cloud(self, "input_cloud")
        pose_frame, transform = pose_matrix(read_message(self, "transform_pose"), "transform_pose")
        frame = pose_frame or frame_of(cloud)
        in_frame = target_T_source(self, frame_of(cloud), frame, "transform_pose", at=cloud.stamp)
        write_cloud(self, "output_cloud", cloud.transformed(transform @ in_frame, frame))
        return NodeStatus.SUCCESS
