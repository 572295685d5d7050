"""PublishString: publish a ``std_msgs/String`` on a topic."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from ..messages.ports import fails_on_bad_input, port_error, read_input, read_text


class PublishString(SyncBehavior):
    """Publishes ``message`` as a ``std_msgs/String`` on ``topic``.

    ``queue_size`` and ``use_best_effort`` are accepted for MoveIt Pro's objectives; Kinema's transport
    delivers reliably with its own queueing, so they change nothing.
    """

    subcategory = "ROS Messaging"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("message", str, "", "The text to publish."),
            input_port("topic", str, "/string_topic", "The topic (default implied by MoveIt Pro's docs)."),
            input_port("queue_size", int, 1, "Accepted, no effect in Kinema (see the description)."),
            input_port(
                "use_best_effort", bool, False, "Accepted, no effect in Kinema (see the description)."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.transport import from_dict

        topic = str(read_input(self, "topic")).strip()
        if not topic:
            raise port_error(self, "topic", "is empty", "give a topic name such as /status")
        node = self.context.require_node(self.registration_id)
        publisher = self.context.publisher(node, "std_msgs/msg/String", topic)
        publisher.publish(from_dict("std_msgs/msg/String", {"data": read_text(self, "message")}))
        return NodeStatus.SUCCESS
