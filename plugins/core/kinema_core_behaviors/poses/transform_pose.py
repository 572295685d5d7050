"""TransformPose: offset a pose by a translation and rotation expressed in the pose's own frame."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import ObjectiveError

from ..messages.conversions import POSE_STAMPED_TYPE, pose_matrix, pose_stamped_message
from ..messages.ports import fails_on_bad_input, message_input, message_output, read_floats, read_message
from ..messages.pose_stamped import pose_from_ports
from ..ui.visualize_pose import publish_pose_marker


class TransformPose(SyncBehavior):
    """Writes ``input_pose`` moved by ``translation_xyz`` and rotated by ``quaternion_xyzw``.

    The offset is applied in the input pose's own axes (``output = input * offset``): translation
    ``0;0;-0.1`` moves a tool pose 10 cm back along its own z axis. The output keeps the input's frame.
    With ``visualize_pose`` the result is also drawn, as VisualizePose does.
    """

    subcategory = "Math - Poses"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("input_pose", POSE_STAMPED_TYPE, "{input_pose}", "The pose to move."),
            input_port(
                "translation_xyz", list[float], "0.0;0.0;0.0", "Translation x;y;z (m), in the pose's axes."
            ),
            input_port(
                "quaternion_xyzw", list[float], "0.0;0.0;0.0;1.0", "Rotation x;y;z;w, in the pose's axes."
            ),
            message_output("output_pose", POSE_STAMPED_TYPE, "{output_pose}", "The moved pose."),
            input_port("visualize_pose", bool, False, "Also draw the result."),
            input_port("marker_text", str, "", "Label of the drawn pose."),
            input_port("marker_lifetime", float, 0.0, "Seconds the drawn pose stays (0: until replaced)."),
            input_port("marker_size", float, 0.1, "Size of the drawn triad (m)."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        offset = pose_from_ports(
            read_floats(self, "translation_xyz", 3, "x;y;z (m)"),
            read_floats(self, "quaternion_xyzw", 4, "x;y;z;w"),
            "TransformPose:",
        )
        if isinstance(offset, str):
            self.logger.publish_failure(offset)
            return NodeStatus.FAILURE
        try:
            frame_id, matrix = pose_matrix(read_message(self, "input_pose"), "input_pose")
            output = pose_stamped_message(frame_id, matrix @ offset)
            self.set_output("output_pose", output)
            if bool(self.get_input("visualize_pose")):
                text = str(self.get_input_or("marker_text", ""))
                publish_pose_marker(
                    self,
                    output,
                    text or self.name or "transformed_pose",
                    float(self.get_input("marker_size")),
                    float(self.get_input("marker_lifetime")),
                    text,
                )
        except ObjectiveError as error:
            self.logger.publish_failure(f"TransformPose: {error}")
            return NodeStatus.FAILURE
        return NodeStatus.SUCCESS
