"""The shape of an objective's behavior tree, read from its XML, numbered the way the engine numbers nodes.

The runtime reports node status changes by ``uid`` and ``node_path``. To show them on a tree read from
XML (without building the tree, which would need every behavior installed), the outline numbers nodes as
:class:`kinema.bt.builder.TreeBuilder` does: depth-first pre-order from 1, with each ``<SubTree>``
expanded in place right after its own node, and paths ``<subtree path>/<name>`` (``<ID>::<uid>`` for an
unnamed node). When a subtree's definition is not available the numbering after it cannot be trusted,
so the outline marks itself and status changes are then matched by path only.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

from lxml import etree

from kinema.bt.xmlparser import EXPLICIT_TAGS
from kinema.bt.xmlsource import parse_xml
from kinema.errors import ObjectiveError, did_you_mean

#: A subtree nested deeper than this is a cycle or a mistake; the engine refuses it too.
MAX_SUBTREE_DEPTH = 64

SubtreeLoader = Callable[[str], "str | None"]


@dataclass
class OutlineNode:
    """One node of the outline.

    Attributes:
        uid: the engine's uid for this node (1-based, pre-order).
        type_id: the registration ID (``Sequence``, ``MoveToWaypoint``, a subtree ID).
        name: the ``name`` attribute, or "" when the node has none.
        path: the engine's full path of the node.
        line: the source line of the element (0 when unknown).
        attributes: the element's other attributes (ports, remappings).
        is_subtree: True for ``<SubTree>`` nodes.
        children: child nodes (for a SubTree: the root of the subtree it expands to).
    """

    uid: int
    type_id: str
    name: str
    path: str
    line: int = 0
    attributes: dict[str, str] = field(default_factory=dict)
    is_subtree: bool = False
    children: list[OutlineNode] = field(default_factory=list)

    @property
    def label(self) -> str:
        """``name (TypeID)`` or just ``TypeID``."""
        if self.name and self.name != self.type_id:
            return f"{self.name} ({self.type_id})"
        return self.type_id

    def walk(self) -> Iterator[OutlineNode]:
        """This node and every descendant, pre-order."""
        stack = [self]
        while stack:
            node = stack.pop()
            yield node
            stack.extend(reversed(node.children))


@dataclass
class TreeOutline:
    """An objective's tree as an outline; ``exact_uids`` is False when a subtree could not be expanded."""

    tree_id: str
    root: OutlineNode | None
    exact_uids: bool = True
    missing_subtrees: list[str] = field(default_factory=list)
    _index: tuple[dict[int, OutlineNode], dict[str, OutlineNode]] | None = field(default=None, repr=False)

    def nodes(self) -> Iterator[OutlineNode]:
        """Every node, pre-order."""
        return self.root.walk() if self.root is not None else iter(())

    def find(self, uid: int, path: str) -> OutlineNode | None:
        """The node a status change names: by uid when the numbering is exact and the path agrees, else by
        path."""
        if self._index is None:
            by_uid = {node.uid: node for node in self.nodes()}
            by_path: dict[str, OutlineNode] = {}
            for node in self.nodes():
                by_path.setdefault(node.path, node)
            self._index = (by_uid, by_path)
        by_uid, by_path = self._index
        if self.exact_uids:
            numbered = by_uid.get(uid)
            if numbered is not None and (not path or numbered.path == path):
                return numbered
        return by_path.get(path) if path else None


def build_outline(
    xml_text: str,
    tree_id: str | None = None,
    *,
    filename: str = "<objective>",
    load_subtree: SubtreeLoader | None = None,
) -> TreeOutline:
    """Read the outline of ``tree_id`` (default: the document's main tree) from a BT.CPP v4 document.

    Args:
        xml_text: the document.
        tree_id: the ``<BehaviorTree ID>`` to outline.
        filename: for error messages.
        load_subtree: returns the XML document that defines a subtree ID this document does not, or
            None when it is unknown.

    Raises:
        ObjectiveError: the XML does not parse, or ``tree_id`` is not in it (with the IDs that are).
    """
    root = parse_xml(xml_text, filename)
    trees = _trees_of(root)
    if tree_id is None:
        tree_id = root.get("main_tree_to_execute") or (next(iter(trees)) if len(trees) == 1 else None)
        if tree_id is None:
            raise ObjectiveError(
                f"{filename} has {len(trees)} <BehaviorTree>s and no main_tree_to_execute; "
                f"name one of: {', '.join(trees) or 'none'}"
            )
    if tree_id not in trees:
        raise ObjectiveError(
            f"{filename} does not define the tree {tree_id!r}; {did_you_mean(tree_id, trees)}"
        )
    builder = _OutlineBuilder(trees, load_subtree)
    top = _first_child(trees[tree_id])
    outline = TreeOutline(tree_id=tree_id, root=None)
    if top is not None:
        outline.root = builder.node(top, prefix="", subtree_path="", depth=0)
    outline.exact_uids = not builder.missing
    outline.missing_subtrees = builder.missing
    return outline


def _trees_of(root: etree._Element) -> dict[str, etree._Element]:
    if root.tag == "BehaviorTree":
        return {root.get("ID") or "": root}
    return {element.get("ID") or "": element for element in root if element.tag == "BehaviorTree"}


def _first_child(element: etree._Element) -> etree._Element | None:
    return next((child for child in element if isinstance(child.tag, str)), None)


class _OutlineBuilder:
    def __init__(self, trees: dict[str, etree._Element], load_subtree: SubtreeLoader | None) -> None:
        self.trees = dict(trees)
        self.load_subtree = load_subtree
        self.uid = 0
        self.missing: list[str] = []

    def definition(self, subtree_id: str) -> etree._Element | None:
        if subtree_id not in self.trees and self.load_subtree is not None and subtree_id not in self.missing:
            text = self.load_subtree(subtree_id)
            if text:
                try:
                    for key, element in _trees_of(parse_xml(text, f"<subtree {subtree_id!r}>")).items():
                        self.trees.setdefault(key, element)
                except ObjectiveError:
                    pass  # shown as a missing subtree below; the objective itself still displays
        return self.trees.get(subtree_id)

    def node(self, element: etree._Element, prefix: str, subtree_path: str, depth: int) -> OutlineNode:
        tag = str(element.tag)
        type_id = element.get("ID", "") if tag in EXPLICIT_TAGS else tag
        name = element.get("name")
        self.uid += 1
        uid = self.uid
        instance = name if name is not None else type_id
        path = prefix + instance + (f"::{uid}" if instance == type_id else "")
        attributes = {str(k): str(v) for k, v in element.attrib.items() if k not in ("ID", "name")}
        node = OutlineNode(
            uid=uid,
            type_id=type_id,
            name=name or "",
            path=path,
            line=element.sourceline or 0,
            attributes=attributes,
            is_subtree=tag == "SubTree",
        )
        if node.is_subtree:
            inner_path = (subtree_path + "/" if subtree_path else "") + (
                name if name is not None else f"{type_id}::{uid}"
            )
            definition = self.definition(type_id) if depth < MAX_SUBTREE_DEPTH else None
            top = _first_child(definition) if definition is not None else None
            if top is None:
                if type_id not in self.missing:
                    self.missing.append(type_id)
            else:
                node.children.append(self.node(top, inner_path + "/", inner_path, depth + 1))
            return node
        for child in element:
            if isinstance(child.tag, str):
                node.children.append(self.node(child, prefix, subtree_path, depth))
        return node
