"""Checking objective files before they run: every problem as ``file:line: message``.

Unlike loading (which stops at the first error, as BT.CPP does), validation reports every problem
it can find: unknown node IDs (with the closest registered names), structure (child counts, IDs),
ports that the node type does not declare, literals that cannot be converted, scripts that do not
parse, SubTree IDs and a ``main_tree_to_execute`` that name no tree, mandatory SubTree model ports
that are not given. Files whose structure is sound are then built, which also catches type conflicts
and recursive subtrees.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from lxml import etree

from kinema.bt.conversions import convert_from_string, type_name
from kinema.bt.errors import BTError
from kinema.bt.names import POST_CONDITIONS, PRE_CONDITIONS, is_allowed_port_name
from kinema.bt.ports import strict_blackboard_pointer
from kinema.bt.script import validate_script
from kinema.bt.xmlparser import EXPLICIT_TAGS, element_children, find_structure_problems, line_of
from kinema.bt.xmlsource import parse_xml_file
from kinema.errors import KinemaError, SourceLocation, did_you_mean

if TYPE_CHECKING:
    from kinema.bt.factory import BehaviorTreeFactory

_SCRIPT_PORTS = {"Script": "code", "ScriptCondition": "code", "Precondition": "if"}


@dataclass(frozen=True)
class Problem:
    """One problem found in an objective file."""

    location: SourceLocation
    message: str

    def __str__(self) -> str:
        return f"{self.location}: {self.message}"


def validate_files(
    paths: list[str | Path],
    factory: BehaviorTreeFactory | None = None,
    *,
    warnings: list[Problem] | None = None,
) -> list[Problem]:
    """Validate objective files together (a SubTree may refer to a tree in another of the files).

    ``factory`` supplies the registered node types (default: the built-in nodes only); its
    already-loaded trees count as known SubTree IDs. The factory itself is not modified. Nodes written
    in a former spelling (kinema.bt.spellings) are validated as today's; each is added to ``warnings``
    when given.
    """
    from kinema.bt.factory import BehaviorTreeFactory

    base = factory if factory is not None else BehaviorTreeFactory()
    problems: list[Problem] = []
    documents: list[tuple[str, etree._Element]] = []
    scratch = _scratch_factory(base)
    notes = scratch.library.spelling_notes
    for path in paths:
        filename = str(path)
        try:
            # The library's reading of the file, former spellings rewritten, is what is checked.
            root = scratch.library.load_file(path, scratch.manifests(), verify=False)
        except KinemaError as error:
            location = error.location or SourceLocation(filename)
            problems.append(Problem(location, error.message))
            continue
        documents.append((filename, root))
    loaded_past = scratch.library.load_problems
    problems += [Problem(error.location or SourceLocation(""), error.message) for error in loaded_past]
    if warnings is not None:
        warnings.extend(Problem(note.location, note.message) for note in notes)
    manifests = scratch.manifests()
    known_trees = set(scratch.library.trees)
    for filename, root in documents:
        problems += _main_tree_problems(root, filename, known_trees)
        problems += [
            Problem(SourceLocation(filename, line), message)
            for line, message in find_structure_problems(root, filename, manifests, known_trees=known_trees)
        ]
        problems += _node_problems(root, filename, scratch)
    if not problems:
        # Building catches what only shows across trees (type conflicts, recursion, duplicate
        # paths); it is only meaningful once every file is structurally sound.
        for filename, root in documents:
            problems += _build_problems(root, filename, scratch)
    return problems


def _main_tree_problems(root: etree._Element, filename: str, known_trees: set[str]) -> list[Problem]:
    """``main_tree_to_execute`` must name a tree of these files (BT.CPP's createTree fails otherwise)."""
    main = root.get("main_tree_to_execute")
    if main is None or main in known_trees:
        return []
    return [
        Problem(
            SourceLocation(filename, line_of(root)),
            f"main_tree_to_execute={main!r} names no tree; {did_you_mean(main, sorted(known_trees))}",
        )
    ]


def _scratch_factory(base: BehaviorTreeFactory) -> BehaviorTreeFactory:
    from kinema.bt.factory import BehaviorTreeFactory

    scratch = BehaviorTreeFactory(base.clock, register_builtins=False)
    scratch._builders = dict(base._builders)
    scratch._manifests = dict(base._manifests)
    scratch.enums = dict(base.enums)
    scratch.former_spellings.update(base.former_spellings)
    scratch.library.trees = dict(base.library.trees)
    scratch.library.subtree_models = dict(base.library.subtree_models)
    return scratch


def _node_problems(root: etree._Element, filename: str, factory: BehaviorTreeFactory) -> list[Problem]:
    problems: list[Problem] = []
    manifests = factory.manifests()
    models = factory.library.subtree_models
    for tree in root.findall("BehaviorTree"):
        for element in tree.iter():
            if not isinstance(element.tag, str) or element is tree:
                continue
            tag = str(element.tag)
            line = line_of(element)
            where = SourceLocation(filename, line)
            for key in (*PRE_CONDITIONS, *POST_CONDITIONS):
                code = element.get(key)
                if code is not None:
                    error = validate_script(code)
                    if error is not None:
                        problems.append(Problem(where, f'script in {key}="{code}" does not parse: {error}'))
            node_id = element.get("ID") if tag in EXPLICIT_TAGS else tag
            if tag == "SubTree":
                problems += _subtree_call_problems(element, node_id or "", models, where)
                continue
            manifest = manifests.get(node_id or "")
            if manifest is None:
                continue
            for attr, value in element.attrib.items():
                attr = str(attr)
                if not is_allowed_port_name(attr):
                    continue
                port = manifest.ports.get(attr)
                if port is None:
                    problems.append(
                        Problem(
                            where,
                            f"port [{attr}] is not a port of {node_id}; {did_you_mean(attr, manifest.ports)}",
                        )
                    )
                    continue
                if not strict_blackboard_pointer(value) and port.has_converter and port.strongly_typed:
                    try:
                        convert_from_string(port.type, value, factory.enums)
                    except BTError as error:
                        problems.append(
                            Problem(
                                where,
                                f'port [{attr}] of {node_id}: "{value}" can not be converted to '
                                f"{type_name(port.type)} ({error.message})",
                            )
                        )
            script_port = _SCRIPT_PORTS.get(node_id or "")
            code = element.get(script_port) if script_port else None
            if code and not strict_blackboard_pointer(code.strip()):
                parse_error = validate_script(code)
                if parse_error is not None:
                    problems.append(
                        Problem(where, f'{node_id} {script_port}="{code}" does not parse: {parse_error}')
                    )
    return problems


def _subtree_call_problems(
    element: etree._Element, subtree_id: str, models: dict, where: SourceLocation
) -> list[Problem]:
    model = models.get(subtree_id)
    if model is None:
        return []
    autoremap = element.get("_autoremap", "false").strip() in ("true", "1", "True", "TRUE")
    problems = []
    for port_name, port in model.ports.items():
        if element.get(port_name) is None and not autoremap and not port.default_str:
            problems.append(
                Problem(
                    where,
                    f"SubTree '{subtree_id}' has a mandatory port [{port_name}] (no default in its "
                    "<TreeNodesModel>), but this call does not set it",
                )
            )
    return problems


def _build_problems(root: etree._Element, filename: str, factory: BehaviorTreeFactory) -> list[Problem]:
    problems: list[Problem] = []
    for tree in root.findall("BehaviorTree"):
        tree_id = tree.get("ID")
        if not tree_id or tree_id not in factory.library.trees:
            continue
        try:
            factory.create_tree(tree_id)
        except KinemaError as error:
            location = error.location or SourceLocation(filename, line_of(tree))
            problems.append(Problem(location, f"building tree '{tree_id}': {error.message}"))
    return problems


def count_trees(path: str | Path) -> int:
    """Number of ``<BehaviorTree>`` elements in a file (0 if it does not parse)."""
    try:
        return len(parse_xml_file(path).findall("BehaviorTree"))
    except KinemaError:
        return 0


__all__ = ["Problem", "count_trees", "element_children", "validate_files"]
