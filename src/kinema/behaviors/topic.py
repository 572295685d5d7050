"""Behaviors that take one message from a topic, or publish one (MoveIt Pro's topic behavior bases)."""

from __future__ import annotations

import threading
from typing import Any, ClassVar

from kinema.behaviors.asynchronous import AsyncBehavior
from kinema.behaviors.faults import BehaviorExecutionError
from kinema.behaviors.interface_type import parametrize
from kinema.behaviors.sync import SyncBehavior
from kinema.bt import NodeStatus, PortInfo, input_port, output_port


class GetMessageFromTopicBehavior(AsyncBehavior):
    """Waits for the next message on a topic and writes it to ``message_out``.

    Derive from ``GetMessageFromTopicBehavior["pkg/msg/Name"]`` (or set :attr:`message_type`). Ports:
    ``topic_name`` (in), ``timeout`` (in, seconds, default 5; ≤ 0 waits forever) and ``message_out``
    (out). Override :meth:`process_message` to check or transform the message. No message within the
    timeout publishes a failure toast and returns FAILURE.
    """

    __slots__ = ()

    message_type: ClassVar[str] = ""
    """The ROS message type, e.g. ``std_msgs/msg/String``."""

    def __class_getitem__(cls, message_type: str) -> type:
        return parametrize(cls, "message_type", "msg", message_type)

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("topic_name", str, description="The topic to take a message from."),
            input_port("timeout", float, 5.0, "Seconds to wait for a message (0 or less: forever)."),
            output_port("message_out", None, "{message_out}", "The message received."),
        ]

    def process_message(self, message: Any) -> bool:
        """Write ``message`` to ``message_out``; return True for SUCCESS. Called off the tick thread."""
        self.set_output("message_out", message)
        return True

    async def do_work(self) -> bool:
        """Subscribe, wait for one message, process it (no need to override)."""
        import asyncio

        if not self.message_type:
            raise BehaviorExecutionError(
                f"behavior '{self.registration_id}' does not say which message type it reads; derive "
                "from GetMessageFromTopicBehavior['pkg/msg/Name'] or set message_type"
            )
        node = self.context.require_node(self.registration_id)
        topic, timeout = self.get_required_inputs("topic_name", "timeout")
        received: list[Any] = []
        arrived = threading.Event()

        def on_message(message: Any) -> None:
            if not arrived.is_set():
                received.append(message)
                arrived.set()

        subscription = node.create_subscription(self.message_type, topic, on_message)
        try:
            wait = None if timeout <= 0 else timeout
            got = await asyncio.to_thread(arrived.wait, wait)
        finally:
            subscription.close()
        if not got:
            self.logger.publish_failure(f"No message on {topic} within {timeout:g} s")
            return False
        return self.process_message(received[0])


class PublishToTopicBehavior(SyncBehavior):
    """Publishes one message on a topic each time it is ticked.

    Derive from ``PublishToTopicBehavior["pkg/msg/Name"]`` (or set :attr:`message_type`). Ports:
    ``topic`` (in), ``message`` (in: a message or a dict of its fields) and ``latched`` (in, default
    false: keep the last message for late subscribers). Override :meth:`create_message` to build the
    message from other ports.
    """

    __slots__ = ()

    message_type: ClassVar[str] = ""
    """The ROS message type, e.g. ``std_msgs/msg/String``."""

    def __class_getitem__(cls, message_type: str) -> type:
        return parametrize(cls, "message_type", "msg", message_type)

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("topic", str, description="The topic to publish on."),
            input_port("message", None, description="The message (or a dict of its fields)."),
            input_port("latched", bool, False, "Keep the last message for subscribers that join later."),
        ]

    def create_message(self) -> Any:
        """Return the message to publish; default: the ``message`` port. Called on the tick thread."""
        return self.get_input("message")

    def get_topic(self) -> str:
        """The topic to publish on; default: the ``topic`` port."""
        return str(self.get_input("topic"))

    def tick(self) -> NodeStatus:
        """Publish :meth:`create_message` on :meth:`get_topic` and return SUCCESS (no need to override)."""
        if not self.message_type:
            raise BehaviorExecutionError(
                f"behavior '{self.registration_id}' does not say which message type it publishes; derive "
                "from PublishToTopicBehavior['pkg/msg/Name'] or set message_type"
            )
        node = self.context.require_node(self.registration_id)
        latched = bool(self.get_input_or("latched", False))
        publisher = self.context.publisher(node, self.message_type, self.get_topic(), latched=latched)
        message = self.create_message()
        if isinstance(message, dict):
            from kinema.transport import from_dict

            message = from_dict(self.message_type, message)
        publisher.publish(message)
        return NodeStatus.SUCCESS
