"""The parameters of an objective: what ``-p name=value``, the SDK's overrides and the UI's form can set.

One rule, used by ``kinema objective show``, the agent's objective list (so the SDK and the terminal
UI) and nothing else computing its own:

1. Every input or inout port the objective declares as a subtree (``<TreeNodesModel><SubTree ID>``),
   in file order, with its default and description. These are the objective's interface, as in
   MoveIt Pro.
2. Then every blackboard key ``{key}`` that a node of the objective's own ``<BehaviorTree>`` reads
   through an input or inout port (a port left out of the XML counts through its declared default,
   e.g. ``{=}``) before any node writes it, in document order. An override of such a key is what
   the node reads (MoveIt Pro's parameter overrides write the root blackboard).

A parameter's type is the type of the first port that reads it ("" when no behavior declares one:
behaviors not loaded, or a port of type ``BT::AnyTypeAllowed``). Values are parsed as YAML into that
type when the objective starts (:mod:`kinema.runtime.overrides`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from kinema.bt.xmlparser import EXPLICIT_TAGS
from kinema.config.objective_file import ObjectivePort
from kinema.errors import KinemaError

if TYPE_CHECKING:
    from lxml import etree

    from kinema.config.objective_file import ObjectiveInfo

_UNTYPED = frozenset({"", "BT::AnyTypeAllowed", "BT::Any"})


def objective_parameters(info: ObjectiveInfo, factory: Any = None) -> list[ObjectivePort]:
    """The overridable parameters of ``info`` (see the module docstring), as input/inout ports.

    Args:
        info: the objective.
        factory: a :class:`~kinema.bt.BehaviorTreeFactory` whose manifests say which port of each node
            reads and which writes, and their types, and whose loaded trees say the types of subtree
            ports (None: only the declared ports are known).
    """
    declared = [port for port in info.ports if port.direction in ("input", "inout")]
    tree = _tree_element(info)
    reads = _Reads(factory).of(tree) if tree is not None and factory is not None else {}
    parameters: list[ObjectivePort] = []
    for port in declared:
        type_name = port.type_name or reads.get(port.name, ("", ""))[0]
        parameters.append(ObjectivePort(port.name, port.direction, port.default, port.description, type_name))
    names = {port.name for port in declared}
    for key, (type_name, where) in reads.items():
        if key not in names:
            parameters.append(ObjectivePort(key, "input", None, f"read by {where}", type_name))
    return parameters


class _Reads:
    """The blackboard keys a tree reads before writing them, with the reading port's type."""

    def __init__(self, factory: Any) -> None:
        self._manifests: dict[str, Any] = factory.manifests()
        self._factory = factory
        self._subtrees: dict[str, tuple[dict[str, tuple[str, str]], set[str]]] = {}

    def of(self, tree: etree._Element, depth: int = 0) -> dict[str, tuple[str, str]]:
        """``key -> (type name, "node.port" that reads it first)``, in document order."""
        return self._scan(tree, depth)[0]

    def _scan(self, tree: etree._Element, depth: int) -> tuple[dict[str, tuple[str, str]], set[str]]:
        reads: dict[str, tuple[str, str]] = {}
        written: set[str] = set()
        for element in tree.iter():
            if not isinstance(element.tag, str) or element is tree:
                continue
            for key, direction, type_name, where in self._port_uses(element, depth):
                if direction == "output":
                    written.add(key)
                elif key not in written and key not in reads:
                    reads[key] = (type_name, where)
                if direction == "inout":
                    written.add(key)
        return reads, written

    def _subtree_usage(self, subtree_id: str, depth: int) -> tuple[dict[str, tuple[str, str]], set[str]]:
        # A SubTree's port p="{key}" reads {key} when the subtree reads {p} before writing it.
        if subtree_id in self._subtrees or depth > 16:
            return self._subtrees.get(subtree_id, ({}, set()))
        self._subtrees[subtree_id] = ({}, set())  # a recursive subtree adds nothing rather than looping
        try:
            element = self._factory.tree_definition(subtree_id).element
        except KinemaError:
            return {}, set()
        usage = self._scan(element, depth + 1)
        self._subtrees[subtree_id] = usage
        return usage

    def _port_uses(self, element: etree._Element, depth: int) -> list[tuple[str, str, str, str]]:
        """``(key, direction, type name, "node.port")`` for every blackboard key a node element uses."""
        tag = str(element.tag)
        node_id = element.get("ID", "") if tag in EXPLICIT_TAGS else tag
        label = element.get("name") or node_id
        if tag == "SubTree":
            return self._subtree_uses(element, node_id, label, depth)
        manifest = self._manifests.get(node_id)
        if manifest is None:
            return []
        uses = []
        for name, port in manifest.ports.items():
            key = _pointer(element.get(name), port, name)
            if key is not None:
                type_name = getattr(port, "type_name", "") or ""
                direction = port.direction.name.lower()
                uses.append((key, direction, "" if type_name in _UNTYPED else type_name, f"{label}.{name}"))
        return uses

    def _subtree_uses(
        self, element: etree._Element, subtree_id: str, label: str, depth: int
    ) -> list[tuple[str, str, str, str]]:
        model = self._factory.library.subtree_models.get(subtree_id)
        declared = dict(model.ports) if model is not None else {}
        remaps = {name: value for name, value in element.attrib.items() if not _reserved(str(name))}
        for name, port in declared.items():
            if name not in remaps and isinstance(port.default_str, str):
                remaps[name] = port.default_str
        inner_reads, inner_written = self._subtree_usage(subtree_id, depth)
        uses = []
        for name, text in remaps.items():
            key = _pointer(text, None, name)
            if key is None:
                continue
            if name in inner_reads:
                type_name = inner_reads[name][0]
                direction = "inout" if name in inner_written else "input"
            elif name in inner_written:
                type_name, direction = "", "output"
            elif name in declared:
                type_name, direction = "", declared[name].direction.name.lower()
            else:
                continue
            uses.append((key, direction, type_name, f"{label}.{name}"))
        return uses


def _reserved(attribute: str) -> bool:
    return attribute in ("ID", "name", "__shared_blackboard") or attribute.startswith("_")


def _pointer(text: str | None, port: Any, name: str) -> str | None:
    """The blackboard key a port value (or, when absent, the port's declared default) points to."""
    from kinema.bt.ports import blackboard_pointer

    if text is None and port is not None and isinstance(port.default_str, str):
        text = port.default_str
    if text is None:
        return None
    key = blackboard_pointer(text, name)
    if key is None or key.startswith("="):
        return None
    return key.lstrip("@")


def _tree_element(info: ObjectiveInfo) -> etree._Element | None:
    from kinema.bt.xmlsource import parse_xml

    try:
        root = parse_xml(info.read_xml(), str(info.file))
    except (KinemaError, OSError):  # the library already reported an unreadable file
        return None
    for tree in root.iter("BehaviorTree"):
        if tree.get("ID") == info.id:
            return tree
    return None


def objective_interface(info: ObjectiveInfo, factory: Any = None) -> list[ObjectivePort]:
    """The parameters (:func:`objective_parameters`) followed by the output ports ``info`` declares.

    This is the list every front end shows as an objective's ports; the override form keeps the inputs.
    """
    outputs = [port for port in info.ports if port.direction == "output"]
    return [*objective_parameters(info, factory), *outputs]
