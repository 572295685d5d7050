"""Where the agent's trees come from: the behavior registry plus the objective library, kept current.

The factory is rebuilt lazily, on the tick thread, the first time an objective loads after the behavior
registry was swapped by a hot reload or the objective files changed, so a running objective keeps the
classes it was built with (DESIGN invariant 1 and §4).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinema.errors import KinemaError

if TYPE_CHECKING:
    from kinema.behaviors.context import BehaviorContext
    from kinema.bt import BehaviorTreeFactory, Clock, Tree
    from kinema.config import ObjectiveInfo, ObjectiveLibrary
    from kinema.plugins import BehaviorHost

log = logging.getLogger("kinema.objective_server")

# How long a run waits for the reload of files saved just before it (debounce plus import, usually well
# under a second); a package still importing after that is used as it was.
RELOAD_SETTLE_S = 3.0


@dataclass(frozen=True)
class LibraryProblem:
    """An objective file that could not be registered, and why."""

    file: str
    message: str


class LibraryTreeSource:
    """A :class:`~kinema.runtime.objective_server.TreeSource` over a behavior host and an objective library.

    Args:
        load_library: builds the current :class:`ObjectiveLibrary` (called again after objective files
            change).
        host: the behavior host (None: only the engine's built-in nodes).
        context: what behaviors reach the world through.
        clock: the runtime clock (sim time in simulation).
    """

    def __init__(
        self,
        load_library: Callable[[], ObjectiveLibrary],
        *,
        host: BehaviorHost | None,
        context: BehaviorContext | None,
        clock: Clock,
    ) -> None:
        self._load_library = load_library
        self._host = host
        self._context = context
        self._clock = clock
        self._lock = threading.Lock()
        self._factory: BehaviorTreeFactory | None = None
        self._registry: Any = None
        self._library: ObjectiveLibrary | None = None
        self._objectives_stale = True
        self._problems: dict[str, LibraryProblem] = {}
        self._loaded: list[str] = []
        # Each objective file's text and objectives when it last registered: a file that fails later is
        # registered from these (see _register).
        self._last_good: dict[Path, tuple[str, list[ObjectiveInfo]]] = {}
        # Set when a config file changed after the start (needs a restart); named in "unknown objective".
        self.restart_note = ""

    # -- TreeSource ---------------------------------------------------------------------------------

    def factory(self) -> BehaviorTreeFactory:
        """The factory for the next run (rebuilt when behaviors or objectives changed).

        Files saved a moment ago are reloaded first: a run started right after a save (`sed -i ...
        && kinema objective run ...`) uses the saved code, not the version before it.
        """
        settle = getattr(self._host, "settle_reloads", None)  # a host that watches files has it
        if settle is not None and not settle(RELOAD_SETTLE_S):
            log.warning(
                "a hot reload was still going on after %.0f s; this run uses the behaviors loaded before it",
                RELOAD_SETTLE_S,
            )
        with self._lock:
            registry = self._host.registry if self._host is not None else None
            if self._factory is None or self._objectives_stale or registry is not self._registry:
                self._rebuild(registry)
            assert self._factory is not None
            return self._factory

    def objective_names(self) -> list[str]:
        """Objectives that can run by name (the ones whose file registered)."""
        self.factory()
        return list(self._loaded)

    def load_error(self, objective_name: str) -> str | None:
        """Why ``objective_name`` (in the library) is not runnable, or None."""
        problem = self._problems.get(objective_name)
        return None if problem is None else f"{problem.file}: {problem.message}"

    def stale_note(self, tree: Tree) -> str:
        """What ``tree`` runs of a behavior package whose latest files failed to load ("" if nothing).

        A failed hot reload keeps the last good version, so the tree runs older code than the file on
        disk holds: the note names the package, the error with its file:line, and when the version that
        runs instead was loaded.
        """
        registry = self._registry
        if registry is None:
            return ""
        used = {node.registration_id for node in tree.nodes()}
        notes = []
        for record, behavior_ids in registry.stale_behaviors(used):
            error = record.error
            where = f"{error.location}: " if error.location is not None else ""
            loaded = time.strftime("%H:%M", time.localtime(record.loaded_at))
            # The error names the package ("plugin 'p': behavior package 'p' failed to import: ...").
            ids = ", ".join(behavior_ids)
            runs = "runs" if len(behavior_ids) == 1 else "run"
            notes.append(f"{where}{error.message}; {ids} {runs} the version from {loaded} instead")
        return "; ".join(notes)

    # -- library --------------------------------------------------------------------------------

    def invalidate_objectives(self) -> None:
        """Objective files changed: reload the library before the next run."""
        with self._lock:
            self._objectives_stale = True

    def objectives(self) -> list[ObjectiveInfo]:
        """The library's objectives with their metadata (sorted by ID)."""
        with self._lock:
            if self._library is None or self._objectives_stale:
                self._reload_library()
            assert self._library is not None
            return self._library.sorted()

    def _rebuild(self, registry: Any) -> None:
        from kinema.bt import BehaviorTreeFactory

        if self._library is None or self._objectives_stale:
            self._reload_library()
            self._objectives_stale = False
        assert self._library is not None
        for error in self._library.errors:
            log.warning("objective library: %s", error)
        for warning in self._library.warnings:
            log.warning("objective library: %s", warning)
        if registry is not None:
            factory = registry.create_factory(self._context, clock=self._clock)
        else:
            factory = BehaviorTreeFactory(clock=self._clock)
        problems: dict[str, LibraryProblem] = {}
        files = self._library.files()
        ids_by_file: dict[Path, list[str]] = {}
        for info in self._library.objectives.values():
            ids_by_file.setdefault(info.file, []).append(info.id)
        for path in files:
            failure = self._register(factory, path, ids_by_file.get(path, []))
            if failure is not None:
                log.warning("objective file %s not loaded: %s", path, failure)
                for objective_id in ids_by_file.get(path, []):
                    problems[objective_id] = LibraryProblem(str(path), str(failure))
        for note in factory.library.spelling_notes:
            log.warning("objective library: %s", note)
        from kinema.config.cell import substitute_config_defaults

        substitute_config_defaults(factory.library.subtree_models, getattr(self._library, "resolved", None))
        self._factory = factory
        self._registry = registry
        self._problems = problems
        registered = set(factory.registered_behavior_trees())
        self._loaded = sorted(i for i in self._library.objectives if i in registered and i not in problems)
        log.info("objective library: %d objectives runnable, %d not loaded", len(self._loaded), len(problems))

    def _reload_library(self) -> None:
        """Read the objective files again; a file that no longer reads keeps the objectives it had.

        Hot reload does not report a file saved broken; a rebuild for another reason (a behavior package
        reloaded, another file saved) must not drop that file's objectives either.
        """
        library = self._library = self._load_library()
        for path, (_text, infos) in self._last_good.items():
            if library.unreadable(path) and library.keep(path, infos):
                log.warning("objective file %s does not read; its last good version stays", path)

    def _register(self, factory: BehaviorTreeFactory, path: Path, ids: list[str]) -> KinemaError | None:
        """Register ``path``'s trees in ``factory``, or its last good version when it does not load now
        (the error is logged); the error when neither loads."""
        assert self._library is not None
        try:
            text = path.read_text(encoding="utf-8")
        except OSError:
            text = None
        try:
            factory.register_behavior_tree_from_file(path)
        except KinemaError as error:
            good = self._last_good.get(path)
            if good is None or good[0] == text:
                return error
            try:
                factory.library.current_path = path.resolve().parent  # its includes resolve from there
                factory.register_behavior_tree_from_text(good[0], str(path))
            except KinemaError:
                return error
            log.warning("objective file %s does not load (%s); its last good version runs", path, error)
            return None
        if text is not None:
            self._last_good[path] = (text, [self._library.objectives[i] for i in ids])
        return None


def library_from_folders(folders: list[Path]) -> ObjectiveLibrary:
    """An objective library made of plain folders (no config package), e.g. for tests."""
    from kinema.config import LibraryPath, ObjectiveLibrary

    paths = [LibraryPath(f"folder{index}", Path(f), "", "") for index, f in enumerate(folders)]
    return ObjectiveLibrary.from_libraries(paths, [])
