"""The shape every Unpack*Message behavior shares: read one message, write some of its fields as outputs.

A subclass names its input port and message type, and lists its outputs as :class:`Field` (the field of
the message, and the port's type and description); ports and tick follow from that table.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, output_port
from kinema.bt.conversions import list_item_type

from .ports import fails_on_bad_input, message_input, message_output, read_message


@dataclass(frozen=True)
class Field:
    """One output of an unpack behavior: message field ``name`` on the port of the same name.

    ``ros_type`` is the field's message type, or empty for a plain value of ``value_type``: a number
    (``float``, the default) or a list (``list[float]``, ``list[str]``), converted item by item. ``port``
    names the port when it is not the field's name (MoveIt Pro's ``name_`` for a JointState's ``name``,
    since ``name`` is every node's own attribute).
    """

    name: str
    ros_type: str
    description: str
    value_type: Any = float
    port: str = ""

    @property
    def port_name(self) -> str:
        """The output port this field is written to."""
        return self.port or self.name

    def plain(self, value: Any) -> Any:
        """``value`` as ``value_type`` (a list's items converted one by one)."""
        item = list_item_type(self.value_type)
        if item is not None:
            return [item(v) for v in value]
        return self.value_type(value)


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
            port = f.port_name
            if f.ros_type:
                ports.append(message_output(port, f.ros_type, f"{{{port}}}", f.description))
            else:
                ports.append(output_port(port, f.value_type, f"{{{port}}}", f.description))
        return ports

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        message: Any = read_message(self, self.message_port)
        for f in self.fields:
            value = getattr(message, f.name)
            self.set_output(f.port_name, value if f.ros_type else f.plain(value))
        return NodeStatus.SUCCESS
