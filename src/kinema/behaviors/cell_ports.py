"""Ports whose default is the cell's own value: the planning group, the tool frame, the gripper's action.

A behavior written for any robot cannot default ``planning_group_name`` to one robot's group. It declares
the port with :func:`cell_input_port` instead::

    cell_input_port("planning_group_name", str, "planning_group", "The planning group that moves.")

and the port's default becomes the running config's value (``moveit_params.joint_group_name`` here): in
the node models Groot2, the terminal UI and ``kinema behaviors`` show, and when an objective leaves the
port out. An empty value means the same, so a subtree can pass ``""`` through (Kinema's core subtrees
declare such ports with the default ``""``). Without a config (``kinema tree run``, unit tests), or when
the config does not set the value, the port has no default and reading it fails with a message that
says which config key to set.

The keys are :data:`kinema.config.cell.CELL_VALUE_KEYS`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from kinema.bt import PortInfo
from kinema.bt.ports import NO_DEFAULT, PortDirection
from kinema.config.cell import CELL_VALUE_KEYS, setting_key_path
from kinema.errors import did_you_mean

if TYPE_CHECKING:
    from kinema.config.cell import CellSettings


class CellPortInfo(PortInfo):
    """An input port whose default is the cell's value ``cell_key`` (see :func:`cell_input_port`)."""

    __slots__ = ("cell_key", "empty_is_default")

    def __init__(
        self, name: str, type: Any, cell_key: str, description: str = "", *, empty_is_default: bool = True
    ) -> None:
        super().__init__(name, PortDirection.INPUT, type, NO_DEFAULT, description)
        self.cell_key = cell_key
        self.empty_is_default = empty_is_default


def cell_input_port(
    name: str, type: Any, cell_key: str, description: str = "", *, empty_is_default: bool = True
) -> PortInfo:
    """Declare an input port whose default is the running config's ``cell_key`` value.

    Args:
        name: the port's name.
        type: its type.
        cell_key: one of :data:`kinema.config.cell.CELL_VALUE_KEYS` (``planning_group``, ``tool_frame``,
            ``gripper_action``, ...).
        description: what the port is; the config key it defaults to is added.
        empty_is_default: an empty value also reads as the cell's value (False for a port where ``""``
            means something of its own, such as "all joints").

    Raises:
        KeyError: ``cell_key`` is not a known cell value.
    """
    if cell_key not in CELL_VALUE_KEYS:
        raise KeyError(f"unknown cell value {cell_key!r}; {did_you_mean(cell_key, CELL_VALUE_KEYS)}")
    note = f"Default: the config's {setting_key_path(cell_key)}."
    text = f"{description} {note}" if description else note
    return CellPortInfo(name, type, cell_key, text, empty_is_default=empty_is_default)


def resolve_cell_ports(ports: list[PortInfo], cell: CellSettings | None) -> list[PortInfo]:
    """``ports`` with each cell port's default set to ``cell``'s value (left without one when unset)."""
    out: list[PortInfo] = []
    for port in ports:
        if isinstance(port, CellPortInfo) and cell is not None:
            value = cell.value(port.cell_key)
            if value is not None:
                resolved = CellPortInfo(
                    port.name,
                    port.type,
                    port.cell_key,
                    port.description,
                    empty_is_default=port.empty_is_default,
                )
                resolved.default = value
                resolved.default_str = PortInfo(port.name, port.direction, port.type, value).default_str
                port = resolved
        out.append(port)
    return out


def cell_ports(ports: list[PortInfo]) -> dict[str, tuple[str, bool]]:
    """Port name -> (cell key, whether an empty value reads as the default), for the cell ports."""
    return {p.name: (p.cell_key, p.empty_is_default) for p in ports if isinstance(p, CellPortInfo)}


def missing_cell_value_message(port: str, cell_key: str, config: str | None) -> str:
    """What to say when a cell port has neither a value nor a configured default."""
    where = f"config {config!r}" if config else "no config (this tree runs without a config package)"
    return (
        f"port [{port}] is empty and {where} gives no default for it: set {setting_key_path(cell_key)} "
        "in config.yaml, or give the port a value"
    )
