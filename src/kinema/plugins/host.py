"""The live side of plugins: load the active loaders, hold the current registry, hot-reload it.

:class:`BehaviorHost` is what the runtime keeps for its lifetime. ``host.registry`` is always a complete,
validated :class:`~kinema.plugins.registry.BehaviorRegistry`; a reload builds a new one beside it and
swaps the reference only when the new code imported, registered and validated, so a broken save never
leaves a half-loaded registry behind.
"""

from __future__ import annotations

import importlib
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from kinema.errors import KinemaError, PluginError
from kinema.plugins.discovery import PluginSpec, available_plugins, select_loaders
from kinema.plugins.events import ReloadEvent, ReloadKind
from kinema.plugins.import_deadline import IMPORT_TIME_LIMIT_S, call_with_deadline
from kinema.plugins.importer import describe_exception, import_fresh, purge_modules
from kinema.plugins.manager import KinemaPluginManager
from kinema.plugins.registration import BehaviorRegistration
from kinema.plugins.registry import BehaviorRegistry, PluginRecord

if TYPE_CHECKING:
    from kinema.config import ResolvedConfig
    from kinema.plugins.hot_reload import DirectoryWatcher

ReloadSubscriber = Callable[[ReloadEvent], None]

# Bundled plugins never reload, so every host in the process shares one import of each (the same
# classes everywhere, and no new module generation per host).
_STATIC_MODULES: dict[tuple[Path, str], object] = {}


@dataclass
class LoadReport:
    """The outcome of loading the active plugins: warnings and errors that did not stop the others."""

    warnings: list[str] = field(default_factory=list)
    errors: list[KinemaError] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True when nothing failed."""
        return not self.errors

    def raise_for_errors(self) -> None:
        """Raise one :class:`PluginError` listing every error (for strict callers like ``kinema build``)."""
        if self.errors:
            raise PluginError("; ".join(str(error) for error in self.errors))


class BehaviorHost:
    """Loads the plugins a config activates and keeps the behavior registry current.

    Args:
        loader_names: the config's merged ``objectives.behavior_loader_plugins`` names.
        workspace: the user workspace whose ``src/`` holds behavior packages (loaded by path).
        import_time_limit: seconds a plugin's import may take before it is reported and abandoned
            (see :mod:`kinema.plugins.import_deadline`).
    """

    def __init__(
        self,
        loader_names: Iterable[str],
        workspace: Path | None = None,
        *,
        import_time_limit: float = IMPORT_TIME_LIMIT_S,
    ) -> None:
        self.loader_names = list(loader_names)
        self.workspace = Path(workspace) if workspace is not None else None
        self.import_time_limit = import_time_limit
        self._manager = KinemaPluginManager()
        self._registry = BehaviorRegistry()
        self._loaded_tops: dict[str, str] = {}
        self._subscribers: list[ReloadSubscriber] = []
        self._lock = threading.RLock()
        self._watcher: DirectoryWatcher | None = None

    @classmethod
    def for_config(cls, resolved: ResolvedConfig) -> BehaviorHost:
        """A host for a resolved config: its unioned ``behavior_loader_plugins`` and its workspace."""
        names = [name for group in resolved.behavior_loader_plugins.values() for name in group]
        return cls(names, resolved.workspace.root)

    @property
    def registry(self) -> BehaviorRegistry:
        """The current registry snapshot (swapped atomically by reloads)."""
        return self._registry

    @property
    def plugins(self) -> list[PluginRecord]:
        """Every activated plugin with its source, registered IDs and error."""
        return list(self._registry.plugins.values())

    def load(self) -> LoadReport:
        """Discover and load every active plugin; a failing plugin is recorded and the others still load."""
        specs, found = self.select()
        report = self.load_specs(specs)
        report.warnings[:0] = found.warnings
        report.errors[:0] = found.errors
        return report

    def select(self) -> tuple[tuple[PluginSpec, ...], LoadReport]:
        """The plugins the config's loader names activate, without importing them (what :meth:`load`
        loads), and the discovery's warnings and errors."""
        catalog, discovery_errors = available_plugins(self.workspace)
        selection = select_loaders(self.loader_names, catalog)
        found = LoadReport(list(selection.warnings), [*discovery_errors, *selection.errors])
        return selection.plugins, found

    def load_specs(self, specs: Iterable[PluginSpec]) -> LoadReport:
        """Load the given plugins (already discovered and selected) into the registry."""
        report = LoadReport()
        with self._lock:
            for spec in specs:
                error = self._load_one(spec)
                if error is not None:
                    report.errors.append(error)
        return report

    def subscribe(self, callback: ReloadSubscriber) -> Callable[[], None]:
        """Call ``callback(event)`` for every reload event; returns a function that unsubscribes."""
        with self._lock:
            self._subscribers.append(callback)

        def unsubscribe() -> None:
            with self._lock:
                if callback in self._subscribers:
                    self._subscribers.remove(callback)

        return unsubscribe

    def reload_package(
        self, root: Path, changed: Iterable[Path] = (), started: float | None = None
    ) -> list[ReloadEvent]:
        """Re-import every plugin whose package folder is ``root`` and swap it in if it validates.

        Args:
            root: a behavior package folder.
            changed: the files that changed (reported in the event).
            started: ``time.monotonic()`` of the first change, to report the reload latency.

        Returns:
            One event per plugin of the package (also sent to the subscribers).
        """
        root = Path(root).resolve()
        started = time.monotonic() if started is None else started
        events = []
        with self._lock:
            specs = [r.spec for r in self._registry.plugins.values() if r.spec.root == root]
            for spec in specs:
                error = self._load_one(spec)
                paths = tuple(str(path) for path in changed)
                duration = time.monotonic() - started
                if error is None:
                    ids = self._registry.plugins[spec.name].behaviors
                    message = f"Reloaded {spec.package}: {', '.join(ids) or 'no behaviors'}"
                    events.append(
                        ReloadEvent(
                            ReloadKind.BEHAVIORS_RELOADED, spec.name, message, None, ids, paths, duration
                        )
                    )
                else:
                    message = f"{spec.package} not reloaded, keeping the last good version: {error.message}"
                    events.append(
                        ReloadEvent(
                            ReloadKind.RELOAD_FAILED, spec.name, message, error.location, (), paths, duration
                        )
                    )
        for event in events:
            self._publish(event)
        return events

    def watch(
        self,
        objective_dirs: Iterable[Path] = (),
        *,
        debounce: float = 0.08,
        polling: bool = False,
    ) -> DirectoryWatcher:
        """Start hot reload: the folders of hot-reloadable plugins and the objective library folders.

        Behavior package changes reload the package; objective XML changes are parsed and announced as
        :attr:`ReloadKind.OBJECTIVES_CHANGED` (or :attr:`ReloadKind.RELOAD_FAILED` with file:line), for the
        runtime to rebuild its objective library. Call :meth:`stop_watching` to end it.
        """
        with self._lock:
            if self._watcher is not None:
                return self._watcher
            # watchdog only when watching: a one-shot command that loads plugins never needs it.
            from kinema.plugins.hot_reload import DirectoryWatcher

            watcher = DirectoryWatcher(debounce=debounce, polling=polling)
            roots = {r.spec.root for r in self._registry.plugins.values() if r.spec.hot_reloadable}
            for root in sorted(root for root in roots if root is not None):
                watcher.add(root, (".py",), self._on_package_change)
            for folder in objective_dirs:
                if Path(folder).is_dir():
                    watcher.add(Path(folder), (".xml",), self._on_objectives_change)
            watcher.start()
            self._watcher = watcher
            return watcher

    def settle_reloads(self, timeout: float) -> bool:
        """Wait (up to ``timeout`` s) for the files saved so far to be reloaded or reported: False when a
        reload is still going on then. True at once when hot reload is off."""
        watcher = self._watcher  # not under the lock: a reload holds it while it imports
        return True if watcher is None else watcher.settle(timeout)

    def stop_watching(self) -> None:
        """Stop hot reload (safe to call when it is not running)."""
        with self._lock:
            watcher, self._watcher = self._watcher, None
        if watcher is not None:
            watcher.stop()

    def _on_package_change(self, root: Path, paths: tuple[Path, ...], started: float) -> None:
        self.reload_package(root, paths, started)

    def _on_objectives_change(self, folder: Path, paths: tuple[Path, ...], started: float) -> None:
        from kinema.bt.xmlsource import parse_xml_file

        for path in paths:
            if path.suffix != ".xml" or not path.is_file():
                continue
            try:
                parse_xml_file(path)
            except KinemaError as error:
                message = (
                    f"objective {path.name} not reloaded, keeping the last good version: {error.message}"
                )
                self._publish(
                    ReloadEvent(
                        ReloadKind.RELOAD_FAILED,
                        str(folder),
                        message,
                        error.location,
                        (),
                        (str(path),),
                        time.monotonic() - started,
                    )
                )
                return
        names = ", ".join(sorted(path.name for path in paths))
        self._publish(
            ReloadEvent(
                ReloadKind.OBJECTIVES_CHANGED,
                str(folder),
                f"Objectives changed: {names}",
                None,
                (),
                tuple(str(path) for path in paths),
                time.monotonic() - started,
            )
        )

    def _publish(self, event: ReloadEvent) -> None:
        with self._lock:
            subscribers = list(self._subscribers)
        for subscriber in subscribers:
            subscriber(event)

    def _load_one(self, spec: PluginSpec) -> PluginError | None:
        """Import, register and validate one plugin; swap it into the registry, or record its failure."""
        try:
            plugin = self._import(spec)
        except PluginError as error:
            self._registry = self._registry.with_failure(PluginRecord(spec, (), error))
            return error
        new_top = getattr(plugin, "__name__", "").split(".")[0] if spec.hot_reloadable else ""
        scratch = KinemaPluginManager()
        try:
            scratch.add(spec.name, plugin)
            registrations = scratch.collect_behaviors(spec.name, spec.root)
            candidate = self._registry.with_plugin(PluginRecord(spec), registrations)
            _check_factory(registrations, spec)
        except PluginError as error:
            if new_top:
                purge_modules(new_top)
            self._registry = self._registry.with_failure(PluginRecord(spec, (), error))
            return error
        self._manager.replace(spec.name, plugin)
        self._registry = candidate
        old_top = self._loaded_tops.pop(spec.name, "")
        if new_top:
            self._loaded_tops[spec.name] = new_top
        if old_top and old_top != new_top:
            purge_modules(old_top)
        return None

    def _import(self, spec: PluginSpec) -> object:
        if spec.root is not None:
            key = (spec.root, spec.module)
            cached = None if spec.hot_reloadable else _STATIC_MODULES.get(key)
            if cached is not None:
                module: object = cached
            else:
                root = spec.root
                try:
                    module = call_with_deadline(
                        lambda: import_fresh(
                            root, spec.module, spec.package, cache_bytecode=not spec.hot_reloadable
                        ),
                        self.import_time_limit,
                        what=f"behavior package '{spec.package}'",
                        root=root,
                        on_late_result=_discard_module,
                    )
                except PluginError as error:
                    raise PluginError(
                        f"plugin '{spec.name}': {error.message}", location=error.location
                    ) from error
                if not spec.hot_reloadable:
                    _STATIC_MODULES[key] = module
        else:
            try:
                module = call_with_deadline(
                    lambda: importlib.import_module(spec.module),
                    self.import_time_limit,
                    what=f"module {spec.module} (entry point of {spec.package})",
                )
            except PluginError as error:
                raise PluginError(
                    f"plugin '{spec.name}': {error.message}", location=error.location
                ) from error
            except Exception as error:
                raise PluginError(
                    f"plugin '{spec.name}' (entry point of {spec.package}) failed to import {spec.module}: "
                    f"{describe_exception(error)}"
                ) from error
        if spec.attribute:
            try:
                return getattr(module, spec.attribute)
            except AttributeError as error:
                raise PluginError(
                    f"plugin '{spec.name}': module {spec.module} has no attribute '{spec.attribute}'"
                ) from error
        return module


def _discard_module(module: object) -> None:
    """Forget a fresh module whose import finished only after it was abandoned."""
    top = getattr(module, "__name__", "").split(".")[0]
    if top:
        purge_modules(top)


def _check_factory(registrations: list[BehaviorRegistration], spec: PluginSpec) -> None:
    """Register the new classes into a throw-away factory so engine-level problems surface now."""
    from kinema.bt import BehaviorTreeFactory

    factory = BehaviorTreeFactory()
    subset = BehaviorRegistry({r.behavior_id: r for r in registrations})
    try:
        subset.populate(factory)
    except KinemaError as error:
        raise PluginError(f"plugin '{spec.name}': {error.message}", location=error.location) from error
    except Exception as error:
        raise PluginError(
            f"plugin '{spec.name}' cannot be registered: {describe_exception(error)}"
        ) from error
