"""Which objectives of a library can load, and why the others cannot.

An objective loads when its file and the files of every SubTree it reaches (its SubTree closure, found
through the library's objective IDs) validate against the registered behaviors. The check reports the
first problem of each objective that does not, as ``file:line: message``, so ``kinema objective list``
can say in one line why an objective will not run.

Loading every behavior of a config to check its library takes most of a ``kinema objective list``, so the
answer is kept (:class:`LibraryCheckCache`) under a fingerprint of everything it depends on: the content of
the library's objective files, the source files of the plugins the config activates and of Kinema itself
(path, nanosecond mtime and size of each), and the interpreter. Any change to one of them checks again.
Only a check in which every plugin loaded is kept, so a plugin that failed for a passing reason (its import
ran out of time on a busy machine) is tried again next time.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import os
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING

from lxml import etree

from kinema.bt.xmlparser import EXPLICIT_TAGS

if TYPE_CHECKING:
    from kinema.bt import BehaviorTreeFactory
    from kinema.config import ObjectiveLibrary
    from kinema.plugins.discovery import PluginSpec

# Bump when what the check reports, or how it is stored, changes in a way a source stamp would not show.
_CACHE_FORMAT = 1


def subtree_renames(factory: BehaviorTreeFactory) -> dict[str, str]:
    """Old node IDs that load as a SubTree today (MoveIt Pro's ``ExecuteMTCTask`` is the "Execute MTC
    Solution" objective): their objective belongs to a closure as a SubTree's does."""
    return {
        old: spelling.current_id
        for old, spellings in factory.former_spellings.items()
        for spelling in spellings
        if spelling.subtree and spelling.current_id
    }


def _subtree_ids(path: Path, renamed: Mapping[str, str]) -> set[str]:
    try:
        root = etree.parse(str(path)).getroot()
    except (OSError, etree.XMLSyntaxError):
        return set()
    found = {str(element.get("ID")) for element in root.iter("SubTree") if element.get("ID")}
    if renamed:
        for element in root.iter(etree.Element):
            spelled = element.get("ID") if element.tag in EXPLICIT_TAGS else element.tag
            if spelled in renamed:
                found.add(renamed[spelled])
    return found


def file_closure(
    library: ObjectiveLibrary, path: Path, renamed: Mapping[str, str] | None = None
) -> list[Path]:
    """``path`` followed by the files of every objective its SubTrees reach, through the library (sorted);
    ``renamed`` (:func:`subtree_renames`) adds the objectives old node IDs load as."""
    seen, todo = {path}, [path]
    while todo:
        for subtree in _subtree_ids(todo.pop(), renamed or {}):
            info = library.objectives.get(subtree)
            if info is not None and info.file not in seen:
                seen.add(info.file)
                todo.append(info.file)
    return [path, *sorted(seen - {path})]


def subtree_closure(
    library: ObjectiveLibrary, objective_id: str, renamed: Mapping[str, str] | None = None
) -> list[Path]:
    """The objective's file followed by the files of every objective its SubTrees reach (sorted)."""
    return file_closure(library, library.get(objective_id).file, renamed)


def file_problem(library: ObjectiveLibrary, path: Path, factory: BehaviorTreeFactory) -> str | None:
    """The first problem of ``path`` validated with its SubTree closure, and how many more there are (on
    its first line: a summary shows one line per file); None when it would load."""
    from kinema.bt.validation import validate_files

    found = validate_files(list(file_closure(library, path, subtree_renames(factory))), factory)
    if not found:
        return None
    first, _, rest = str(found[0]).partition("\n")
    if len(found) > 1:
        more = len(found) - 1
        first += f" (and {more} more problem{'s' if more > 1 else ''}: `kinema tree validate` lists them all)"
    return f"{first}\n{rest}" if rest else first


def library_problems(library: ObjectiveLibrary, factory: BehaviorTreeFactory) -> dict[str, str]:
    """Objective ID -> the first problem that keeps it from loading (objectives that load are absent)."""
    from kinema.bt.validation import validate_files

    problems: dict[str, str] = {}
    checked: dict[tuple[Path, ...], str | None] = {}
    renamed = subtree_renames(factory)
    for info in library.sorted():
        closure = tuple(subtree_closure(library, info.id, renamed))
        if closure not in checked:
            found = validate_files(list(closure), factory)
            checked[closure] = str(found[0]) if found else None
        problem = checked[closure]
        if problem is not None:
            problems[info.id] = problem
    return problems


def _stamp_tree(digest: hashlib._Hash, folder: Path, suffixes: tuple[str, ...]) -> None:
    """Feed path, nanosecond mtime and size of every file under ``folder`` ending in ``suffixes``."""
    if folder.is_file():
        stat = folder.stat()
        digest.update(f"{folder}:{stat.st_mtime_ns}:{stat.st_size}\n".encode())
        return
    for current, folders, files in os.walk(folder):
        folders[:] = sorted(name for name in folders if name != "__pycache__" and not name.startswith("."))
        for name in sorted(files):
            if name.endswith(suffixes):
                stat = os.stat(os.path.join(current, name))
                digest.update(f"{current}/{name}:{stat.st_mtime_ns}:{stat.st_size}\n".encode())


def _plugin_sources(spec: PluginSpec) -> list[Path]:
    """The folder (or file) holding a plugin's code: its package folder, or its entry point's top module."""
    if spec.root is not None:
        return [spec.root]
    found = importlib.util.find_spec(spec.module.split(".")[0])  # a top-level name: nothing is imported
    if found is None:
        return []
    if found.submodule_search_locations:
        return [Path(location) for location in found.submodule_search_locations]
    return [Path(found.origin)] if found.origin else []


def check_fingerprint(library: ObjectiveLibrary, specs: Iterable[PluginSpec]) -> str:
    """A digest of everything :func:`library_problems` depends on, for :class:`LibraryCheckCache`."""
    import kinema

    digest = hashlib.sha256(f"{_CACHE_FORMAT}\n{sys.version}\n{kinema.__version__}\n".encode())
    _stamp_tree(digest, Path(kinema.__file__).parent, (".py",))
    for spec in sorted(specs, key=lambda one: one.name):
        digest.update(f"{spec.name}|{spec.module}|{spec.package}|{spec.root}|{spec.attribute}\n".encode())
        for folder in _plugin_sources(spec):
            _stamp_tree(digest, folder, (".py", ".xml", ".yaml", ".toml"))
    # objective files by content: they are small, and an edit that keeps the size within one tick of the
    # file system's clock keeps the mtime too
    for info in library.sorted():
        digest.update(f"{info.id}|{info.file}|".encode() + hashlib.sha256(info.file.read_bytes()).digest())
    return digest.hexdigest()


class LibraryCheckCache:
    """The last check of one config's library, in the user's cache folder, under its fingerprint."""

    def __init__(self, config: str, workspace: Path | None) -> None:
        import platformdirs

        identity = hashlib.sha256(f"{config}|{workspace}".encode()).hexdigest()[:16]
        self.path = platformdirs.user_cache_path("kinema") / "objective-check" / f"{config}-{identity}.json"

    def get(self, fingerprint: str) -> dict[str, str] | None:
        """The problems stored under ``fingerprint``, else None (none, another fingerprint, damaged)."""
        try:
            stored = json.loads(self.path.read_text())
        except (OSError, ValueError):
            return None
        if not isinstance(stored, dict) or stored.get("fingerprint") != fingerprint:
            return None
        problems = stored.get("problems")
        if not isinstance(problems, dict) or not all(isinstance(v, str) for v in problems.values()):
            return None
        return {str(key): value for key, value in problems.items()}

    def put(self, fingerprint: str, problems: dict[str, str]) -> None:
        """Store ``problems`` under ``fingerprint`` (atomically; an unwritable cache is skipped)."""
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            partial = self.path.with_name(f"{self.path.name}.{os.getpid()}.tmp")
            partial.write_text(json.dumps({"fingerprint": fingerprint, "problems": problems}))
            os.replace(partial, self.path)
        except OSError:
            pass
