"""Node manifests: what the factory knows about each registered node type."""

from __future__ import annotations

from enum import Enum

from kinema.bt.ports import PortInfo


class NodeType(Enum):
    """Node categories, named as in ``<TreeNodesModel>``."""

    ACTION = "Action"
    CONDITION = "Condition"
    CONTROL = "Control"
    DECORATOR = "Decorator"
    SUBTREE = "SubTree"

    def __str__(self) -> str:
        return self.value


class NodeManifest:
    """A registered node type.

    Attributes:
        id: the registration ID (the XML element name in compact form).
        category: Action, Condition, Control, Decorator or SubTree.
        ports: port name -> :class:`PortInfo`.
        description: free text (``<TreeNodesModel>`` and editors show it).
        metadata: ``(key, value)`` pairs written as ``<MetadataFields>``.
        builtin: True for the nodes BT.CPP registers by default.
    """

    __slots__ = ("builtin", "category", "description", "id", "metadata", "ports")

    def __init__(
        self,
        id: str,
        category: NodeType,
        ports: dict[str, PortInfo] | None = None,
        description: str = "",
        metadata: list[tuple[str, str]] | None = None,
        builtin: bool = False,
    ) -> None:
        self.id = id
        self.category = category
        self.ports: dict[str, PortInfo] = dict(ports or {})
        self.description = description
        self.metadata: list[tuple[str, str]] = list(metadata or [])
        self.builtin = builtin

    def __repr__(self) -> str:
        return f"NodeManifest({self.id!r}, {self.category.value}, ports={list(self.ports)})"
