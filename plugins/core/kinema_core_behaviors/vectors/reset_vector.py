"""ResetVector and ResetPoseStampedVector: make a vector empty (creating it if needed)."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, bidirectional_port

from ..messages.ports import message_vector_inout


class ResetVector(SyncBehavior):
    """Sets ``vector`` to an empty vector; use it to create a vector before PushBackVector fills it.

    The vector may hold any type (messages, numbers, strings); an existing vector keeps its type.
    """

    subcategory = "Vector Handling"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [bidirectional_port("vector", None, "{vector}", "The vector to empty (created if missing).")]

    def tick(self) -> NodeStatus:
        self.set_output("vector", [])
        return NodeStatus.SUCCESS


class ResetPoseStampedVector(SyncBehavior):
    """Sets ``vector`` to an empty vector of ``geometry_msgs/PoseStamped``."""

    subcategory = "Vector Handling"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_vector_inout(
                "vector", "geometry_msgs/msg/PoseStamped", "{vector}", "The pose vector to empty."
            )
        ]

    def tick(self) -> NodeStatus:
        self.set_output("vector", [])
        return NodeStatus.SUCCESS
