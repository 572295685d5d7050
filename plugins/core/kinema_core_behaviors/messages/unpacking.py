"""The shape every Unpack*Message behavior shares: read one message, write some of its fields as outputs.

A subclass names its input port and message type, and lists its outputs as :class:`Field` (the field of
the message, and the port's type and description); ports and tick follow from that table.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, output_port

from .ports import fails_on_bad_input, message_input, message_output, read_message


@dataclass(frozen=True)
class Field:
    """One output of an unpack behavior: message field ``name`` on the port of the same name.

    ``ros_type`` is the field's message type, or empty for a number (written as a float).
    """

    name: str
    ros_type: str
    description: str


class UnpackMessage(SyncBehavior):
    """Base of the unpack behaviors: ``message_port`` (a ``message_type``) split into :attr:`fields`."""

    subcategory = "Messages"
    message_port: ClassVar[str] = ""
    message_type: ClassVar[str] = ""
    message_description: ClassVar[str] = ""
    fields: ClassVar[tuple[Field, ...]] = ()

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        ports = [
            message_input(
                cls.message_port, cls.message_type, f"{{{cls.message_port}}}", cls.message_description
            )
        ]
        for f in cls.fields:
            if f.ros_type:
                ports.append(message_output(f.name, f.ros_type, f"{{{f.name}}}", f.description))
            else:
                ports.append(output_port(f.name, float, f"{{{f.name}}}", f.description))
        return ports

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        message: Any = read_message(self, self.message_port)
        for f in self.fields:
            value = getattr(message, f.name)
            self.set_output(f.name, value if f.ros_type else float(value))
        return NodeStatus.SUCCESS
