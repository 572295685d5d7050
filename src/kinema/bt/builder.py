"""Instantiating a tree definition: XML elements -> nodes, blackboards, subtrees (reference 1.4-1.7, 5)."""

from __future__ import annotations

import enum
from typing import TYPE_CHECKING, Any

from kinema.bt.blackboard import Blackboard
from kinema.bt.conversions import convert_from_string, parse_double_full, parse_int_full, type_name
from kinema.bt.decorators import SubTreeNode
from kinema.bt.errors import BTError, BTLogicError, BTRuntimeError, ScriptParseError
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
from kinema.bt.xmlparser import EXPLICIT_TAGS, element_children, line_of
from kinema.errors import SourceLocation

if TYPE_CHECKING:
    from lxml import etree

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

            raise BTRuntimeError(
                f"Can't find a tree with name: {tree_id}; {did_you_mean(tree_id, self.library.trees)}"
            )
        root_element = definition.root_element
        if root_element is None:
            raise BTRuntimeError(
                f"The tag <BehaviorTree> with ID '{tree_id}' must have exactly 1 child",
                location=definition.location,
            )
        blackboard.name = tree_path or tree_id
        subtree = Subtree(tree_id, tree_path, blackboard)
        self.tree.subtrees.append(subtree)
        ancestors.append(tree_id)
        filename = definition.filename
        # Iterative depth-first walk (pre-order, uids in creation order) so deep trees cannot
        # exhaust the Python stack.
        stack: list[tuple[etree._Element, TreeNode | None]] = [(root_element, parent)]
        while stack:
            element, parent_node = stack.pop()
            node = self._create_node(element, blackboard, parent_node, prefix, filename)
            subtree.nodes.append(node)
            if isinstance(node, SubTreeNode):
                self._enter_subtree(node, element, subtree, blackboard, filename, ancestors)
            else:
                for child in reversed(element_children(element)):
                    stack.append((child, node))
        ancestors.pop()

    def _enter_subtree(
        self,
        node: SubTreeNode,
        element: etree._Element,
        subtree: Subtree,
        blackboard: Blackboard,
        filename: str,
        ancestors: list[str],
    ) -> None:
        subtree_id = element.get("ID") or ""
        new_bb = Blackboard.create(blackboard)
        remapping: dict[str, str] = {}
        autoremap = False
        for attr_name, attr_value in element.attrib.items():
            attr_name = str(attr_name)
            if attr_value == "{=}":
                attr_value = "{" + attr_name + "}"
            if attr_name == "_autoremap":
                try:
                    autoremap = convert_from_string(bool, attr_value)
                except BTError as error:
                    raise BTRuntimeError(
                        error.message, location=SourceLocation(filename, line_of(element))
                    ) from None
                new_bb.enable_auto_remapping(autoremap)
                continue
            if not is_allowed_port_name(attr_name):
                continue
            remapping[attr_name] = attr_value
        model = self.library.subtree_models.get(subtree_id)
        if model is not None:
            for port_name, port_info in model.ports.items():
                if port_name not in remapping and not autoremap:
                    if not port_info.default_str:
                        raise BTRuntimeError(
                            f'In the <TreeNodesModel> the <Subtree ID="{subtree_id}"> is defining '
                            "a mandatory "
                            f"port called [{port_name}], but you are not remapping it",
                            location=SourceLocation(filename, line_of(element)),
                        )
                    remapping[port_name] = port_info.default_str
        for attr_name, attr_value in remapping.items():
            stripped = attr_value.strip()
            if len(stripped) >= 3 and stripped[0] == "{" and stripped[-1] == "}":
                new_bb.add_subtree_remapping(attr_name, stripped[1:-1])
            else:
                # A literal is stored locally and never auto-remapped.
                new_bb.enable_auto_remapping(False)
                new_bb.set(attr_name, literal_subtree_value(attr_value))
                new_bb.enable_auto_remapping(autoremap)
        path = subtree.instance_name
        if path:
            path += "/"
        name = element.get("name")
        path += name if name is not None else f"{subtree_id}::{node.uid}"
        for existing in self.tree.subtrees:
            if existing.instance_name == path:
                raise BTRuntimeError(
                    f"Duplicate SubTree path detected: '{path}'. Multiple SubTree nodes with the same 'name' "
                    "attribute under the same parent are not allowed. Please use unique names or omit the "
                    "'name' attribute to auto-generate unique paths.",
                    location=SourceLocation(filename, line_of(element)),
                )
        self._create_subtree(subtree_id, path, path + "/", new_bb, node, ancestors)

    def _create_node(
        self,
        element: etree._Element,
        blackboard: Blackboard,
        parent: TreeNode | None,
        prefix: str,
        filename: str,
    ) -> TreeNode:
        tag = str(element.tag)
        line = line_of(element)
        location = _LazyLocation(filename, line)
        element_id = element.get("ID")
        if tag in EXPLICIT_TAGS:
            if element_id is None:
                raise BTRuntimeError(f"Attribute [ID] is mandatory in <{tag}>", location=location)
            type_id = element_id
        else:
            if not self.factory.is_registered(tag):
                raise BTRuntimeError(f"{tag} is not a registered node", location=location)
            type_id = tag
            if element_id is not None:
                raise BTRuntimeError(f"Attribute [ID] is not allowed in <{type_id}>", location=location)
        explicit_name = element.get("name")
        instance_name = explicit_name if explicit_name is not None else type_id
        if explicit_name is not None:
            problem = instance_name_problem(explicit_name)
            if problem:
                raise BTRuntimeError(f"Error at line {line}: {problem}", location=location)
        is_subtree = tag == "SubTree"
        manifest = None if is_subtree else self.manifests.get(type_id)
        port_remap: dict[str, str] = {}
        other: dict[str, str] = {}
        for attr_name, attr_value in element.attrib.items():
            attr_name = str(attr_name)
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
                            location=location,
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
                                location=location,
                            ) from None
                port_remap[attr_name] = attr_value
            elif attr_name not in RESERVED_ATTRIBUTES:
                other[attr_name] = attr_value
        config = NodeConfig(blackboard)
        config.uid = self.tree.next_uid()
        config.path = prefix + instance_name + (f"::{config.uid}" if instance_name == type_id else "")
        config.manifest = manifest
        config.enums = self.factory.enums
        config.other_attributes = other
        config.wake_up = self.tree.wake_up
        config.clock = self.factory.clock
        config.source_file = filename
        config.source_line = line
        if other or len(element.attrib) > len(port_remap):
            # Only elements with reserved attributes can carry pre/post-conditions.
            for key in PRE_CONDITIONS:
                code = element.get(key)
                if code is not None:
                    config.pre_conditions[key] = _parse_condition(code, key, config.path, location)
            for key in POST_CONDITIONS:
                code = element.get(key)
                if code is not None:
                    config.post_conditions[key] = _parse_condition(code, key, config.path, location)
        if is_subtree:
            config.input_ports = dict(port_remap)
            config.manifest = self.manifests.get("SubTree")
            node = self.factory.instantiate_node("SubTree", instance_name, config)
            assert isinstance(node, SubTreeNode)
            node.subtree_id = type_id
        else:
            if manifest is None:
                from kinema.errors import did_you_mean

                raise BTRuntimeError(
                    f"Node not recognized: {type_id}; {did_you_mean(type_id, self.manifests)}",
                    location=location,
                )
            self._precreate_entries(manifest, port_remap, blackboard, location)
            for port_name, value in port_remap.items():
                direction = manifest.ports[port_name].direction
                if direction is not PortDirection.OUTPUT:
                    config.input_ports[port_name] = value
                if direction is not PortDirection.INPUT:
                    config.output_ports[port_name] = value
            _apply_defaults(manifest, config)
            try:
                node = self.factory.instantiate_node(type_id, instance_name, config)
            except BTError as error:
                if error.location is None:
                    error.location = location
                raise
        if parent is not None:
            if isinstance(parent, ControlNode):
                parent.add_child(node)
            elif isinstance(parent, DecoratorNode):
                parent.set_child(node)
        return node

    def _precreate_entries(
        self, manifest: Any, port_remap: dict[str, str], blackboard: Blackboard, location: SourceLocation
    ) -> None:
        for port_name, port_info in manifest.ports.items():
            value = port_remap.get(port_name)
            if value is None:
                continue
            key = blackboard_pointer(value, port_name)
            if key is None:
                continue
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
                if mismatch and existing.type is not str and not accepts:
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


class _LazyLocation(SourceLocation):
    """A SourceLocation for error paths; built per node, so it skips the frozen-dataclass init."""

    def __init__(self, file: str, line: int) -> None:
        object.__setattr__(self, "file", file)
        object.__setattr__(self, "line", line)


def _apply_defaults(manifest: Any, config: NodeConfig) -> None:
    """Declared defaults for ports the XML omits (an empty default is not applied, as in BT.CPP)."""
    for port_name, port_info in manifest.ports.items():
        if not port_info.has_default or not port_info.default_str:
            continue
        text = port_info.default_str
        if port_info.direction is not PortDirection.OUTPUT and port_name not in config.input_ports:
            # Plain values travel as text, like BT.CPP's default strings; other objects (no text
            # form) are handed over as they are.
            plain = isinstance(port_info.default, str | int | float | list | tuple | enum.Enum)
            config.input_ports[port_name] = text if plain else port_info.default
        if (
            port_info.direction is not PortDirection.INPUT
            and port_name not in config.output_ports
            and blackboard_pointer(text, port_name) is not None
        ):
            config.output_ports[port_name] = text


def _parse_condition(code: str, attribute: str, path: str, location: SourceLocation) -> Any:
    try:
        return parse_script(code)
    except ScriptParseError as error:
        raise BTLogicError(
            f"Error in the script \"{code}\" of attribute {attribute} in node '{path}': {error.message}",
            location=location,
        ) from None
