"""Loading BT.CPP v4 XML documents into a library of tree definitions (BT.CPP's ``XMLParser``).

A factory owns one :class:`TreeLibrary`; it is cumulative, so trees loaded earlier stay visible to
``<SubTree ID=...>`` in later documents. Loading a document processes its ``<include>``s first, then
verifies the whole document (unknown nodes, child counts, IDs), then reads the ``<SubTree>`` port
models of ``<TreeNodesModel>``, then registers each ``<BehaviorTree>``.
"""

from __future__ import annotations

import os
from collections import deque
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from lxml import etree

from kinema.bt.errors import BTRuntimeError
from kinema.bt.manifest import NodeType
from kinema.bt.names import model_name_problem, port_name_problem
from kinema.bt.ports import NO_DEFAULT, PortDirection, PortInfo
from kinema.bt.spellings import (
    FormerSpelling,
    SpellingNote,
    apply_objective_parameters,
    rewrite_former_spellings,
)
from kinema.bt.xmlsource import MAX_DEPTH, parse_xml, parse_xml_file
from kinema.errors import SourceLocation

if TYPE_CHECKING:
    from kinema.bt.manifest import NodeManifest

# A tree's nodes in document order as three columns: signature (tag, then the (name, value) pairs of
# its attributes), line, and the index of its parent node (-1 for the root node). See TreeDefinition.
Skeleton = tuple[list[tuple[Any, ...]], list[int], list[int]]

# How many documents loaded from text a library keeps for loading them again (see TreeLibrary.load_text).
_MAX_CACHED_DOCUMENTS = 32
# How many notes of nodes read in a former spelling a library keeps (a runtime loads documents for days).
_MAX_SPELLING_NOTES = 1000

EXPLICIT_TAGS = frozenset({"Action", "Condition", "Control", "Decorator", "SubTree"})
# Tags whose structural check reads more than the tag and the number of children: the ID, or (for a
# ReactiveSequence) the children's tags.
_CHECKED_BY_MORE = EXPLICIT_TAGS | {"ReactiveSequence"}
_PORT_TAGS = {
    "input_port": PortDirection.INPUT,
    "output_port": PortDirection.OUTPUT,
    "inout_port": PortDirection.INOUT,
}


def element_children(element: etree._Element) -> list[etree._Element]:
    """Child elements only (comments and processing instructions skipped)."""
    # A comment's or processing instruction's tag is a function, an element's a str; this is about
    # twice as fast as iterchildren(etree.Element), and every build walks every element.
    return [child for child in element if child.tag.__class__ is str] if len(element) else []


def read_skeleton(tree_root: etree._Element) -> Skeleton:
    """The skeleton of a tree (see :data:`Skeleton`) read from its root node's element: elements only,
    and nothing below a ``<SubTree>`` (its children, which verification refuses, are ignored).

    Verification reads the same off the trees it walks in document order (find_structure_problems).
    """
    signatures: list[tuple[Any, ...]] = []
    lines: list[int] = []
    parents: list[int] = []
    # element -> its index, for the elements whose children are nodes
    index_of: dict[etree._Element, int] = {}
    for element in tree_root.iter(etree.Element):
        if signatures:
            parent_index = index_of.get(element.getparent(), -1)
            if parent_index < 0:
                continue  # below a <SubTree>
        else:
            parent_index = -1
        tag = element.tag
        if tag != "SubTree":
            index_of[element] = len(signatures)
        parents.append(parent_index)
        signatures.append((tag, *element.items()))
        lines.append(element.sourceline or 0)
    return signatures, lines, parents


def line_of(element: etree._Element) -> int:
    """The 1-based source line of an element (0 if unknown)."""
    return element.sourceline or 0


class TreeDefinition:
    """A ``<BehaviorTree>`` as loaded: its ID, element and file.

    ``attributes`` keeps everything written on the element (``_description``, ``_favorite`` ...), so
    an objective can be written back unchanged in meaning.
    """

    __slots__ = ("element", "filename", "id", "plan", "plan_key", "skeleton")

    def __init__(self, tree_id: str, element: etree._Element, filename: str) -> None:
        self.id = tree_id
        self.element = element
        self.filename = filename
        # The builder's compiled plan (kinema.bt.builder.Plan) and the registry it is valid for.
        self.plan: Any = None
        self.plan_key: Any = None
        # What verification read off the tree's nodes for the builder, when it walked them in
        # document order (see find_structure_problems): None, or the columns (signature, line,
        # parent index), a signature being the tag followed by the (name, value) attribute pairs.
        self.skeleton: Skeleton | None = None

    @property
    def attributes(self) -> dict[str, str]:
        """Attributes of the ``<BehaviorTree>`` element (metadata included)."""
        return dict(self.element.attrib)

    @property
    def root_element(self) -> etree._Element | None:
        """The single child element (the tree's root node)."""
        children = element_children(self.element)
        return children[0] if children else None

    @property
    def location(self) -> SourceLocation:
        """``file:line`` of the ``<BehaviorTree>`` element."""
        return SourceLocation(self.filename, line_of(self.element))

    def to_xml(self) -> str:
        """The ``<BehaviorTree>`` element as XML text."""
        return etree.tostring(self.element, encoding="unicode")


class SubtreeModel:
    """``<TreeNodesModel><SubTree ID>``: ports with defaults, description and metadata."""

    __slots__ = ("description", "id", "metadata", "ports")

    def __init__(self, subtree_id: str) -> None:
        self.id = subtree_id
        self.ports: dict[str, PortInfo] = {}
        self.description = ""
        self.metadata: list[tuple[str, str]] = []


def read_metadata(model: etree._Element) -> list[tuple[str, str]]:
    """``(key, value)`` pairs of every ``<MetadataFields><Metadata k="v"/>`` under ``model``."""
    pairs: list[tuple[str, str]] = []
    for fields in model.iter("MetadataFields"):
        for item in fields.iter("Metadata"):
            pairs.extend((str(k), str(v)) for k, v in item.attrib.items())
    return pairs


def located_error(message: str, filename: str, line: int) -> BTRuntimeError:
    """A BT RuntimeError that carries ``file:line``."""
    return BTRuntimeError(message, location=SourceLocation(filename, line))


class TreeLibrary:
    """The trees and SubTree models loaded into one factory (cumulative)."""

    def __init__(self) -> None:
        self.trees: dict[str, TreeDefinition] = {}
        self.subtree_models: dict[str, SubtreeModel] = {}
        self.node_models: dict[str, etree._Element] = {}
        self.current_path = Path.cwd()
        self.first_main_tree: str | None = None
        self.documents_loaded = 0
        self._suffix = 0
        # Former spellings of node types (the factory's, shared): nodes written so are rewritten to
        # today's spelling as each document loads, each leaving a note (kinema.bt.spellings).
        self.spellings: Mapping[str, list[FormerSpelling]] = {}
        self.spelling_notes: deque[SpellingNote] = deque(maxlen=_MAX_SPELLING_NOTES)
        # What a validating load (verify=False) found and went on past: a parameter file that does not load.
        self.load_problems: list[BTRuntimeError] = []
        # Documents loaded from text, by (text, filename, verify, registry), oldest first: loading the
        # same objective again (a hot reload of an unchanged file, /do_objective with the same XML)
        # skips parsing, verifying and compiling it. The cache is the library's own and goes with its
        # factory: a registry key names one factory, so no other library could use an entry, and
        # entries kept past their factory only grew the collector's oldest generation.
        self._documents: dict[tuple[object, ...], tuple[etree._Element, list[TreeDefinition]]] = {}

    def clear(self) -> None:
        """Forget every tree (the factory's ``clear_registered_behavior_trees``)."""
        self.trees.clear()
        self.subtree_models.clear()
        self.node_models.clear()
        self.current_path = Path.cwd()
        self.first_main_tree = None
        self.documents_loaded = 0
        self._suffix = 0

    # -- loading ---------------------------------------------------------------------------------

    def load_text(
        self,
        text: str,
        filename: str,
        manifests: dict[str, NodeManifest],
        *,
        verify: bool = True,
        registry: object = None,
    ) -> etree._Element:
        """Load XML text; relative includes resolve against the library's current path.

        ``verify=False`` skips BT.CPP's structural checks (the validator reports them itself).
        ``registry`` identifies the node types ``manifests`` holds (the factory's ``plan_key()``):
        with it, loading the same text again for the same registry reuses the parsed, verified
        document and its trees' compiled plans (a document with ``<include>`` is always re-read).
        """
        key = (text, filename, verify, registry) if registry is not None else None
        documents = self._documents
        cached = documents.get(key) if key is not None else None
        if cached is not None:
            root, definitions = cached
            self._read_models(root, filename)
            if self.documents_loaded == 0 and self.first_main_tree is None:
                self.first_main_tree = root.get("main_tree_to_execute")
            self.documents_loaded += 1
            for definition in definitions:
                self.trees[definition.id] = definition
            return root
        root = parse_xml(text, filename)
        self._load_document(root, filename, manifests, include_stack=[], verify=verify)
        if key is not None and root.find("include") is None:
            ids = [element.get("ID") for element in root.findall("BehaviorTree")]
            if all(ids):
                if len(documents) >= _MAX_CACHED_DOCUMENTS:
                    del documents[next(iter(documents))]
                documents[key] = (root, [self.trees[tree_id] for tree_id in ids if tree_id is not None])
        return root

    def load_file(
        self, path: str | Path, manifests: dict[str, NodeManifest], *, verify: bool = True
    ) -> etree._Element:
        """Load an XML file; its directory becomes the current path (as BT.CPP does)."""
        path = Path(path)
        root = parse_xml_file(path)
        self.current_path = path.resolve().parent
        self._load_document(root, str(path), manifests, include_stack=[str(path.resolve())], verify=verify)
        return root

    def _load_document(
        self,
        root: etree._Element,
        filename: str,
        manifests: dict[str, NodeManifest],
        include_stack: list[str],
        verify: bool = True,
    ) -> None:
        if root.tag != "root":
            raise located_error("The XML must have a root node called <root>", filename, line_of(root))
        for include in root.findall("include"):
            self._load_include(include, filename, manifests, include_stack, verify)
        # A validator (verify=False) hears of a parameter file that does not load among the file's other
        # problems; a load for a run stops at it.
        parameter_problems = None if verify else self.load_problems
        self.spelling_notes.extend(
            apply_objective_parameters(root, filename, manifests, self.spellings, parameter_problems)
        )
        if self.spellings:
            self.spelling_notes.extend(rewrite_former_spellings(root, filename, self.spellings, manifests))
        skeletons: dict[etree._Element, Skeleton] | None = {} if verify else None
        if verify:
            verify_document(root, filename, manifests, skeletons)
        self._read_models(root, filename)
        if self.documents_loaded == 0 and self.first_main_tree is None:
            self.first_main_tree = root.get("main_tree_to_execute")
        self.documents_loaded += 1
        for element in root.findall("BehaviorTree"):
            tree_id = element.get("ID")
            if tree_id is None:
                tree_id = f"BehaviorTree_{self._suffix}"
                self._suffix += 1
            definition = self.trees[tree_id] = TreeDefinition(tree_id, element, filename)
            if skeletons:
                definition.skeleton = skeletons.get(element)

    def _load_include(
        self,
        include: etree._Element,
        filename: str,
        manifests: dict[str, NodeManifest],
        include_stack: list[str],
        verify: bool = True,
    ) -> None:
        path_attr = include.get("path")
        if path_attr is None:
            raise located_error("Invalid <include> tag: missing 'path' attribute", filename, line_of(include))
        file_path = Path(path_attr)
        if include.get("ros_pkg") is not None and not file_path.is_absolute():
            raise located_error(
                "Using attribute [ros_pkg] in <include>, but Kinema has no ROS package index; "
                "use a path relative to the including file instead",
                filename,
                line_of(include),
            )
        if not file_path.is_absolute():
            file_path = self.current_path / file_path
        resolved = str(file_path.resolve())
        if resolved in include_stack:
            chain = " -> ".join([*include_stack, resolved])
            raise located_error(f"<include> cycle: {chain}", filename, line_of(include))
        if len(include_stack) > 64:
            raise located_error("<include> nests deeper than 64 files", filename, line_of(include))
        if not file_path.is_file():
            raise located_error(
                f'<include path="{path_attr}">: no such file {file_path}', filename, line_of(include)
            )
        previous = self.current_path
        self.current_path = file_path.resolve().parent
        try:
            child_root = parse_xml_file(file_path)
            self._load_document(child_root, str(file_path), manifests, [*include_stack, resolved], verify)
        finally:
            self.current_path = previous

    def _read_models(self, root: etree._Element, filename: str) -> None:
        for models in root.findall("TreeNodesModel"):
            for model in element_children(models):
                model_id = model.get("ID")
                if model.tag != "SubTree":
                    if model_id:
                        self.node_models[model_id] = model
                    continue
                if model_id is None:
                    raise located_error(
                        "Missing attribute 'ID' in SubTree element within TreeNodesModel",
                        filename,
                        line_of(model),
                    )
                subtree_model = self.subtree_models.setdefault(model_id, SubtreeModel(model_id))
                subtree_model.description = model.get("description", subtree_model.description)
                subtree_model.metadata = read_metadata(model) or subtree_model.metadata
                for port_element in element_children(model):
                    direction = _PORT_TAGS.get(str(port_element.tag))
                    if direction is None:
                        continue
                    name = port_element.get("name")
                    if name is None:
                        raise located_error(
                            "Missing attribute [name] in port (SubTree model)",
                            filename,
                            line_of(port_element),
                        )
                    problem = port_name_problem(name)
                    if problem is not None:
                        raise located_error(
                            f"Error at line {line_of(port_element)}: {problem}",
                            filename,
                            line_of(port_element),
                        )
                    default = port_element.get("default")
                    subtree_model.ports[name] = PortInfo(
                        name,
                        direction,
                        None,
                        NO_DEFAULT if default is None else default,
                        port_element.get("description", "") or (port_element.text or "").strip(),
                    )

    # -- main tree -------------------------------------------------------------------------------

    def main_tree_of(self, root: etree._Element, before: set[str]) -> str:
        """The tree ``createTreeFromText`` instantiates for document ``root`` (BT.CPP's rules)."""
        main = root.get("main_tree_to_execute")
        if main:
            return main
        with_id = [e.get("ID") for e in root.findall("BehaviorTree") if e.get("ID")]
        if len(with_id) == 1 and len(root.findall("BehaviorTree")) == 1:
            return with_id[0]
        new = [tree_id for tree_id in self.trees if tree_id not in before]
        if len(new) == 1:
            return new[0]
        if self.first_main_tree:
            return self.first_main_tree
        if len(self.trees) == 1:
            return next(iter(self.trees))
        raise BTRuntimeError("[main_tree_to_execute] was not specified correctly")


def verify_document(
    root: etree._Element,
    filename: str,
    manifests: dict[str, NodeManifest],
    skeletons: dict[etree._Element, Skeleton] | None = None,
) -> None:
    """BT.CPP's ``VerifyXML``: raise the first structural problem of a document.

    ``skeletons`` (optional) gets the skeleton of each ``<BehaviorTree>`` element verified in one
    walk of its nodes (see :class:`TreeDefinition`): the builder then compiles it without reading
    the XML again.
    """
    problems = find_structure_problems(root, filename, manifests, first_only=True, skeletons=skeletons)
    if problems:
        line, message = problems[0]
        raise located_error(f"Error at line {line}: -> {message}", filename, line)


def find_structure_problems(
    root: etree._Element,
    filename: str,
    manifests: dict[str, NodeManifest],
    *,
    first_only: bool = False,
    known_trees: set[str] | None = None,
    skeletons: dict[etree._Element, Skeleton] | None = None,
) -> list[tuple[int, str]]:
    """Structural problems of a document as ``(line, message)`` (VerifyXML's checks).

    With ``known_trees``, ``<SubTree ID>`` values that name no known tree are reported too. With
    ``skeletons``, the trees walked in document order get their skeleton there (meaningful only
    where no problem was found).
    """
    problems: list[tuple[int, str]] = []

    def report(line: int, message: str) -> bool:
        problems.append((line, message))
        return first_only

    fine: set[tuple[object, ...]] = set()
    # tag -> numbers of children found fine, for the tags whose check needs nothing else
    fine_counts: dict[str, set[int]] = {}
    models = root.findall("TreeNodesModel")
    if len(models) > 1 and report(line_of(models[1]), "Only a single node <TreeNodesModel> is supported"):
        return problems
    top_level = element_children(root)
    # No node of any tree deeper than MAX_DEPTH (libxml2 answers for the whole document at once).
    shallow = not _TOO_DEEP(root)
    tree_elements = root.findall("BehaviorTree")
    for element in tree_elements:
        tree_id = element.get("ID") or ""
        line = line_of(element)
        if (
            not tree_id
            and len(top_level) > 1
            and report(line, "The tag <BehaviorTree> must have the attribute [ID]")
        ):
            return problems
        if tree_id:
            problem = model_name_problem(tree_id, tree_id=True)
            if problem and report(line, problem):
                return problems
        if tree_id in manifests and report(
            line, "The attribute [ID] of tag <BehaviorTree> must not use the name of a registered Node"
        ):
            return problems
        if len(element_children(element)) != 1 and report(
            line, f"The tag <BehaviorTree> with ID '{tree_id}' must have exactly 1 child"
        ):
            return problems
        if shallow and _plain(element):
            # Every node is an element and none is too deep: walk them in document order (the order
            # of the walk below) without listing each node's children.
            if skeletons is not None:
                signatures: list[tuple[Any, ...]] = []
                lines: list[int] = []
                parents: list[int] = []
                # node element -> its index, for the nodes that have children
                index_of: dict[etree._Element, int] = {}
                skeletons[element] = (signatures, lines, parents)
            for node in element.iterdescendants():
                tag = node.tag
                if skeletons is not None:
                    # The builder's reading of the node, taken on the way (one walk instead of two).
                    if len(node):
                        index_of[node] = len(signatures)
                    parents.append(index_of.get(node.getparent(), -1))  # -1: the tree's root node
                    signatures.append((tag, *node.items()))
                    lines.append(node.sourceline or 0)
                if tag not in _CHECKED_BY_MORE:
                    # Most nodes: only the tag and the number of children matter (not the ID).
                    count = len(node)
                    counts = fine_counts.get(tag)
                    if counts is not None and count in counts:
                        continue
                    found = len(problems)
                    if _verify_node(node, 1, manifests, report, known_trees, list(node)):
                        return problems
                    if len(problems) == found:
                        fine_counts.setdefault(tag, set()).add(count)
                    continue
                kind: tuple[Any, ...] = (tag, node.get("ID"), len(node))
                if tag == "ReactiveSequence":
                    kind += tuple([child.tag for child in node])
                if kind not in fine:
                    found = len(problems)
                    if _verify_node(node, 1, manifests, report, known_trees, list(node)):
                        return problems
                    if len(problems) == found:
                        fine.add(kind)
            continue
        stack = [(child, 1) for child in reversed(element_children(element))]
        while stack:
            node, depth = stack.pop()
            children = element_children(node)
            # Whether a node is fine depends only on its tag, ID and number of children (and its
            # depth, and for a ReactiveSequence its children's tags): check each such kind once.
            tag = node.tag
            kind = (tag, node.get("ID"), len(children))
            if tag == "ReactiveSequence":
                kind += tuple([child.tag for child in children])
            if depth > MAX_DEPTH or kind not in fine:
                found = len(problems)
                if _verify_node(node, depth, manifests, report, known_trees, children):
                    return problems
                if len(problems) == found:
                    fine.add(kind)
            if children:
                children.reverse()
                stack.extend([(child, depth + 1) for child in children])
    return problems


def _plain(tree: etree._Element) -> bool:
    """True if a ``<BehaviorTree>`` holds no comment or processing instruction (so its nodes' children
    are all elements)."""
    return not _NOT_PLAIN(tree)


_NOT_PLAIN = etree.XPath("boolean(.//comment() | .//processing-instruction())")
# A node at depth MAX_DEPTH + 1 in any tree of the document (a tree's root node is at depth 1).
_TOO_DEEP = etree.XPath("boolean(./*/*" + "/*" * MAX_DEPTH + ")")


def _verify_node(
    node: etree._Element,
    depth: int,
    manifests: dict[str, NodeManifest],
    report: Callable[[int, str], bool],
    known_trees: set[str] | None,
    children: list[etree._Element],
) -> bool:
    """Check one node element; return True to stop (first_only and a problem was found)."""
    line = line_of(node)
    if depth > MAX_DEPTH:
        return report(
            line, f"Maximum XML nesting depth exceeded (limit: {MAX_DEPTH}). The XML is too deeply nested."
        )
    name = str(node.tag)
    node_id = node.get("ID") or ""
    explicit = name in EXPLICIT_TAGS
    if explicit and not node_id:
        return report(line, f"The tag <{name}> must have the attribute [ID]")
    if name == "SubTree":
        if children and report(line, f"<SubTree> with ID '{node_id}' should not have any child"):
            return True
        problem = model_name_problem(node_id, tree_id=True)
        if problem and report(line, problem):
            return True
        if node_id in manifests and report(
            line, "The attribute [ID] of tag <SubTree> must not use the name of a registered Node"
        ):
            return True
        if known_trees is not None and node_id not in known_trees:
            return report(
                line,
                f"SubTree ID '{node_id}' is not a known BehaviorTree{unknown_hint(node_id, known_trees)} "
                "(give the file that defines it too, or <include> it)",
            )
        return False
    lookup = node_id if explicit else name
    if not explicit:
        problem = model_name_problem(name)
        if problem and report(line, problem):
            return True
    manifest = manifests.get(lookup)
    if manifest is None:
        return report(line, f"Node not recognized: {lookup}{unknown_hint(lookup, manifests)}")
    category = manifest.category
    count = len(children)
    if category is NodeType.DECORATOR and count != 1:
        return report(line, f"The node '{lookup}' must have exactly 1 child")
    if category is NodeType.CONTROL:
        if count == 0:
            return report(line, f"The node '{lookup}' must have 1 or more children")
        if lookup == "TryCatch" and count < 2:
            return report(line, "The node 'TryCatch' must have at least 2 children")
        if lookup == "ReactiveSequence":
            async_count = 0
            for child in children:
                child_manifest = manifests.get(str(child.tag))
                if child_manifest is None:
                    return report(line_of(child), f"Unknown node type: {child.tag}")
                if child_manifest.category is NodeType.CONTROL and child.tag == "AsyncSequence":
                    async_count += 1
                    if async_count > 1:
                        return report(line, "A ReactiveSequence cannot have more than one async child.")
    if category in (NodeType.ACTION, NodeType.CONDITION) and count != 0:
        return report(line, f"The node '{lookup}' must not have any child")
    return False


def unknown_hint(value: str, choices: object) -> str:
    """ "; did you mean 'X'?" when a registered name is close to ``value``, else ""."""
    import difflib

    close = difflib.get_close_matches(value, sorted(choices), n=3, cutoff=0.6)  # type: ignore[call-overload]
    if not close:
        return ""
    return "; did you mean " + " or ".join(repr(c) for c in close) + "?"


def relative_to_cwd(path: str) -> str:
    """``path`` relative to the working directory when it is below it (for messages)."""
    try:
        return os.path.relpath(path)
    except ValueError:
        return path
