"""TransformPoseFrame: the same pose, expressed in another frame of the cell."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import KinemaError

from ..messages.conversions import POSE_STAMPED_TYPE, pose_matrix, pose_stamped_message
from ..messages.ports import fails_on_bad_input, message_input, message_output, read_message
from .frame_tree import current_frame_tree


class TransformPoseFrame(SyncBehavior):
    """Writes ``input_pose`` expressed in ``target_frame_id`` (same place in the world, other frame).

    Frames are the robot's links at the current joint state (``world``, ``base_link``, ``tool0``,
    ``grasp_link``, ...), the simulated objects, the world-fixed cameras and the planning scene's
    objects. Fails naming the frame and the closest known frames when either frame does not exist.
    """

    subcategory = "Math - Poses"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("input_pose", POSE_STAMPED_TYPE, "{input_pose}", "The pose to re-express."),
            input_port("target_frame_id", str, "world", "The frame to express it in."),
            message_output("output_pose", POSE_STAMPED_TYPE, "{output_pose}", "The pose in target_frame_id."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        source, matrix = pose_matrix(read_message(self, "input_pose"), "input_pose")
        target = str(self.get_input("target_frame_id"))
        if source == target or {source, target} <= {"", "world"}:
            self.set_output("output_pose", pose_stamped_message(target, matrix))
            return NodeStatus.SUCCESS
        try:
            result = current_frame_tree(self).transform(matrix, source, target)
        except KinemaError as error:
            self.logger.publish_failure(f"TransformPoseFrame: cannot express the pose in {target!r}: {error}")
            return NodeStatus.FAILURE
        self.set_output("output_pose", pose_stamped_message(target, result))
        return NodeStatus.SUCCESS
