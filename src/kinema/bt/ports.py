"""Port declarations: what a node type reads and writes (BT.CPP ``providedPorts()``)."""

from __future__ import annotations

from enum import EnumMeta, IntEnum
from typing import Any

from kinema.bt.conversions import has_converter, is_strongly_typed, to_str, type_name
from kinema.bt.errors import BTLogicError


class PortDirection(IntEnum):
    """Direction of a port, numbered as in BT.CPP."""

    INPUT = 0
    OUTPUT = 1
    INOUT = 2

    @property
    def xml_tag(self) -> str:
        """The element name used in ``<TreeNodesModel>``."""
        return ("input_port", "output_port", "inout_port")[self]


class _NoDefault:
    __slots__ = ()

    def __repr__(self) -> str:
        return "NO_DEFAULT"


NO_DEFAULT: Any = _NoDefault()

RESERVED_PORT_NAMES = frozenset(
    {
        "name",
        "ID",
        "_autoremap",
        "_description",
        "_failureIf",
        "_successIf",
        "_skipIf",
        "_while",
        "_onSuccess",
        "_onFailure",
        "_onHalted",
        "_post",
        "__shared_blackboard",
    }
)


class PortInfo:
    """One declared port.

    Attributes:
        name: the port name (an XML attribute of the node).
        direction: INPUT, OUTPUT or INOUT.
        type: the Python type of the value (None = any type allowed).
        default: the default value as given (``NO_DEFAULT`` when there is none).
        default_str: the default as text, as BT.CPP's ``toStr`` writes it, or None.
        description: free text for models and editors.
    """

    __slots__ = (
        "default",
        "default_str",
        "description",
        "direction",
        "has_converter",
        "name",
        "strongly_typed",
        "type",
    )

    def __init__(
        self,
        name: str,
        direction: PortDirection = PortDirection.INPUT,
        type: Any = None,
        default: Any = NO_DEFAULT,
        description: str = "",
    ) -> None:
        self.name = name
        self.direction = direction
        self.type = type
        self.default = default
        self.default_str: str | None = None if default is NO_DEFAULT else to_str(default)
        self.description = description
        self.strongly_typed = is_strongly_typed(type)
        # BT.CPP gives enum-typed ports (NodeStatus included) no string converter, so their
        # literals are not checked when the tree is built, only when the port is read.
        self.has_converter = has_converter(type) and not (isinstance(type, EnumMeta))

    @property
    def has_default(self) -> bool:
        """True if the port declares a default value."""
        return self.default is not NO_DEFAULT

    @property
    def type_name(self) -> str:
        """The type name as BT.CPP prints it (``int``, ``double``, ``std::string`` ...)."""
        return type_name(self.type)

    def __repr__(self) -> str:
        return (
            f"PortInfo({self.name!r}, {self.direction.name}, {self.type_name}, default={self.default_str!r})"
        )


def input_port(name: str, type: Any = None, default: Any = NO_DEFAULT, description: str = "") -> PortInfo:
    """Declare an input port (``InputPort<T>(name, default, description)``)."""
    return PortInfo(name, PortDirection.INPUT, type, default, description)


def output_port(name: str, type: Any = None, default: Any = NO_DEFAULT, description: str = "") -> PortInfo:
    """Declare an output port; a default must be a blackboard pointer such as ``"{key}"``."""
    if default is not NO_DEFAULT and not (isinstance(default, str) and _is_pointer_text(default)):
        raise BTLogicError(
            f"Output port [{name}]: the default value must be a blackboard pointer like {{key}}"
        )
    return PortInfo(name, PortDirection.OUTPUT, type, default, description)


def bidirectional_port(
    name: str, type: Any = None, default: Any = NO_DEFAULT, description: str = ""
) -> PortInfo:
    """Declare an input/output port."""
    return PortInfo(name, PortDirection.INOUT, type, default, description)


def _is_pointer_text(text: str) -> bool:
    stripped = text.strip()
    return stripped == "=" or (len(stripped) >= 3 and stripped[0] == "{" and stripped[-1] == "}")


def blackboard_pointer(text: str, port_name: str) -> str | None:
    """The blackboard key a port value points to, or None for a literal.

    ``{key}`` (spaces around it trimmed), ``{=}`` and a bare ``=`` (the key named like the port);
    ``{@key}`` keeps its ``@`` (it is resolved by the blackboard).
    """
    stripped = text.strip()
    if stripped == "=" or stripped == "{=}":
        return port_name
    if len(stripped) >= 3 and stripped[0] == "{" and stripped[-1] == "}":
        return stripped[1:-1]
    return None


def strict_blackboard_pointer(text: str) -> bool:
    """The pointer test used for parse-time literal validation: no trimming, no bare ``=``."""
    return len(text) >= 3 and text[0] == "{" and text[-1] == "}"
