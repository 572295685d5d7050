"""PublishEmpty: publish a ``std_msgs/Empty`` on a topic (a signal: "motion ended", "go")."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from ..messages.ports import fails_on_bad_input, port_error, read_input


class PublishEmpty(SyncBehavior):
    """Publishes one ``std_msgs/Empty`` on ``topic`` and succeeds.

    ``queue_size`` and ``use_best_effort`` are accepted for MoveIt Pro's objectives; Kinema's transport
    delivers reliably with its own queueing, so they change nothing.
    """

    subcategory = "ROS Messaging"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "topic", str, "", "The topic (MoveIt Pro's objectives use /studio_ui/motion_ended); required."
            ),
            input_port("queue_size", int, 1, "Accepted, no effect in Kinema (see the description)."),
            input_port(
                "use_best_effort", bool, False, "Accepted, no effect in Kinema (see the description)."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.transport import from_dict

        topic = str(read_input(self, "topic")).strip() if "topic" in self.config.input_ports else ""
        if not topic:
            raise port_error(self, "topic", "is empty", "give a topic name such as /studio_ui/motion_ended")
        node = self.context.require_node(self.registration_id)
        self.context.publisher(node, "std_msgs/msg/Empty", topic).publish(from_dict("std_msgs/msg/Empty", {}))
        return NodeStatus.SUCCESS
