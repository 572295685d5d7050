"""CalculatePoseOffset: the pose of one pose relative to another."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior
from kinema.errors import KinemaError

from ..messages.conversions import POSE_STAMPED_TYPE, pose_matrix, pose_stamped_message
from ..messages.ports import fails_on_bad_input, message_input, message_output, read_message
from .frame_tree import current_frame_tree


class CalculatePoseOffset(SyncBehavior):
    """Writes ``source_to_destination_pose = inverse(source_pose) * destination_pose``.

    The result is ``destination_pose`` seen from ``source_pose`` (a grasp relative to a detected tag),
    so ``TransformPoseWithPose`` with ``transform_pose`` = the source gives the destination back. Poses
    in different frames are first brought into the source's frame through the frame tree. The result's
    ``frame_id`` is the source pose's frame (MoveIt Pro's choice is not public; this is what composing
    it back with TransformPoseWithPose needs).
    """

    subcategory = "Math - Poses"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("source_pose", POSE_STAMPED_TYPE, "{source_pose}", "The reference pose."),
            message_input("destination_pose", POSE_STAMPED_TYPE, "{destination_pose}", "The other pose."),
            message_output(
                "source_to_destination_pose",
                POSE_STAMPED_TYPE,
                "{source_to_destination_pose}",
                "destination_pose relative to source_pose.",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        source_frame, source = pose_matrix(read_message(self, "source_pose"), "source_pose")
        destination_frame, destination = pose_matrix(
            read_message(self, "destination_pose"), "destination_pose"
        )
        if destination_frame != source_frame and {destination_frame, source_frame} - {"", "world"}:
            try:
                destination = current_frame_tree(self).transform(destination, destination_frame, source_frame)
            except KinemaError as error:
                self.logger.publish_failure(f"CalculatePoseOffset: {error}")
                return NodeStatus.FAILURE
        offset = np.linalg.inv(source) @ destination
        self.set_output("source_to_destination_pose", pose_stamped_message(source_frame, offset))
        return NodeStatus.SUCCESS
