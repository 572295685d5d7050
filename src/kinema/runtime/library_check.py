"""Which objectives of a library can load, and why the others cannot.

An objective loads when its file and the files of every SubTree it reaches (its SubTree closure, found
through the library's objective IDs) validate against the registered behaviors. The check reports the
first problem of each objective that does not, as ``file:line: message``, so ``kinema objective list``
can say in one line why an objective will not run.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from lxml import etree

if TYPE_CHECKING:
    from kinema.bt import BehaviorTreeFactory
    from kinema.config import ObjectiveLibrary


def _subtree_ids(path: Path) -> set[str]:
    try:
        root = etree.parse(str(path)).getroot()
    except (OSError, etree.XMLSyntaxError):
        return set()
    return {str(element.get("ID")) for element in root.iter("SubTree") if element.get("ID")}


def file_closure(library: ObjectiveLibrary, path: Path) -> list[Path]:
    """``path`` followed by the files of every objective its SubTrees reach, through the library (sorted)."""
    seen, todo = {path}, [path]
    while todo:
        for subtree in _subtree_ids(todo.pop()):
            info = library.objectives.get(subtree)
            if info is not None and info.file not in seen:
                seen.add(info.file)
                todo.append(info.file)
    return [path, *sorted(seen - {path})]


def subtree_closure(library: ObjectiveLibrary, objective_id: str) -> list[Path]:
    """The objective's file followed by the files of every objective its SubTrees reach (sorted)."""
    return file_closure(library, library.get(objective_id).file)


def file_problem(library: ObjectiveLibrary, path: Path, factory: BehaviorTreeFactory) -> str | None:
    """The first problem of ``path`` validated with its SubTree closure, or None when it would load."""
    from kinema.bt.validation import validate_files

    found = validate_files(list(file_closure(library, path)), factory)
    return str(found[0]) if found else None


def library_problems(library: ObjectiveLibrary, factory: BehaviorTreeFactory) -> dict[str, str]:
    """Objective ID -> the first problem that keeps it from loading (objectives that load are absent)."""
    from kinema.bt.validation import validate_files

    problems: dict[str, str] = {}
    checked: dict[tuple[Path, ...], str | None] = {}
    for info in library.sorted():
        closure = tuple(subtree_closure(library, info.id))
        if closure not in checked:
            found = validate_files(list(closure), factory)
            checked[closure] = str(found[0]) if found else None
        problem = checked[closure]
        if problem is not None:
            problems[info.id] = problem
    return problems
