"""CalibrateCameraPose: where a camera really is, from three tags on a calibration tool it sees."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import KinemaError

from ..messages.conversions import POSE_STAMPED_TYPE, pose_stamped_message
from ..messages.ports import fails_on_bad_input, message_input, message_output, port_error, read_input
from .clouds import pose_in_frame


class CalibrateCameraPose(SyncBehavior):
    """Computes the pose of ``camera_optical_frame`` in ``base_link`` from the detected poses of the three
    tags of a calibration tool (``left_tag_pose``, ``right_tag_pose``, ``bottom_tag_pose``) and writes it to
    ``computed_pose``.

    The tool's frame is defined by the tags' centres: origin at their centroid, x from the left tag to the
    right one, y from the bottom tag toward the middle of the other two, z = x cross y; the robot description
    must place ``calibration_tool_frame`` so. Its pose in ``base_link`` comes from the robot (at the
    current joint state) and the tags' positions, brought into ``camera_optical_frame``, give the tool as
    the camera sees it; the camera is where both agree. Average several results (AveragePoseStampedVector)
    to beat detection noise. (MoveIt Pro's tool convention is not public; this is Kinema's.) Fails on a
    frame the cell does not know and on tags that define no frame (two at one place, or all on a line).
    """

    subcategory = "Perception - Camera Calibration"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("base_link", str, "world", "The frame the camera's pose is written in."),
            input_port(
                "calibration_tool_frame", str, "", "The robot description's frame of the calibration tool."
            ),
            input_port("camera_optical_frame", str, "", "The camera's optical frame (the one calibrated)."),
            *(
                message_input(f"{side}_tag_pose", POSE_STAMPED_TYPE, f"{{{side}_pose}}", f"The {side} tag.")
                for side in ("left", "right", "bottom")
            ),
            message_output(
                "computed_pose", POSE_STAMPED_TYPE, "{computed_pose}", "The camera's pose in base_link."
            ),
        ]

    def _frame(self, port: str) -> str:
        name = str(read_input(self, port)).strip() if port in self.config.input_ports else ""
        if not name:
            raise port_error(self, port, "is empty", "name a frame of the cell")
        return name

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.perception import camera_in_base

        from ..poses.frame_tree import current_frame_tree

        base, tool, camera = (
            self._frame(p) for p in ("base_link", "calibration_tool_frame", "camera_optical_frame")
        )
        centres: list[Any] = [
            pose_in_frame(self, f"{side}_tag_pose", camera)[:3, 3] for side in ("left", "right", "bottom")
        ]
        try:
            tree = current_frame_tree(self)
            base_T_tool = tree.transform(tree.world_T(tool), "world", base)
            computed = camera_in_base(base_T_tool, *centres)
        except KinemaError as error:
            self.logger.publish_failure(f"CalibrateCameraPose: {error}")
            return NodeStatus.FAILURE
        self.set_output("computed_pose", pose_stamped_message(base, computed))
        return NodeStatus.SUCCESS
