"""PublishString: publish a ``std_msgs/String`` on a topic."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from ..messages.ports import fails_on_bad_input, port_error, read_input, shown


class PublishString(SyncBehavior):
    """Publishes ``message`` (a ``std_msgs/String``, as MoveIt Pro passes it, or text) on ``topic``.

    ``queue_size`` and ``use_best_effort`` are accepted for MoveIt Pro's objectives; Kinema's transport
    delivers reliably with its own queueing, so they change nothing.
    """

    subcategory = "ROS Messaging"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "message", None, "", "The message: a std_msgs/String (e.g. from CreateStringMessage) or text."
            ),
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
        message = read_input(self, "message") if "message" in self.config.input_ports else ""
        if getattr(message, "__msgtype__", None) != "std_msgs/msg/String":
            if not isinstance(message, str | int | float):
                raise port_error(
                    self,
                    "message",
                    f"got {shown(message)}",
                    "give a std_msgs/String (CreateStringMessage) or text",
                )
            message = from_dict("std_msgs/msg/String", {"data": str(message)})
        publisher.publish(message)
        return NodeStatus.SUCCESS
