"""Instantiating a tree definition: XML elements -> nodes, blackboards, subtrees (reference 1.4-1.7, 5)."""

from __future__ import annotations

import enum
from typing import TYPE_CHECKING, Any

from kinema.bt.blackboard import Blackboard
from kinema.bt.conversions import Unsigned, convert_from_string, parse_double_full, parse_int_full, type_name
from kinema.bt.decorators import SubTreeNode
from kinema.bt.errors import BTError, BTLogicError, BTRuntimeError, ScriptParseError, TreeNotFoundError
from kinema.bt.limits import MAX_TREE_NODES
from kinema.bt.names import (
    POST_CONDITIONS,
    PRE_CONDITIONS,
    RESERVED_ATTRIBUTES,
    instance_name_problem,
    is_allowed_port_name,
)
from kinema.bt.node import ControlNode, DecoratorNode, NodeConfig, TreeNode
from kinema.bt.ports import PortDirection, blackboard_pointer, strict_blackboard_pointer
from kinema.bt.script import parse_script
from kinema.bt.tree import Subtree, Tree
from kinema.bt.xmlparser import EXPLICIT_TAGS, Skeleton, read_skeleton
from kinema.errors import SourceLocation

if TYPE_CHECKING:
    from kinema.bt.factory import BehaviorTreeFactory

MAX_SUBTREE_DEPTH = 256


def literal_subtree_value(text: str) -> Any:
    """A literal SubTree attribute keeps its numeric type (4.9.1+): int, then double, else text."""
    if "." not in text and "e" not in text and "E" not in text:
        number = parse_int_full(text)
        if number is not None:
            return number
    value = parse_double_full(text)
    if value is not None:
        return value
    return text


class TreeBuilder:
    """Builds one :class:`Tree` from the factory's library."""

    def __init__(self, factory: BehaviorTreeFactory) -> None:
        self.factory = factory
        self.library = factory.library
        self.manifests = factory.manifests()
        self.tree = Tree(factory.clock, self.manifests)
        self._wake_up = self.tree.wake_up  # one bound method for every node's config
        # Plans compiled for another factory or registry generation are not reused.
        self.plan_key = factory.plan_key()
        self._enums = factory.enums
        self._clock = factory.clock
        # (tag, attributes...) -> what that element compiles to (valid for this registry only)
        self.kinds: dict[tuple[Any, ...], NodeKind] = {}
        # The instance path of every Subtree made so far (two SubTree nodes may not make the same one).
        self._subtree_paths: set[str] = set()
        # Registered node classes, which the builder constructs itself (other builders go through
        # factory.instantiate_node, which checks what they return).
        self._classes: dict[str, type[TreeNode]] = factory.node_classes()
        # The entries SubTree number literals created (ids, while this tree is built): see _number_fits.
        self._number_literals: set[int] = set()

    def build(self, tree_id: str, blackboard: Blackboard) -> Tree:
        """Instantiate ``tree_id`` with ``blackboard`` as the root scope."""
        if blackboard.time_source is None:
            blackboard.time_source = self.factory.clock.now
        self._create_subtree(tree_id, "", "", blackboard, None, [])
        return self.tree

    def _create_subtree(
        self,
        tree_id: str,
        tree_path: str,
        prefix: str,
        blackboard: Blackboard,
        parent: TreeNode | None,
        ancestors: list[str],
    ) -> None:
        if tree_id in ancestors:
            chain = " -> ".join([*ancestors, tree_id])
            raise BTRuntimeError(f"Recursive behavior tree cycle detected: tree '{tree_id}' ({chain})")
        if len(ancestors) >= MAX_SUBTREE_DEPTH:
            raise BTRuntimeError(f"SubTrees nest deeper than {MAX_SUBTREE_DEPTH} levels")
        definition = self.library.trees.get(tree_id)
        if definition is None:
            from kinema.errors import did_you_mean

            raise TreeNotFoundError(
                tree_id,
                f"Can't find a tree with name: {tree_id}; {did_you_mean(tree_id, self.library.trees)}",
            )
        plan = definition.plan if definition.plan_key == self.plan_key else None
        root_element = definition.root_element if plan is None else None  # a plan was compiled from one
        if plan is None and root_element is None:
            raise BTRuntimeError(
                f"The tag <BehaviorTree> with ID '{tree_id}' must have exactly 1 child",
                location=definition.location,
            )
        blackboard.name = tree_path or tree_id
        subtree = Subtree(tree_id, tree_path, blackboard)
        self.tree.subtrees.append(subtree)
        self._subtree_paths.add(tree_path)
        ancestors.append(tree_id)
        filename = definition.filename
        if plan is None:
            # First instance with this registry: compile each element as it is reached (so the
            # first error is the one a plain walk meets first) and keep the plan for the next ones.
            skeleton = definition.skeleton
            if skeleton is None:  # (verification did not walk it: it holds comments, say)
                assert root_element is not None
                skeleton = read_skeleton(root_element)
            plan = self._compile_skeleton(skeleton, blackboard, parent, prefix, subtree, ancestors, filename)
            definition.plan = plan
            definition.plan_key = self.plan_key
        else:
            self._instantiate_plan(plan, blackboard, parent, prefix, subtree, ancestors, filename)
        ancestors.pop()

    def _compile_skeleton(
        self,
        skeleton: Skeleton,
        blackboard: Blackboard,
        parent: TreeNode | None,
        prefix: str,
        subtree: Subtree,
        ancestors: list[str],
        filename: str,
    ) -> Plan:
        # Each element is compiled as it is reached, in document order (the order nodes are created
        # and numbered in), so the first error is the one a plain walk meets first.
        signatures, lines, parents = skeleton
        plan_kinds: list[NodeKind] = []
        nodes = subtree.nodes
        kinds = self.kinds
        create = self._create_node
        for signature, line, parent_index in zip(signatures, lines, parents, strict=True):
            kind = kinds.get(signature)
            if kind is None:
                kind = kinds[signature] = self._compile_kind(signature, filename, prefix, line)
            plan_kinds.append(kind)
            node = create(
                kind, line, blackboard, nodes[parent_index] if parent_index >= 0 else parent, prefix, filename
            )
            nodes.append(node)
            if kind.is_subtree:
                self._enter_subtree(node, kind, line, subtree, blackboard, filename, ancestors)  # type: ignore[arg-type]
        return plan_kinds, lines, parents

    def _instantiate_plan(
        self,
        plan: Plan,
        blackboard: Blackboard,
        parent: TreeNode | None,
        prefix: str,
        subtree: Subtree,
        ancestors: list[str],
        filename: str,
    ) -> None:
        # A flat walk: each step's parent was made before it (pre-order), and the subtree's nodes
        # are the plan's steps in order.
        nodes = subtree.nodes
        create = self._create_node
        for kind, line, parent_index in zip(*plan, strict=True):
            node = create(
                kind, line, blackboard, nodes[parent_index] if parent_index >= 0 else parent, prefix, filename
            )
            nodes.append(node)
            if kind.is_subtree:
                self._enter_subtree(node, kind, line, subtree, blackboard, filename, ancestors)  # type: ignore[arg-type]

    def _enter_subtree(
        self,
        node: SubTreeNode,
        kind: NodeKind,
        line: int,
        subtree: Subtree,
        blackboard: Blackboard,
        filename: str,
        ancestors: list[str],
    ) -> None:
        subtree_id = kind.type_id
        new_bb = Blackboard(blackboard)
        ports = kind.subtree_ports
        if ports is None:
            ports = kind.subtree_ports = _subtree_ports(kind, filename, line)
        remapping, autoremap = ports
        if autoremap:
            new_bb.enable_auto_remapping(True)
        model = self.library.subtree_models.get(subtree_id)
        if model is not None:
            remapping = dict(remapping)
            for port_name, port_info in model.ports.items():
                if port_name not in remapping and not autoremap:
                    if not port_info.default_str:
                        raise BTRuntimeError(
                            f'In the <TreeNodesModel> the <Subtree ID="{subtree_id}"> is defining '
                            "a mandatory "
                            f"port called [{port_name}], but you are not remapping it",
                            location=SourceLocation(filename, line),
                        )
                    remapping[port_name] = port_info.default_str
        for attr_name, attr_value in remapping.items():
            stripped = attr_value.strip()
            if len(stripped) >= 3 and stripped[0] == "{" and stripped[-1] == "}":
                new_bb.add_subtree_remapping(attr_name, stripped[1:-1])
            else:
                # A literal is stored locally and never auto-remapped.
                new_bb.enable_auto_remapping(False)
                literal = literal_subtree_value(attr_value)
                new_bb.set(attr_name, literal)
                if not isinstance(literal, str):
                    self._number_literals.add(id(new_bb.get_entry(attr_name)))
                new_bb.enable_auto_remapping(autoremap)
        path = subtree.instance_name
        if path:
            path += "/"
        name = kind.explicit_name
        path += name if name is not None else f"{subtree_id}::{node.uid}"
        if path in self._subtree_paths:
            raise BTRuntimeError(
                f"Duplicate SubTree path detected: '{path}'. Multiple SubTree nodes with the same 'name' "
                "attribute under the same parent are not allowed. Please use unique names or omit the "
                "'name' attribute to auto-generate unique paths.",
                location=SourceLocation(filename, line),
            )
        try:
            self._create_subtree(subtree_id, path, path + "/", new_bb, node, ancestors)
        except TreeNotFoundError as error:
            if error.location is None:  # this <SubTree> names the missing tree
                error.location = SourceLocation(filename, line)
            raise

    def _compile_kind(self, signature: tuple[Any, ...], filename: str, prefix: str, line: int) -> NodeKind:
        """What an element compiles to, from its signature: its tag, then its attributes' (name, value)."""
        tag = str(signature[0])
        attributes: list[tuple[str, str]] = list(signature[1:])
        values = dict(attributes)
        element_id = values.get("ID")
        if tag in EXPLICIT_TAGS:
            if element_id is None:
                raise BTRuntimeError(
                    f"Attribute [ID] is mandatory in <{tag}>", location=_LazyLocation(filename, line)
                )
            type_id = element_id
        else:
            if not self.factory.is_registered(tag):
                raise BTRuntimeError(
                    f"{tag} is not a registered node", location=_LazyLocation(filename, line)
                )
            type_id = tag
            if element_id is not None:
                raise BTRuntimeError(
                    f"Attribute [ID] is not allowed in <{type_id}>", location=_LazyLocation(filename, line)
                )
        explicit_name: str | None = values.get("name")
        instance_name = explicit_name if explicit_name is not None else type_id
        if explicit_name is not None:
            problem = instance_name_problem(explicit_name)
            if problem:
                raise BTRuntimeError(
                    f"Error at line {line}: {problem}", location=_LazyLocation(filename, line)
                )
        is_subtree = tag == "SubTree"
        manifest = None if is_subtree else self.manifests.get(type_id)
        port_remap: dict[str, str] = {}
        other: dict[str, str] = {}
        for attr_name, attr_value in attributes:
            if is_allowed_port_name(attr_name):
                if manifest is not None:
                    port_info = manifest.ports.get(attr_name)
                    if port_info is None:
                        from kinema.errors import did_you_mean

                        raise BTRuntimeError(
                            f"a port with name [{attr_name}] is found in the XML (<{tag}>, line {line}) "
                            "but not "
                            f"in the providedPorts() of its registered node type. "
                            + (
                                f"{did_you_mean(attr_name, manifest.ports).capitalize()}."
                                if manifest.ports
                                else f"{type_id} has no ports."
                            ),
                            location=_LazyLocation(filename, line),
                        )
                    if (
                        not strict_blackboard_pointer(attr_value)
                        and port_info.has_converter
                        and port_info.strongly_typed
                    ):
                        try:
                            convert_from_string(port_info.type, attr_value, self.factory.enums)
                        except BTError:
                            raise BTLogicError(
                                f'The port with name "{attr_name}" and value "{attr_value}" can not be '
                                f"converted to {type_name(port_info.type)}",
                                location=_LazyLocation(filename, line),
                            ) from None
                port_remap[attr_name] = attr_value
            elif attr_name not in RESERVED_ATTRIBUTES:
                other[attr_name] = attr_value
        # The path gets "::uid" when the node has no name of its own.
        unnamed = instance_name == type_id
        pre_conditions: dict[str, Any] = _NOTHING
        post_conditions: dict[str, Any] = _NOTHING
        if not _CONDITION_ATTRIBUTES.isdisjoint(values):
            # The path the node is about to get (for messages only).
            path = prefix + instance_name + (f"::{self.tree._uid + 1}" if unnamed else "")
            # The parsed scripts are stateless and shared by every instance.
            pre_conditions = {
                key: _parse_condition(values[key], key, path, filename, line)
                for key in PRE_CONDITIONS
                if key in values
            }
            post_conditions = {
                key: _parse_condition(values[key], key, path, filename, line)
                for key in POST_CONDITIONS
                if key in values
            }
        if is_subtree:
            return NodeKind(
                type_id,
                True,
                instance_name,
                explicit_name,
                unnamed,
                self.manifests.get("SubTree"),
                attributes,
                other,
                port_remap,
                _NOTHING,
                pre_conditions,
                post_conditions,
                (),
                self._classes.get("SubTree"),
            )
        if manifest is None:
            from kinema.errors import did_you_mean

            raise BTRuntimeError(
                f"Node not recognized: {type_id}; {did_you_mean(type_id, self.manifests)}",
                location=_LazyLocation(filename, line),
            )
        entries: list[tuple[str, Any]] = []
        input_ports: dict[str, Any] = {}
        output_ports: dict[str, Any] = {}
        if port_remap:
            ports = manifest.ports
            for port_name, port_info in ports.items():
                value = port_remap.get(port_name)
                if value is None:
                    continue
                entry_key = blackboard_pointer(value, port_name)
                if entry_key is not None:
                    entries.append((entry_key, port_info))
            for port_name, value in port_remap.items():
                direction = ports[port_name].direction
                if direction is not PortDirection.OUTPUT:
                    input_ports[port_name] = value
                if direction is not PortDirection.INPUT:
                    output_ports[port_name] = value
        if manifest.ports:
            _apply_defaults(manifest, input_ports, output_ports)
        return NodeKind(
            type_id,
            False,
            instance_name,
            explicit_name,
            unnamed,
            manifest,
            attributes,
            other,
            input_ports,
            output_ports,
            pre_conditions,
            post_conditions,
            entries,
            self._classes.get(type_id),
        )

    def _create_node(
        self,
        kind: NodeKind,
        line: int,
        blackboard: Blackboard,
        parent: TreeNode | None,
        prefix: str,
        filename: str,
    ) -> TreeNode:
        tree = self.tree
        config = _new_config(NodeConfig)
        config.blackboard = blackboard
        uid = tree._uid + 1
        if uid > MAX_TREE_NODES:
            tree.next_uid()  # raises, with the explanation
        tree._uid = config.uid = uid
        instance_name = kind.instance_name
        config.path = prefix + instance_name + f"::{uid}" if kind.unnamed else prefix + instance_name
        config.manifest = kind.manifest
        config.enums = self._enums
        config.wake_up = self._wake_up
        config.clock = self._clock
        config.source_file = filename
        config.source_line = line
        # Each node owns its dicts (a node may change them): a copy of the kind's, or None for an empty
        # one (NodeConfig makes it on first use).
        config._other_attributes = kind.other.copy() if kind.other else None
        config._input_ports = kind.input_ports.copy() if kind.input_ports else None
        config._output_ports = kind.output_ports.copy() if kind.output_ports else None
        config._pre_conditions = kind.pre_conditions.copy() if kind.pre_conditions else None
        config._post_conditions = kind.post_conditions.copy() if kind.post_conditions else None
        if kind.entries:
            self._precreate_entries(kind.entries, blackboard, _LazyLocation(filename, line))
        node_type = kind.node_type
        cls = kind.node_class
        try:
            if cls is None:
                node = self.factory.instantiate_node(node_type, instance_name, config)
            else:
                # What instantiate_node does for a class (its manifest is already in the config).
                node = cls(instance_name, config)
                if node.config is not config:
                    raise BTLogicError(
                        f"node type [{node_type}] must pass its config to TreeNode.__init__(name, config)"
                    )
                node.registration_id = node_type
        except BTError as error:
            if error.location is None:
                error.location = _LazyLocation(filename, line)
            raise
        if kind.is_subtree:
            assert isinstance(node, SubTreeNode)
            node.subtree_id = kind.type_id
        if parent is not None:
            if isinstance(parent, ControlNode):
                parent.add_child(node)
            elif isinstance(parent, DecoratorNode):
                parent.set_child(node)
        return node

    def _precreate_entries(
        self, entries: list[tuple[str, Any]], blackboard: Blackboard, location: SourceLocation
    ) -> None:
        for key, port_info in entries:
            existing = blackboard.get_entry(key)
            if existing is not None:
                mismatch = (
                    existing.strongly_typed and port_info.strongly_typed and existing.type != port_info.type
                )
                # A value set from outside the tree (Blackboard.set, a test) types its entry by its class;
                # a port type that accepts that very value (a message type, say) is the same type to it.
                accepts = (
                    existing.value is not None
                    and isinstance(port_info.type, type)
                    and isinstance(existing.value, port_info.type)
                )
                if (
                    mismatch
                    and existing.type is not str
                    and not accepts
                    and not (id(existing) in self._number_literals and _number_fits(existing, port_info))
                ):
                    raise BTRuntimeError(
                        f"The creation of the tree failed because the port [{key}] was initially "
                        f"created with type [{type_name(existing.type)}] and, later type "
                        f"[{type_name(port_info.type)}] was "
                        "used somewhere else.",
                        location=location,
                    )
            else:
                try:
                    blackboard.create_entry(key, port_info.type)
                except BTError as error:
                    raise BTRuntimeError(error.message, location=location) from None


def _subtree_ports(kind: NodeKind, filename: str, line: int) -> tuple[dict[str, str], bool]:
    """What a ``<SubTree>`` element's own attributes give its instances: the port remapping (port ->
    ``{key}`` or literal text, ``{=}`` spelled out) and ``_autoremap``."""
    remapping: dict[str, str] = {}
    autoremap = False
    for attr_name, attr_value in kind.attributes:
        if attr_value == "{=}":
            attr_value = "{" + attr_name + "}"
        if attr_name == "_autoremap":
            try:
                autoremap = convert_from_string(bool, attr_value)
            except BTError as error:
                raise BTRuntimeError(error.message, location=SourceLocation(filename, line)) from None
            continue
        if is_allowed_port_name(attr_name):
            remapping[attr_name] = attr_value
    return remapping, autoremap


def _number_fits(existing: Any, port_info: Any) -> bool:
    """A number in the entry (from a SubTree literal) that the numeric port's type holds exactly.

    BT.CPP 4.10 refuses ``<SubTree msec_key="500"/>`` reaching an ``unsigned`` port such as Timeout's
    ``msec``: since 4.9.1 the literal is stored as ``int``. The BT.CPP that MoveIt Pro ships stored it as
    text (the universal donor), and MoveIt Pro's own objectives rely on it (lab_sim's Force Relaxation), so
    Kinema accepts a stored number that the port's numeric type represents exactly.
    """
    value, target = existing.value, port_info.type
    if type(value) not in (int, float) or target not in (int, Unsigned, float):
        return False
    if target is float:
        return True
    if isinstance(value, float) and not value.is_integer():
        return False
    number = int(value)
    return 0 <= number <= 2**32 - 1 if target is Unsigned else -(2**31) <= number < 2**31


class NodeKind:
    """What an element compiles to against a registry, shared by every element written the same
    way (same tag and attributes) and by every instance of it."""

    __slots__ = (
        "attributes",
        "entries",
        "explicit_name",
        "input_ports",
        "instance_name",
        "is_subtree",
        "manifest",
        "node_class",
        "node_type",
        "other",
        "output_ports",
        "post_conditions",
        "pre_conditions",
        "subtree_ports",
        "type_id",
        "unnamed",
    )

    def __init__(
        self,
        type_id: str,
        is_subtree: bool,
        instance_name: str,
        explicit_name: str | None,
        unnamed: bool,
        manifest: Any,
        attributes: list[tuple[str, str]],
        other: dict[str, str],
        input_ports: dict[str, Any],
        output_ports: dict[str, Any],
        pre_conditions: dict[str, Any],
        post_conditions: dict[str, Any],
        entries: list[tuple[str, Any]] | tuple[()],
        node_class: type[TreeNode] | None,
    ) -> None:
        # The tree (SubTree) or node type it instantiates, and the registered type that makes its node.
        self.type_id = type_id
        self.is_subtree = is_subtree
        self.node_type = "SubTree" if is_subtree else type_id
        # The registered class the builder constructs itself, or None (a builder function: see
        # TreeBuilder._classes); kinds are only reused with the registry they were made for.
        self.node_class = node_class
        self.instance_name = instance_name
        self.explicit_name = explicit_name
        # True when the instance path gets "::uid" (no name of its own)
        self.unnamed = unnamed
        self.manifest = manifest
        self.attributes = attributes
        # Read-only once made: each node gets copies (empty ones may be shared).
        self.other = other
        self.input_ports = input_ports
        self.output_ports = output_ports
        self.pre_conditions = pre_conditions
        self.post_conditions = post_conditions
        # (blackboard key, port info) of every port given as a {pointer}, in the manifest's order
        self.entries = entries
        # A SubTree's remapping and _autoremap from its attributes (see _subtree_ports; on first use)
        self.subtree_ports: tuple[dict[str, str], bool] | None = None


# A tree definition as the builder needs it, one step per element in document order (pre-order), as
# three columns (a step costs no object of its own): what each element compiles to, its line, and
# the index of its parent's step (-1 for the tree's root). A plan is kept on the TreeDefinition with
# the registry generation it was made for, so SubTree instances and later builds skip the XML.
Plan = tuple[list["NodeKind"], list[int], list[int]]

_new_config = object.__new__
# The empty mapping NodeKinds share (never written: kinds are read-only once made).
_NOTHING: dict[str, Any] = {}
_CONDITION_ATTRIBUTES = frozenset((*PRE_CONDITIONS, *POST_CONDITIONS))


class _LazyLocation(SourceLocation):
    """A SourceLocation for error paths; built per node, so it skips the frozen-dataclass init."""

    def __init__(self, file: str, line: int) -> None:
        object.__setattr__(self, "file", file)
        object.__setattr__(self, "line", line)


def _apply_defaults(manifest: Any, input_ports: dict[str, Any], output_ports: dict[str, Any]) -> None:
    """Declared defaults for ports the XML omits (an empty default is not applied, as in BT.CPP)."""
    for port_name, port_info in manifest.ports.items():
        if not port_info.has_default or not port_info.default_str:
            continue
        text = port_info.default_str
        if port_info.direction is not PortDirection.OUTPUT and port_name not in input_ports:
            # Plain values travel as text, like BT.CPP's default strings; other objects (no text
            # form) are handed over as they are.
            plain = isinstance(port_info.default, str | int | float | list | tuple | enum.Enum)
            input_ports[port_name] = text if plain else port_info.default
        if (
            port_info.direction is not PortDirection.INPUT
            and port_name not in output_ports
            and blackboard_pointer(text, port_name) is not None
        ):
            output_ports[port_name] = text


def _parse_condition(code: str, attribute: str, path: str, filename: str, line: int) -> Any:
    try:
        return parse_script(code)
    except ScriptParseError as error:
        raise BTLogicError(
            f"Error in the script \"{code}\" of attribute {attribute} in node '{path}': {error.message}",
            location=_LazyLocation(filename, line),
        ) from None
