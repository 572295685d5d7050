"""UnpackJointStateMessage: split a sensor_msgs/JointState into its header and per-joint lists."""

from __future__ import annotations

from .conversions import JOINT_STATE_TYPE
from .unpacking import Field, UnpackMessage


class UnpackJointStateMessage(UnpackMessage):
    """Splits ``joint_state`` (a ``sensor_msgs/JointState``, e.g. from GetJointState) into its fields.

    The joint names are written to ``name_`` (MoveIt Pro's spelling: ``name`` is the node's own name);
    ``position``, ``velocity`` and ``effort`` are lists of numbers, in the order of the names, and empty
    when the message leaves them empty (a JointState may carry positions only). They feed CreateRobotState's
    ``joint_names`` and ``positions`` directly.
    """

    message_port = "joint_state"
    message_type = JOINT_STATE_TYPE
    message_description = "The joint state to split."
    fields = (
        Field("header", "std_msgs/msg/Header", "Its header."),
        Field("name", "", "The joint names.", list[str], port="name_"),
        Field("position", "", "The joint positions (rad or m), one per name.", list[float]),
        Field(
            "velocity", "", "The joint velocities (rad/s or m/s); empty if the message has none.", list[float]
        ),
        Field("effort", "", "The joint efforts (N·m or N); empty if the message has none.", list[float]),
    )
