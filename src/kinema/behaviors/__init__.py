"""The behavior author's API: everything needed to write a Kinema behavior, from one place.

A behavior is a BT node class with typed ports and metadata::

    from kinema.behaviors import AsyncBehavior, input_port, output_port

    class MyBehavior(AsyncBehavior):
        \"\"\"Adds int_1 and int_2.\"\"\"

        subcategory = "Example Behaviors"

        @classmethod
        def provided_ports(cls):
            return [
                input_port("int_1", int, 0),
                input_port("int_2", int, 0),
                output_port("int_out", int, "{int_out}"),
            ]

        async def do_work(self) -> bool:
            int_1, int_2 = self.get_required_inputs("int_1", "int_2")
            self.set_output("int_out", int_1 + int_2)
            return True

and a plugin registers it (see :mod:`kinema.plugins`).

Base classes: :class:`SyncBehavior` (one tick), :class:`StatefulBehavior` (several ticks on the tick
thread), :class:`AsyncBehavior` (work off the tick thread), :class:`ServiceClientBehavior`,
:class:`ActionClientBehavior`, :class:`GetMessageFromTopicBehavior`, :class:`PublishToTopicBehavior`.
Every behavior has ``self.context`` (:class:`BehaviorContext`), ``self.logger``
(``publish_info/publish_warn/publish_failure`` → toasts) and ``self.get_required_inputs(...)``. A renamed
behavior keeps its old spellings readable with ``former_spellings = (FormerSpelling("OldName",
ports={"old_port": "new_port"}),)`` on its class; ``kinema build`` names the current spelling wherever
an objective still uses an old one.
"""

from __future__ import annotations

from kinema.behaviors.action_client import ActionClientBehavior
from kinema.behaviors.asynchronous import AsyncBehavior
from kinema.behaviors.base import Behavior
from kinema.behaviors.context import BehaviorContext
from kinema.behaviors.faults import BehaviorExecutionError
from kinema.behaviors.logger import BehaviorLogger, LogLevel, LogMessage, LogSink
from kinema.behaviors.message_type import message_type
from kinema.behaviors.required_inputs import MissingInputsError, get_required_inputs
from kinema.behaviors.service_client import ServiceClientBehavior
from kinema.behaviors.sync import StatefulBehavior, SyncBehavior
from kinema.behaviors.topic import GetMessageFromTopicBehavior, PublishToTopicBehavior
from kinema.bt import FormerSpelling, NodeStatus, PortInfo, bidirectional_port, input_port, output_port

__all__ = [
    "ActionClientBehavior",
    "AsyncBehavior",
    "Behavior",
    "BehaviorContext",
    "BehaviorExecutionError",
    "BehaviorLogger",
    "FormerSpelling",
    "GetMessageFromTopicBehavior",
    "LogLevel",
    "LogMessage",
    "LogSink",
    "MissingInputsError",
    "NodeStatus",
    "PortInfo",
    "PublishToTopicBehavior",
    "ServiceClientBehavior",
    "StatefulBehavior",
    "SyncBehavior",
    "bidirectional_port",
    "get_required_inputs",
    "input_port",
    "message_type",
    "output_port",
]
