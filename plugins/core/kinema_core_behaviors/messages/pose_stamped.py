"""PoseStamped messages: CreatePoseStamped builds one, UnpackPoseStampedMessage splits it."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import FormerSpelling, NodeStatus, PortInfo, SyncBehavior, input_port

from .conversions import pose_stamped_message
from .ports import (
    fails_on_bad_input,
    message_input,
    message_output,
    port_error,
    read_floats,
    read_input,
    read_message,
)

POSE_STAMPED = "geometry_msgs/msg/PoseStamped"


def pose_from_ports(position: list[float], orientation: list[float], what: str) -> np.ndarray | str:
    """A 4x4 transform from ``x;y;z`` and ``x;y;z;w``, or the reason it cannot be built.

    An all-zero quaternion typed into a port is refused (a typo more often than "no rotation"), although
    :mod:`kinema.transforms` reads one in a message as the identity.
    """
    from kinema import transforms

    if len(position) != 3:
        return f"{what} position must have 3 values (x;y;z), got {len(position)}"
    if len(orientation) != 4:
        return f"{what} orientation must have 4 values (x;y;z;w), got {len(orientation)}"
    if transforms.is_zero_quaternion(orientation):
        return f"{what} orientation is a zero quaternion"
    try:
        return transforms.pose_matrix(position, orientation)
    except transforms.TransformError as error:
        return f"{what} {error}"


class CreatePoseStamped(SyncBehavior):
    """Writes a ``geometry_msgs/PoseStamped`` in ``reference_frame`` (the quaternion is normalised)."""

    subcategory = "Math - Poses"
    former_spellings = (FormerSpelling("CreateStampedPose", ports={"stamped_pose": "pose_stamped"}),)

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("reference_frame", str, "world", "Frame the pose is expressed in."),
            input_port("position_xyz", list[float], "0.0;0.0;0.0", "Position x;y;z (m)."),
            input_port("orientation_xyzw", list[float], "0.0;0.0;0.0;1.0", "Orientation quaternion x;y;z;w."),
            message_output("pose_stamped", POSE_STAMPED, "{pose_stamped}", "The pose."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        position = read_floats(self, "position_xyz", 3, "x;y;z")
        orientation = read_floats(self, "orientation_xyzw", 4, "x;y;z;w")
        matrix = pose_from_ports(position, orientation, "")
        if isinstance(matrix, str):
            raise port_error(
                self, "orientation_xyzw", f"= {orientation} is a zero quaternion", "e.g. 0;0;0;1"
            )
        frame = str(read_input(self, "reference_frame"))
        self.set_output("pose_stamped", pose_stamped_message(frame, matrix))
        return NodeStatus.SUCCESS


class UnpackPoseStampedMessage(SyncBehavior):
    """Splits a ``geometry_msgs/PoseStamped`` into its ``header`` and ``pose``."""

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("pose_stamped", POSE_STAMPED, "{pose_stamped}", "The pose to unpack."),
            message_output("header", "std_msgs/msg/Header", "{header}", "Its header (frame and stamp)."),
            message_output("pose", "geometry_msgs/msg/Pose", "{pose}", "Its pose."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        message = read_message(self, "pose_stamped")
        self.set_output("header", message.header)
        self.set_output("pose", message.pose)
        return NodeStatus.SUCCESS
