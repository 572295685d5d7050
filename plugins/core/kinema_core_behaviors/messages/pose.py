"""Pose and Point messages: unpack a pose into position and orientation, a point into x, y, z."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from .ports import fails_on_bad_input, message_input, message_output, read_input, read_message
from .unpacking import Field, UnpackMessage


class CreatePoseMessage(SyncBehavior):
    """Writes a ``geometry_msgs/Pose`` from a ``position`` Point and an ``orientation`` Quaternion."""

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("position", "geometry_msgs/msg/Point", "{position}", "The position."),
            message_input("orientation", "geometry_msgs/msg/Quaternion", "{orientation}", "The orientation."),
            message_output("pose", "geometry_msgs/msg/Pose", "{pose}", "The pose."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.transport import from_dict
        from kinema.transport.messages import to_dict

        pose = from_dict(
            "geometry_msgs/msg/Pose",
            {
                "position": to_dict(read_message(self, "position")),
                "orientation": to_dict(read_message(self, "orientation")),
            },
        )
        self.set_output("pose", pose)
        return NodeStatus.SUCCESS


class UnpackPoseMessage(UnpackMessage):
    """Splits a ``geometry_msgs/Pose`` into its ``position`` (Point) and ``orientation`` (Quaternion)."""

    message_port = "pose"
    message_type = "geometry_msgs/msg/Pose"
    message_description = "The pose to unpack."
    fields = (
        Field("position", "geometry_msgs/msg/Point", "Its position."),
        Field("orientation", "geometry_msgs/msg/Quaternion", "Its orientation."),
    )


class CreatePointMessage(SyncBehavior):
    """Writes a ``geometry_msgs/Point`` from ``x``, ``y`` and ``z``."""

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("x", float, 0.0, "x (m)."),
            input_port("y", float, 0.0, "y (m)."),
            input_port("z", float, 0.0, "z (m)."),
            message_output("point", "geometry_msgs/msg/Point", "{point}", "The point."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.transport import from_dict

        xyz = {axis: float(read_input(self, axis)) for axis in "xyz"}
        self.set_output("point", from_dict("geometry_msgs/msg/Point", xyz))
        return NodeStatus.SUCCESS


class UnpackPointMessage(UnpackMessage):
    """Splits a ``geometry_msgs/Point`` into ``x``, ``y`` and ``z``."""

    message_port = "point"
    message_type = "geometry_msgs/msg/Point"
    message_description = "The point to unpack."
    fields = (Field("x", "", "x (m)."), Field("y", "", "y (m)."), Field("z", "", "z (m)."))
