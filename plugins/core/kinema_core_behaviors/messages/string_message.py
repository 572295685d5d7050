"""String messages: CreateStringMessage wraps text in ``std_msgs/String``, UnpackStringMessage unwraps it."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from .ports import fails_on_bad_input, message_input, message_output, read_message, read_text


class CreateStringMessage(SyncBehavior):
    """Writes a ``std_msgs/String`` holding ``data``."""

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("data", str, "", "The text."),
            message_output("string", "std_msgs/msg/String", "{string}", "The message."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.transport import from_dict

        self.set_output("string", from_dict("std_msgs/msg/String", {"data": read_text(self, "data")}))
        return NodeStatus.SUCCESS


class UnpackStringMessage(SyncBehavior):
    """Writes the text of a ``std_msgs/String`` to ``data``."""

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("string", "std_msgs/msg/String", "{string}", "The message."),
            output_port("data", str, "{data}", "Its text."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        self.set_output("data", str(read_message(self, "string").data))
        return NodeStatus.SUCCESS
