"""TransformPoseWithPose: compose two poses (apply ``transform_pose`` on top of ``input_pose``)."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior

from ..messages.conversions import POSE_STAMPED_TYPE, pose_matrix, pose_stamped_message
from ..messages.ports import fails_on_bad_input, message_input, message_output, read_message


class TransformPoseWithPose(SyncBehavior):
    """Writes ``transform_pose * input_pose``, in ``transform_pose``'s frame.

    ``input_pose`` is read as a pose relative to the frame that ``transform_pose`` places: a grasp
    relative to a detected tag (``input_pose``) composed with the tag's pose in the world
    (``transform_pose``) gives the grasp in the world.
    """

    subcategory = "Math - Poses"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("input_pose", POSE_STAMPED_TYPE, "{input_pose}", "The pose to transform."),
            message_input(
                "transform_pose",
                POSE_STAMPED_TYPE,
                "{transform_pose}",
                "The transform to apply on top of it.",
            ),
            message_output("output_pose", POSE_STAMPED_TYPE, "{output_pose}", "transform_pose * input_pose."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        _, pose = pose_matrix(read_message(self, "input_pose"), "input_pose")
        frame, transform = pose_matrix(read_message(self, "transform_pose"), "transform_pose")
        self.set_output("output_pose", pose_stamped_message(frame, transform @ pose))
        return NodeStatus.SUCCESS
