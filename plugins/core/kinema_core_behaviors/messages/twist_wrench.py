"""TwistStamped and WrenchStamped messages: create them from x;y;z ports and unpack them.

Twists and wrenches are one concept here: a pair of 3-vectors (linear/angular, force/torque) in a frame.
"""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from .ports import fails_on_bad_input, message_input, message_output, read_floats, read_input, read_message


def _xyz(values: list[float]) -> dict[str, float]:
    return dict(zip("xyz", values, strict=True))


class CreateTwistStamped(SyncBehavior):
    """Writes a ``geometry_msgs/TwistStamped`` in ``reference_frame``."""

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("reference_frame", str, "world", "Frame the twist is expressed in."),
            input_port("linear_velocity_xyz", list[float], "0.0;0.0;0.0", "Linear velocity x;y;z (m/s)."),
            input_port("angular_velocity_xyz", list[float], "0.0;0.0;0.0", "Angular velocity x;y;z (rad/s)."),
            message_output(
                "twist_stamped", "geometry_msgs/msg/TwistStamped", "{twist_stamped}", "The twist."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.transport import from_dict

        linear = read_floats(self, "linear_velocity_xyz", 3, "x;y;z")
        angular = read_floats(self, "angular_velocity_xyz", 3, "x;y;z")
        message = from_dict(
            "geometry_msgs/msg/TwistStamped",
            {
                "header": {"frame_id": str(read_input(self, "reference_frame"))},
                "twist": {"linear": _xyz(linear), "angular": _xyz(angular)},
            },
        )
        self.set_output("twist_stamped", message)
        return NodeStatus.SUCCESS


class UnpackTwistStampedMessage(SyncBehavior):
    """Splits a ``geometry_msgs/TwistStamped`` into its ``header`` and ``twist``."""

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("twist_stamped", "geometry_msgs/msg/TwistStamped", "{twist_stamped}", "The twist."),
            message_output("header", "std_msgs/msg/Header", "{header}", "Its header."),
            message_output("twist", "geometry_msgs/msg/Twist", "{twist}", "Its twist."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        message = read_message(self, "twist_stamped")
        self.set_output("header", message.header)
        self.set_output("twist", message.twist)
        return NodeStatus.SUCCESS


class CreateWrenchStamped(SyncBehavior):
    """Writes a ``geometry_msgs/WrenchStamped`` in ``reference_frame``."""

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("reference_frame", str, "world", "Frame the wrench is expressed in."),
            input_port("force_xyz", list[float], "0.0;0.0;0.0", "Force x;y;z (N)."),
            input_port("torque_xyz", list[float], "0.0;0.0;0.0", "Torque x;y;z (N m)."),
            message_output(
                "wrench_stamped", "geometry_msgs/msg/WrenchStamped", "{wrench_stamped}", "The wrench."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.transport import from_dict

        force = read_floats(self, "force_xyz", 3, "x;y;z")
        torque = read_floats(self, "torque_xyz", 3, "x;y;z")
        message = from_dict(
            "geometry_msgs/msg/WrenchStamped",
            {
                "header": {"frame_id": str(read_input(self, "reference_frame"))},
                "wrench": {"force": _xyz(force), "torque": _xyz(torque)},
            },
        )
        self.set_output("wrench_stamped", message)
        return NodeStatus.SUCCESS


class UnpackWrenchStampedMessage(SyncBehavior):
    """Splits a ``geometry_msgs/WrenchStamped`` into its ``header`` and ``wrench``."""

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "wrench_stamped", "geometry_msgs/msg/WrenchStamped", "{wrench_stamped}", "The wrench."
            ),
            message_output("header", "std_msgs/msg/Header", "{header}", "Its header."),
            message_output("wrench", "geometry_msgs/msg/Wrench", "{wrench}", "Its wrench."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        message = read_message(self, "wrench_stamped")
        self.set_output("header", message.header)
        self.set_output("wrench", message.wrench)
        return NodeStatus.SUCCESS
