"""What one objective XML file declares: its objectives, their metadata and their ports.

MoveIt Pro's conventions (one ``<BehaviorTree>`` per file, named by ``main_tree_to_execute``):

* ``_description`` and ``_favorite`` are attributes of ``<BehaviorTree>``; a ``<Metadata description=...>``
  in the model is used when the attribute is missing.
* ``<TreeNodesModel><SubTree ID=...>`` declares the objective's ports (``input_port``, ``output_port``,
  ``inout_port`` with ``name``, ``default`` and a description as attribute or text) and its
  ``<MetadataFields><Metadata runnable=... subcategory=.../>``.
* An objective is runnable unless ``<Metadata runnable="false">`` says otherwise, or, for files written
  before that existed, ``_subtreeOnly="true"`` on the ``<BehaviorTree>``.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from kinema.bt.xmlsource import parse_xml
from kinema.config.yamlsource import read_text_file
from kinema.errors import ObjectiveError, SourceLocation

#: An objective file is a few kB; one this large is not an objective.
MAX_OBJECTIVE_BYTES = 8 * 1024 * 1024
_PORT_TAGS = {"input_port": "input", "output_port": "output", "inout_port": "inout"}
_TRUE = frozenset({"true", "1", "yes", "on"})
_FALSE = frozenset({"false", "0", "no", "off"})


@dataclass(frozen=True)
class ObjectivePort:
    """A port an objective (used as a subtree) declares in its TreeNodesModel.

    Attributes:
        name: the port name.
        direction: ``"input"``, ``"output"`` or ``"inout"``.
        default: the default value as written (``{key}`` for a blackboard default), or None.
        description: the port's description, "" when none.
        type_name: the value type when known (from the behavior port that reads it), "" otherwise.
    """

    name: str
    direction: str
    default: str | None = None
    description: str = ""
    type_name: str = ""


@dataclass
class ObjectiveInfo:
    """One objective of a library.

    Attributes:
        id: the ``<BehaviorTree ID>`` (the objective's name).
        file: the XML file that defines it.
        line: the line of its ``<BehaviorTree>`` element.
        description: ``_description`` (or ``Metadata description``), "" when none.
        favorite: ``_favorite="true"``.
        runnable: False for subtree-only objectives.
        subcategory: ``Metadata subcategory``, or None.
        ports: the declared subtree ports, in file order.
        metadata: every ``Metadata`` attribute of its model (first value wins).
        package: the package whose library holds the file ("" until a library assigns it).
        shadows: files of objectives with the same ID that this one hides (less-derived packages).
    """

    id: str
    file: Path
    line: int
    description: str = ""
    favorite: bool = False
    runnable: bool = True
    subcategory: str | None = None
    ports: list[ObjectivePort] = field(default_factory=list)
    metadata: dict[str, str] = field(default_factory=dict)
    package: str = ""
    shadows: list[Path] = field(default_factory=list)

    @property
    def location(self) -> SourceLocation:
        """``file:line`` of the objective's ``<BehaviorTree>``."""
        return SourceLocation(str(self.file), self.line)

    def read_xml(self) -> str:
        """The text of the file that defines the objective."""
        return read_text_file(self.file, max_bytes=MAX_OBJECTIVE_BYTES, error=ObjectiveError)

    def to_json(self) -> dict[str, object]:
        """A JSON-ready summary (what ``kinema objective list --json`` prints per objective)."""
        return {
            "id": self.id,
            "file": str(self.file),
            "line": self.line,
            "package": self.package,
            "description": self.description,
            "favorite": self.favorite,
            "runnable": self.runnable,
            "subcategory": self.subcategory,
            "ports": [
                {
                    "name": p.name,
                    "direction": p.direction,
                    "type": p.type_name,
                    "default": p.default,
                    "description": p.description,
                }
                for p in self.ports
            ],
            "metadata": self.metadata,
            "shadows": [str(path) for path in self.shadows],
        }


@dataclass
class ParsedObjectiveFile:
    """The objectives of one file and the soft problems found in it (``file:line: message``)."""

    objectives: list[ObjectiveInfo]
    warnings: list[str]


def parse_objective_file(path: Path) -> ParsedObjectiveFile:
    """Read one objective XML file.

    Raises:
        ObjectiveError: the file cannot be read or parsed, or declares no usable objective; the message
            carries ``file:line``.
    """
    text = read_text_file(path, max_bytes=MAX_OBJECTIVE_BYTES, error=ObjectiveError)
    root = parse_xml(text, str(path))
    return objectives_of(root, path, text)


def objectives_of(root: etree._Element, path: Path, text: str | None = None) -> ParsedObjectiveFile:
    """Extract the objectives of an already parsed objective document (see :func:`parse_objective_file`).

    ``text`` (the document's source) lets each objective's line be the line its ``<BehaviorTree`` tag
    starts on; libxml2 reports the line where a multi-line start tag ends.
    """
    opener_lines = _lines_of("<BehaviorTree", text) if text is not None else None
    filename = str(path)
    if root.tag != "root":
        raise ObjectiveError(
            f'the top element is <{root.tag}>, an objective file starts with <root BTCPP_format="4">',
            location=SourceLocation(filename, root.sourceline or 0),
        )
    trees = [element for element in root if element.tag == "BehaviorTree"]
    if not trees:
        raise ObjectiveError(
            "the file has no <BehaviorTree>", location=SourceLocation(filename, root.sourceline or 0)
        )
    models = _subtree_models(root)
    objectives: list[ObjectiveInfo] = []
    warnings: list[str] = []
    seen: dict[str, int] = {}
    for tree in trees:
        line = _tag_start_line(opener_lines, tree.sourceline or 0)
        tree_id = tree.get("ID")
        if not tree_id:
            raise ObjectiveError(
                "a <BehaviorTree> has no ID (the objective's name)", location=SourceLocation(filename, line)
            )
        if tree_id in seen:
            raise ObjectiveError(
                f"the objective {tree_id!r} is defined twice in this file (first on line {seen[tree_id]})",
                location=SourceLocation(filename, line),
            )
        seen[tree_id] = line
        objectives.append(_objective(tree, tree_id, models.get(tree_id), path, line, warnings))
    main = root.get("main_tree_to_execute")
    if main is not None and main not in seen:
        warnings.append(
            f"{filename}:{root.sourceline or 0}: main_tree_to_execute={main!r} "
            "names no <BehaviorTree> of this file "
            f"(it defines {', '.join(repr(i) for i in seen)})"
        )
    return ParsedObjectiveFile(objectives, warnings)


def _lines_of(opener: str, text: str) -> list[int]:
    """The lines (1-based, ascending) on which ``opener`` occurs in ``text``."""
    if "\r" in text:
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    lines: list[int] = []
    line, previous = 1, 0
    for match in re.finditer(re.escape(opener), text):
        line += text.count("\n", previous, match.start())
        previous = match.start()
        lines.append(line)
    return lines


def _tag_start_line(opener_lines: list[int] | None, reported: int) -> int:
    """The line of the nearest tag opener at or before the line libxml2 reported (the end of the tag)."""
    if not opener_lines or reported <= 0:
        return reported
    index = bisect.bisect_right(opener_lines, reported) - 1
    return opener_lines[index] if index >= 0 else reported


def _subtree_models(root: etree._Element) -> dict[str, etree._Element]:
    models: dict[str, etree._Element] = {}
    for model in root.iter("TreeNodesModel"):
        for subtree in model:
            if subtree.tag == "SubTree" and subtree.get("ID") and subtree.get("ID") not in models:
                models[subtree.get("ID")] = subtree
    return models


def _objective(
    tree: etree._Element,
    tree_id: str,
    model: etree._Element | None,
    path: Path,
    line: int,
    warnings: list[str],
) -> ObjectiveInfo:
    metadata: dict[str, str] = {}
    ports: list[ObjectivePort] = []
    if model is not None:
        for child in model:
            if child.tag == "MetadataFields":
                for item in child:
                    if item.tag == "Metadata":
                        for key, value in item.attrib.items():
                            metadata.setdefault(key, value)
            elif child.tag in _PORT_TAGS:
                name = child.get("name")
                if not name:
                    warnings.append(
                        f"{path}:{child.sourceline or 0}: a port of {tree_id!r} has no name; ignored"
                    )
                    continue
                text = (child.text or "").strip()
                ports.append(
                    ObjectivePort(
                        name, _PORT_TAGS[child.tag], child.get("default"), child.get("description") or text
                    )
                )
    runnable = True
    if "runnable" in metadata:
        runnable = _flag(metadata["runnable"], True, f"{path}:{line}", "runnable", warnings)
    elif tree.get("_subtreeOnly") is not None:
        runnable = not _flag(tree.get("_subtreeOnly", ""), False, f"{path}:{line}", "_subtreeOnly", warnings)
    return ObjectiveInfo(
        id=tree_id,
        file=path,
        line=line,
        description=tree.get("_description") or metadata.get("description", ""),
        favorite=_flag(tree.get("_favorite", "false"), False, f"{path}:{line}", "_favorite", warnings),
        runnable=runnable,
        subcategory=metadata.get("subcategory"),
        ports=ports,
        metadata=metadata,
    )


def _flag(value: str, default: bool, where: str, name: str, warnings: list[str]) -> bool:
    lowered = value.strip().lower()
    if lowered in _TRUE:
        return True
    if lowered in _FALSE:
        return False
    warnings.append(f"{where}: {name}={value!r} is not true or false; using {str(default).lower()}")
    return default
