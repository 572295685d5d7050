"""The behavior registry: an immutable snapshot of which class implements which behavior ID.

The objective server takes the current snapshot when an objective starts and builds a fresh
:class:`~kinema.bt.BehaviorTreeFactory` from it, so a hot reload (which swaps in a new snapshot) never
touches the instances of a running objective; the next run uses the new classes.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from kinema.errors import PluginError
from kinema.plugins.discovery import PluginSpec
from kinema.plugins.registration import BehaviorRegistration

if TYPE_CHECKING:
    from kinema.behaviors.context import BehaviorContext
    from kinema.bt import BehaviorTreeFactory, Clock
    from kinema.bt.spellings import FormerSpelling


@dataclass(frozen=True)
class PluginRecord:
    """A plugin as loaded: where it came from, what it registered, or why it failed.

    ``loaded_at`` is the wall time (``time.time()``) its registered behaviors were imported: after a failed
    reload (``error`` set, ``behaviors`` kept) it dates the last good version, which is what still runs.
    """

    spec: PluginSpec
    behaviors: tuple[str, ...] = ()
    error: PluginError | None = None
    loaded_at: float = field(default_factory=time.time)

    @property
    def name(self) -> str:
        """The loader name."""
        return self.spec.name

    @property
    def ok(self) -> bool:
        """True when the plugin loaded and registered without error."""
        return self.error is None


def former_spellings_of(registration: BehaviorRegistration) -> list[FormerSpelling]:
    """The former spellings a behavior class declares (``former_spellings``), for its registered ID.

    Only the class's own attribute counts: a subclass registered under another ID does not inherit the
    old names of its base.
    """
    declared = registration.cls.__dict__.get("former_spellings", ())
    return [
        spelling if spelling.current_id else replace(spelling, current_id=registration.behavior_id)
        for spelling in declared
    ]


def _check_old_ids(registrations: Iterable[BehaviorRegistration]) -> None:
    """An old ID may be the former name of one behavior only (the factory could not tell which to read).

    Raises:
        PluginError: naming both behaviors, their plugins and where they are defined.
    """
    owners: dict[str, tuple[str, BehaviorRegistration]] = {}
    for registration in registrations:
        for spelling in former_spellings_of(registration):
            if not spelling.old_id:
                continue
            owner = owners.setdefault(spelling.old_id, (spelling.current_id, registration))
            if owner[0] != spelling.current_id:
                other = owner[1]
                raise PluginError(
                    f"'{spelling.old_id}' is declared the former name of both '{owner[0]}' (plugin "
                    f"'{other.plugin}', {other.location}) and '{spelling.current_id}' (plugin "
                    f"'{registration.plugin}', {registration.location}); remove one of the declarations"
                )


class BehaviorRegistry(Mapping[str, BehaviorRegistration]):
    """Behavior ID → registration, plus the record of every plugin that took part. Never mutated."""

    def __init__(
        self,
        registrations: Mapping[str, BehaviorRegistration] | None = None,
        plugins: Mapping[str, PluginRecord] | None = None,
        generation: int = 0,
    ) -> None:
        self._registrations = dict(registrations or {})
        self._plugins = dict(plugins or {})
        self.generation = generation

    def __getitem__(self, behavior_id: str) -> BehaviorRegistration:
        return self._registrations[behavior_id]

    def __iter__(self) -> Iterator[str]:
        return iter(self._registrations)

    def __len__(self) -> int:
        return len(self._registrations)

    @property
    def plugins(self) -> Mapping[str, PluginRecord]:
        """Every plugin that was activated, by loader name, including the ones that failed."""
        return dict(self._plugins)

    def behaviors_of(self, plugin: str) -> list[BehaviorRegistration]:
        """The registrations of one plugin."""
        return [record for record in self._registrations.values() if record.plugin == plugin]

    def with_plugin(
        self, record: PluginRecord, registrations: list[BehaviorRegistration]
    ) -> BehaviorRegistry:
        """Return a new registry where ``record``'s plugin provides exactly ``registrations``.

        Raises:
            PluginError: an ID is already registered by another plugin (the message names both).
        """
        merged = {key: value for key, value in self._registrations.items() if value.plugin != record.name}
        for registration in registrations:
            other = merged.get(registration.behavior_id)
            if other is not None:
                raise PluginError(
                    f"behavior '{registration.behavior_id}' is registered by both plugin '{other.plugin}' "
                    f"({other.location}) and plugin '{record.name}' ({registration.location}); "
                    "rename one of them or remove one loader from behavior_loader_plugins"
                )
            merged[registration.behavior_id] = registration
        _check_old_ids(merged.values())
        plugins = dict(self._plugins)
        plugins[record.name] = PluginRecord(record.spec, tuple(r.behavior_id for r in registrations), None)
        return BehaviorRegistry(merged, plugins, self.generation + 1)

    def with_failure(self, record: PluginRecord) -> BehaviorRegistry:
        """Return a new registry noting that ``record``'s plugin failed; its last good behaviors stay."""
        plugins = dict(self._plugins)
        previous = plugins.get(record.name)
        kept = previous.behaviors if previous is not None else ()
        loaded_at = previous.loaded_at if previous is not None else record.loaded_at
        plugins[record.name] = PluginRecord(record.spec, kept, record.error, loaded_at)
        return BehaviorRegistry(self._registrations, plugins, self.generation)

    def stale_behaviors(self, behavior_ids: Iterable[str]) -> list[tuple[PluginRecord, list[str]]]:
        """Of ``behavior_ids``, those whose plugin's latest files failed to load, grouped by plugin.

        Each still runs the version its plugin registered before (``PluginRecord.loaded_at``).
        """
        found: dict[str, list[str]] = {}
        for behavior_id in sorted(set(behavior_ids)):
            registration = self._registrations.get(behavior_id)
            if registration is None:
                continue
            record = self._plugins.get(registration.plugin)
            if record is not None and record.error is not None:
                found.setdefault(record.name, []).append(behavior_id)
        return [(self._plugins[name], ids) for name, ids in found.items()]

    def populate(self, factory: BehaviorTreeFactory, context: BehaviorContext | None = None) -> None:
        """Register every behavior into ``factory``, each bound to ``context``.

        Args:
            factory: a factory, typically fresh for one objective run.
            context: what the behaviors reach the world through; None gives each behavior an offline
                context (no transport node), enough to build and validate trees.
        """
        from kinema.behaviors.binding import bind_behavior
        from kinema.behaviors.context import BehaviorContext

        context = context if context is not None else BehaviorContext.offline()
        for registration in self._registrations.values():
            factory.register_node_type(bind_behavior(registration, context), registration.behavior_id)
        for registration in self._registrations.values():
            for spelling in former_spellings_of(registration):
                factory.register_former_spelling(spelling)

    def create_factory(
        self, context: BehaviorContext | None = None, *, clock: Clock | None = None
    ) -> BehaviorTreeFactory:
        """Return a new factory with the engine's built-in nodes and every behavior of this registry.

        The factory uses ``clock``, else the context's clock, else wall time.
        """
        from kinema.bt import BehaviorTreeFactory

        chosen_clock = clock if clock is not None else (context.clock if context is not None else None)
        factory = (
            BehaviorTreeFactory(clock=chosen_clock) if chosen_clock is not None else BehaviorTreeFactory()
        )
        self.populate(factory, context)
        return factory
