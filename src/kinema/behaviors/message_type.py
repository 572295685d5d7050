"""ROS message types as port types: one Python type object per ROS type, shared by every plugin.

A port declared with ``message_type("geometry_msgs/msg/PoseStamped")`` is strongly typed as BT.CPP's
``InputPort<geometry_msgs::msg::PoseStamped>`` is: two ports sharing a blackboard entry must agree on the
type when the tree is built, and a value of another type is refused when it is read. The type object is
cached per ROS type in the SDK (not in a plugin), so every behavior of every plugin that declares a
PoseStamped port gets the same one, across hot reloads too (the engine compares port types with ``==``).
A value is an instance when it is a message of that ROS type (the rosbags dataclasses Kinema's transport
builds), whichever typestore built it.

Calling the type builds a message of it (``PoseStamped(pose={"position": {"x": 0.1}})``), for tests and
for behaviors that write message ports.

Literal port text (rare for messages) is read as MoveIt Pro's JSON serialisation of the message,
``json:{"pose": {...}}``, or as YAML flow text without the prefix (what ``ros2 topic pub`` takes).
"""

from __future__ import annotations

import json
from typing import Any, ClassVar

from kinema.nesting import loads_json

_TYPES: dict[str, type] = {}


class MessageTypeMeta(type):
    """Metaclass of message port types: ``isinstance`` checks the message's ROS type name."""

    ros_type: str

    def __instancecheck__(cls, value: Any) -> bool:
        return getattr(value, "__msgtype__", None) == getattr(cls, "ros_type", None)

    def __repr__(cls) -> str:
        return f"<message type {cls.ros_type}>"

    def __call__(cls, **fields: Any) -> Any:
        """A message of this type: ``message_type("sensor_msgs/msg/JointState")(name=["a"], position=[0.5])``.

        Fields not given get their defaults; a nested message may be a dict of its fields. What a test
        hands ``tick_behavior`` for a message port, or a behavior writes to one.

        Raises:
            TransportError: a field the message does not have (naming the valid ones), or a value of the
                wrong type.
        """
        from kinema.transport import from_dict

        if not getattr(cls, "ros_type", ""):
            raise TypeError("MessageValue is the base of message port types; use message_type(ROS_TYPE)")
        return from_dict(cls.ros_type, fields)


class MessageValue(metaclass=MessageTypeMeta):
    """Base of the generated message port types; calling one builds a message of its ROS type."""

    ros_type: ClassVar[str] = ""

    @classmethod
    def from_string(cls, text: str) -> Any:
        """A message of this type from ``json:{...}`` or YAML flow text.

        Raises:
            ValueError: the text is not a mapping of this message's fields.
        """
        from kinema.errors import TransportError
        from kinema.transport import from_dict, parse_yaml_flow

        try:
            if text.startswith("json:"):
                data = loads_json(text[5:], f"the {cls.ros_type} JSON")
                if not isinstance(data, dict):
                    raise ValueError(f"{cls.ros_type} JSON must be an object, got {text[5:][:80]}")
                return from_dict(cls.ros_type, data)
            return parse_yaml_flow(cls.ros_type, text)
        except json.JSONDecodeError as error:
            raise ValueError(f"invalid JSON for {cls.ros_type}: {error.msg}") from None
        except TransportError as error:
            raise ValueError(error.message) from None


def normalise_ros_type(ros_type: str) -> str:
    """``pkg/msg/Name`` from ``pkg/Name``, ``pkg/msg/Name`` or ``pkg::msg::Name``."""
    parts = [part for part in ros_type.replace("::", "/").strip("/").split("/") if part]
    if len(parts) == 2:
        parts.insert(1, "msg")
    if len(parts) != 3:
        raise ValueError(f"bad ROS message type {ros_type!r}: expected pkg/msg/Name")
    return "/".join(parts)


def message_type(ros_type: str) -> type:
    """The port type of the ROS message type ``ros_type`` (``"geometry_msgs/msg/PoseStamped"``).

    Its name is the C++ one (``geometry_msgs::msg::PoseStamped``), which models and the behavior
    reference print.
    """
    full = normalise_ros_type(ros_type)
    cls = _TYPES.get(full)
    if cls is None:
        cpp_name = full.replace("/", "::")
        cls = MessageTypeMeta(
            cpp_name,
            (MessageValue,),
            {"ros_type": full, "__qualname__": cpp_name, "__module__": __name__},
        )
        _TYPES[full] = cls
    return cls


def ros_type_of_port_type(port_type: Any) -> str | None:
    """The ROS type a message port type stands for, or None for any other type."""
    return getattr(port_type, "ros_type", None) if isinstance(port_type, MessageTypeMeta) else None
