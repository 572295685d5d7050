"""AddPoseStampedToVector: append a pose to a vector of poses."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior

from ..messages.conversions import POSE_STAMPED_TYPE
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_vector_inout,
    read_message,
    read_vector,
)


class AddPoseStampedToVector(SyncBehavior):
    """Appends ``input`` (a PoseStamped) to the pose vector ``vector``; a vector nothing has written yet
    starts with this pose. Fails when ``input`` is not a PoseStamped or ``vector`` holds something else
    than a vector."""

    subcategory = "Vector Handling"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("input", POSE_STAMPED_TYPE, "{stamped_pose}", "The pose to append."),
            message_vector_inout(
                "vector", POSE_STAMPED_TYPE, "{pose_stamped_vector}", "The vector it is appended to."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        pose = read_message(self, "input")
        key = self.port_blackboard_key("vector")
        written = (
            key is not None and getattr(self.config.blackboard.get_entry(key), "value", None) is not None
        )
        poses = read_vector(self, "vector") if written else []
        self.set_output("vector", [*poses, pose])
        return NodeStatus.SUCCESS
