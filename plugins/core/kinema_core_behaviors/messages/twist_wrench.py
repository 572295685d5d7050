"""TwistStamped and WrenchStamped messages: create them from x;y;z ports and unpack them.

Twists and wrenches are one concept here: a pair of 3-vectors (linear/angular, force/torque) in a frame,
so one creator and the shared unpacker serve both, each behavior a table of names.
"""

from __future__ import annotations

from typing import ClassVar

from kinema.behaviors import FormerSpelling, NodeStatus, PortInfo, SyncBehavior, input_port

from .ports import fails_on_bad_input, message_output, read_floats, read_input
from .unpacking import Field, UnpackMessage


class _CreateVectorPairStamped(SyncBehavior):
    """Writes a stamped pair of 3-vectors (field ``body``: ``first``, ``second``) in ``reference_frame``."""

    subcategory = "Messages"
    message_type: ClassVar[str] = ""
    output: ClassVar[str] = ""
    noun: ClassVar[str] = ""  # "twist", "wrench"
    body: ClassVar[str] = ""  # the field holding the pair: "twist", "wrench"
    first: ClassVar[tuple[str, str, str]] = ("", "", "")  # field, port, description
    second: ClassVar[tuple[str, str, str]] = ("", "", "")

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("reference_frame", str, "world", f"Frame the {cls.noun} is expressed in."),
            input_port(cls.first[1], list[float], "0.0;0.0;0.0", cls.first[2]),
            input_port(cls.second[1], list[float], "0.0;0.0;0.0", cls.second[2]),
            message_output(cls.output, cls.message_type, f"{{{cls.output}}}", f"The {cls.noun}."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.transport import from_dict

        pair = {
            field: dict(zip("xyz", read_floats(self, port, 3, "x;y;z"), strict=True))
            for field, port, _ in (self.first, self.second)
        }
        header = {"frame_id": str(read_input(self, "reference_frame"))}
        self.set_output(self.output, from_dict(self.message_type, {"header": header, self.body: pair}))
        return NodeStatus.SUCCESS


class CreateTwistStamped(_CreateVectorPairStamped):
    """Writes a ``geometry_msgs/TwistStamped`` in ``reference_frame``."""

    message_type = "geometry_msgs/msg/TwistStamped"
    output = "twist_stamped"
    noun = body = "twist"
    first = ("linear", "linear_velocity_xyz", "Linear velocity x;y;z (m/s).")
    second = ("angular", "angular_velocity_xyz", "Angular velocity x;y;z (rad/s).")
    former_spellings = (FormerSpelling("CreateStampedTwist", ports={"stamped_twist": "twist_stamped"}),)


class UnpackTwistStampedMessage(UnpackMessage):
    """Splits a ``geometry_msgs/TwistStamped`` into its ``header`` and ``twist``."""

    message_port = "twist_stamped"
    message_type = "geometry_msgs/msg/TwistStamped"
    message_description = "The twist."
    fields = (
        Field("header", "std_msgs/msg/Header", "Its header."),
        Field("twist", "geometry_msgs/msg/Twist", "Its twist."),
    )


class CreateWrenchStamped(_CreateVectorPairStamped):
    """Writes a ``geometry_msgs/WrenchStamped`` in ``reference_frame``."""

    message_type = "geometry_msgs/msg/WrenchStamped"
    output = "wrench_stamped"
    noun = body = "wrench"
    first = ("force", "force_xyz", "Force x;y;z (N).")
    second = ("torque", "torque_xyz", "Torque x;y;z (N m).")
    former_spellings = (FormerSpelling("CreateStampedWrench", ports={"stamped_wrench": "wrench_stamped"}),)


class UnpackWrenchStampedMessage(UnpackMessage):
    """Splits a ``geometry_msgs/WrenchStamped`` into its ``header`` and ``wrench``."""

    message_port = "wrench_stamped"
    message_type = "geometry_msgs/msg/WrenchStamped"
    message_description = "The wrench."
    fields = (
        Field("header", "std_msgs/msg/Header", "Its header."),
        Field("wrench", "geometry_msgs/msg/Wrench", "Its wrench."),
    )
