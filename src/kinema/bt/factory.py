"""The factory: registered node types, scripting enums, loaded trees, and tree creation."""

from __future__ import annotations

import enum
import inspect
import itertools
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING

from kinema.bt.blackboard import Blackboard
from kinema.bt.clock import Clock, WallClock
from kinema.bt.errors import BTLogicError, BTRuntimeError, TreeNotFoundError
from kinema.bt.manifest import NodeManifest, NodeType
from kinema.bt.names import model_name_problem, port_name_problem
from kinema.bt.node import (
    ConditionNode,
    ControlNode,
    DecoratorNode,
    NodeConfig,
    SimpleActionNode,
    SimpleConditionNode,
    SimpleDecoratorNode,
    TreeNode,
)
from kinema.bt.ports import PortInfo
from kinema.bt.spellings import FormerSpelling
from kinema.bt.status import NodeStatus
from kinema.bt.tree import Tree
from kinema.bt.xmlparser import TreeDefinition, TreeLibrary
from kinema.errors import did_you_mean

if TYPE_CHECKING:
    from lxml import etree

# A serial per factory (never reused, unlike id()): part of the key of compiled tree plans.
_FACTORY_SERIALS = itertools.count(1)

NodeBuilder = Callable[[str, NodeConfig], TreeNode]


def category_of(cls: type) -> NodeType:
    """The manifest category implied by a node class."""
    if issubclass(cls, DecoratorNode):
        return NodeType.DECORATOR
    if issubclass(cls, ControlNode):
        return NodeType.CONTROL
    if issubclass(cls, ConditionNode):
        return NodeType.CONDITION
    return NodeType.ACTION


def _ports_dict(ports: Iterable[PortInfo], owner: str, *, check_names: bool = True) -> dict[str, PortInfo]:
    result: dict[str, PortInfo] = {}
    for port in ports:
        if not isinstance(port, PortInfo):
            raise BTLogicError(f"provided_ports() of [{owner}] must return PortInfo objects, got {port!r}")
        if check_names:
            problem = port_name_problem(port.name)
            if problem is not None:
                raise BTLogicError(f"Node [{owner}]: {problem}")
        result[port.name] = port
    return result


class BehaviorTreeFactory:
    """Registers node types and behavior trees, and creates :class:`Tree` instances.

    Args:
        clock: the time source of every tree this factory creates (default: a :class:`WallClock`).
        register_builtins: register the 42 node IDs BT.CPP 4.10 registers by default.
    """

    def __init__(self, clock: Clock | None = None, *, register_builtins: bool = True) -> None:
        self.clock: Clock = clock if clock is not None else WallClock()
        self._builders: dict[str, NodeBuilder] = {}
        self._manifests: dict[str, NodeManifest] = {}
        self.enums: dict[str, int] = {}
        self.library = TreeLibrary()
        # Spelled ID (an old one, or today's with old ports) -> its former spellings; the library
        # reads XML through them (kinema.bt.spellings).
        self.former_spellings: dict[str, list[FormerSpelling]] = {}
        self.library.spellings = self.former_spellings
        # Bumped by every change of the node types or enums: compiled tree plans depend on them.
        self._generation = 0
        self._node_classes: tuple[int, dict[str, type[TreeNode]]] | None = None
        self._serial = next(_FACTORY_SERIALS)
        if register_builtins:
            from kinema.bt.builtins import register_builtin_nodes

            register_builtin_nodes(self)

    # -- node types ------------------------------------------------------------------------------

    def register_builder(self, manifest: NodeManifest, builder: NodeBuilder) -> None:
        """Register a node type from a manifest and a ``builder(name, config) -> TreeNode``.

        Raises:
            BTLogicError: the ID is invalid or already registered.
        """
        node_id = manifest.id
        problem = model_name_problem(node_id)
        if problem is not None:
            raise BTLogicError(f"Cannot register node type: {problem}")
        if node_id in self._builders:
            raise BTLogicError(f"ID [{node_id}] already registered")
        self._builders[node_id] = builder
        self._manifests[node_id] = manifest
        self._generation += 1

    def register_node_type(
        self,
        cls: type[TreeNode],
        id: str | None = None,
        *,
        description: str | None = None,
        metadata: Iterable[tuple[str, str]] | dict[str, str] | None = None,
        builtin: bool = False,
    ) -> None:
        """Register a node class under ``id`` (default: the class name).

        The class is constructed as ``cls(name, config)`` and declares its ports with the
        classmethod ``provided_ports()``. ``metadata`` (or a ``metadata()`` classmethod) becomes
        ``<MetadataFields>`` in the TreeNodesModel.
        """
        if not (inspect.isclass(cls) and issubclass(cls, TreeNode)):
            raise BTLogicError(f"register_node_type() needs a TreeNode subclass, got {cls!r}")
        node_id = id or cls.__name__
        ports = _ports_dict(cls.provided_ports(), node_id, check_names=not builtin)
        if metadata is None and callable(getattr(cls, "metadata", None)):
            metadata = cls.metadata()  # type: ignore[attr-defined]
        pairs = list(metadata.items()) if isinstance(metadata, dict) else list(metadata or [])
        doc = description if description is not None else (inspect.getdoc(cls) or "").split("\n\n")[0]
        manifest = NodeManifest(node_id, category_of(cls), ports, doc, pairs, builtin)
        self.register_builder(manifest, cls)

    def register_simple_action(
        self, id: str, fn: Callable[[TreeNode], NodeStatus], ports: Iterable[PortInfo] = ()
    ) -> None:
        """Register a sync action calling ``fn(node)``; it may not return RUNNING."""
        manifest = NodeManifest(id, NodeType.ACTION, _ports_dict(ports, id))
        self.register_builder(manifest, lambda name, config: SimpleActionNode(name, config, fn))

    def register_simple_condition(
        self, id: str, fn: Callable[[TreeNode], NodeStatus], ports: Iterable[PortInfo] = ()
    ) -> None:
        """Register a condition calling ``fn(node)``."""
        manifest = NodeManifest(id, NodeType.CONDITION, _ports_dict(ports, id))
        self.register_builder(manifest, lambda name, config: SimpleConditionNode(name, config, fn))

    def register_simple_decorator(
        self,
        id: str,
        fn: Callable[[NodeStatus, TreeNode], NodeStatus],
        ports: Iterable[PortInfo] = (),
    ) -> None:
        """Register a decorator calling ``fn(child_status, node)`` after ticking its child."""
        manifest = NodeManifest(id, NodeType.DECORATOR, _ports_dict(ports, id))
        self.register_builder(manifest, lambda name, config: SimpleDecoratorNode(name, config, fn))

    def register_former_spelling(self, spelling: FormerSpelling) -> None:
        """Read nodes written in ``spelling`` (an old ID, or today's ID with old port names) as today's.

        Raises:
            BTLogicError: no current ID, or the old ID already names another node type's old spelling.
        """
        if not spelling.current_id:
            raise BTLogicError(f"former spelling {spelling.old_id or spelling.ports!r} names no current ID")
        spelled = spelling.spelled_id
        for other in self.former_spellings.get(spelled, []):
            if spelling.old_id and other.current_id != spelling.current_id:
                raise BTLogicError(
                    f"{spelling.old_id} is declared the old name of both {other.current_id} and "
                    f"{spelling.current_id}"
                )
        self.former_spellings.setdefault(spelled, []).append(spelling)
        self._generation += 1

    def unregister(self, id: str) -> bool:
        """Forget node type ``id``; False if it was not registered."""
        self._manifests.pop(id, None)
        self._generation += 1
        return self._builders.pop(id, None) is not None

    def plan_key(self) -> tuple[int, int]:
        """Identifies this factory's registry as it is now (tree plans compiled for it are valid)."""
        return (self._serial, self._generation)

    def is_registered(self, id: str) -> bool:
        """True if ``id`` is a registered node type."""
        return id in self._builders

    def manifests(self) -> dict[str, NodeManifest]:
        """Registered node types: ID -> manifest (category, ports, description, metadata)."""
        return dict(self._manifests)

    def node_classes(self) -> dict[str, type[TreeNode]]:
        """The registered node types that are TreeNode classes (the tree builder constructs those
        itself); one dict per registry generation, not to be changed by the caller."""
        cached = self._node_classes
        if cached is None or cached[0] != self._generation:
            classes = {
                node_id: builder
                for node_id, builder in self._builders.items()
                if isinstance(builder, type) and issubclass(builder, TreeNode)
            }
            cached = self._node_classes = (self._generation, classes)
        return cached[1]

    def builtin_nodes(self) -> list[str]:
        """IDs of the built-in node types."""
        return [m.id for m in self._manifests.values() if m.builtin]

    def instantiate_node(self, id: str, name: str, config: NodeConfig) -> TreeNode:
        """Create one node of type ``id`` (used by the tree builder)."""
        builder = self._builders.get(id)
        if builder is None:
            raise BTRuntimeError(f"Node not recognized: {id}; {did_you_mean(id, self._builders)}")
        if config.manifest is None:
            config.manifest = self._manifests.get(id)
        node = builder(name, config)
        if not isinstance(node, TreeNode):
            raise BTLogicError(f"the builder of [{id}] returned {node!r}, not a TreeNode")
        if node.config is not config:
            raise BTLogicError(f"node type [{id}] must pass its config to TreeNode.__init__(name, config)")
        node.registration_id = id
        return node

    # -- scripting enums -------------------------------------------------------------------------

    def register_scripting_enum(self, name: str, value: int) -> None:
        """Make ``name`` usable in scripts (as ``value``) and in enum ports and Switch cases.

        Raises:
            BTLogicError: ``name`` is already registered with a different value.
        """
        previous = self.enums.get(name)
        if previous is not None and previous != int(value):
            raise BTLogicError(
                f"Registering the enum [{name}] twice with different values, "
                f"first {previous} and later {int(value)}"
            )
        self.enums[name] = int(value)
        self._generation += 1

    def register_scripting_enums(self, enum_type: type[enum.Enum]) -> None:
        """Register every member of an int-valued ``Enum`` by name."""
        for member in enum_type:
            self.register_scripting_enum(member.name, int(member.value))

    # -- trees -----------------------------------------------------------------------------------

    def register_behavior_tree_from_text(self, xml: str, filename: str = "<string>") -> etree._Element:
        """Load every ``<BehaviorTree>`` of an XML text (includes resolve against the current path); returns
        the document's root element (the same parse, kept while the text is loaded again)."""
        return self.library.load_text(xml, filename, self._manifests, registry=self.plan_key())

    def register_behavior_tree_from_file(self, path: str | Path) -> etree._Element:
        """Load every ``<BehaviorTree>`` of an XML file; returns the document's root element."""
        return self.library.load_file(path, self._manifests)

    def registered_behavior_trees(self) -> list[str]:
        """IDs of the loaded trees, sorted."""
        return sorted(self.library.trees)

    def tree_definition(self, tree_id: str) -> TreeDefinition:
        """The loaded definition of ``tree_id`` (its XML element, file and metadata)."""
        definition = self.library.trees.get(tree_id)
        if definition is None:
            raise BTRuntimeError(f"unknown tree '{tree_id}'; {did_you_mean(tree_id, self.library.trees)}")
        return definition

    def clear_registered_behavior_trees(self) -> None:
        """Forget every loaded tree."""
        self.library.clear()

    def create_tree(self, tree_id: str, blackboard: Blackboard | None = None) -> Tree:
        """Instantiate a loaded tree; ``blackboard`` becomes its root scope (a new one if None)."""
        from kinema.bt.builder import TreeBuilder

        if tree_id not in self.library.trees:
            raise TreeNotFoundError(
                tree_id,
                f"Can't find a tree with name: {tree_id}; {did_you_mean(tree_id, self.library.trees)}",
            )
        return TreeBuilder(self).build(tree_id, blackboard if blackboard is not None else Blackboard.create())

    def create_tree_from_text(
        self, xml: str, blackboard: Blackboard | None = None, *, filename: str = "<string>"
    ) -> Tree:
        """Load ``xml`` and instantiate its main tree (``main_tree_to_execute`` or BT.CPP's fallbacks)."""
        before = set(self.library.trees)
        root = self.library.load_text(xml, filename, self._manifests, registry=self.plan_key())
        return self.create_tree(self.library.main_tree_of(root, before), blackboard)

    def create_tree_from_file(self, path: str | Path, blackboard: Blackboard | None = None) -> Tree:
        """Load an XML file and instantiate its main tree."""
        before = set(self.library.trees)
        root = self.library.load_file(path, self._manifests)
        return self.create_tree(self.library.main_tree_of(root, before), blackboard)
