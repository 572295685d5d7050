"""A typed facade over pluggy, so the rest of Kinema never calls an untyped ``pm.hook``.

Each plugin is registered under its loader name. Calling a hook for *one* plugin (rather than for all
of them at once) is what lets ``register()`` stamp every behavior with the plugin that registered it,
and lets a broken plugin fail alone.
"""

from __future__ import annotations

from pathlib import Path

import pluggy

from kinema.errors import PluginError
from kinema.plugins import hookspecs
from kinema.plugins.importer import describe_exception, user_location
from kinema.plugins.registration import BehaviorRegistration, validate_registration


class KinemaPluginManager:
    """Holds the loaded plugin objects and calls their hooks."""

    def __init__(self) -> None:
        self._pm = pluggy.PluginManager(hookspecs.PROJECT_NAME)
        self._pm.add_hookspecs(hookspecs)

    def add(self, name: str, plugin: object) -> None:
        """Register ``plugin`` as ``name`` and check its hooks against the hookspecs.

        Raises:
            PluginError: a hook has a name or arguments no hookspec has (e.g. a typo), or the name is taken.
        """
        if self._pm.has_plugin(name):
            raise PluginError(f"a plugin named '{name}' is already loaded")
        try:
            self._pm.register(plugin, name=name)
            self._pm.check_pending()
        except pluggy.PluginValidationError as error:
            if self._pm.has_plugin(name):
                self._pm.unregister(name=name)
            valid = ", ".join(sorted(self.hook_names()))
            raise PluginError(f"plugin '{name}' is not valid: {error} (hooks: {valid})") from error

    def remove(self, name: str) -> None:
        """Unregister the plugin ``name`` (no-op if it is not loaded)."""
        if self._pm.has_plugin(name):
            self._pm.unregister(name=name)

    def replace(self, name: str, plugin: object) -> None:
        """Swap the plugin object registered as ``name`` (hot reload)."""
        self.remove(name)
        self.add(name, plugin)

    def names(self) -> list[str]:
        """The names of the loaded plugins."""
        return [name for name, _ in self._pm.list_name_plugin() if name is not None]

    def hook_names(self) -> list[str]:
        """The hooks a plugin can implement."""
        return [name for name in dir(hookspecs) if hasattr(getattr(hookspecs, name), "kinema_spec")]

    def collect_behaviors(self, name: str, root: Path | None = None) -> list[BehaviorRegistration]:
        """Call ``register_behaviors`` of the plugin ``name`` only, and return what it registered.

        Args:
            name: a loaded plugin.
            root: the plugin's folder, used to point an exception at the line in the user's file.

        Raises:
            PluginError: a registration is invalid, an ID is registered twice by this plugin, or the
                hook raised; the message names the plugin.
        """
        plugin = self._pm.get_plugin(name)
        if plugin is None:
            raise PluginError(f"plugin '{name}' is not loaded")
        others = [other for other_name, other in self._pm.list_name_plugin() if other_name != name]
        caller = self._pm.subset_hook_caller("register_behaviors", remove_plugins=others)
        registered: dict[str, BehaviorRegistration] = {}

        def register(cls: type, behavior_id: str | None = None) -> None:
            record = validate_registration(cls, behavior_id, name)
            previous = registered.get(record.behavior_id)
            if previous is not None:
                raise PluginError(
                    f"plugin '{name}' registers behavior '{record.behavior_id}' twice "
                    f"({previous.cls.__name__} and {record.cls.__name__})",
                    location=record.location,
                )
            registered[record.behavior_id] = record

        try:
            caller(register=register)
        except PluginError:
            raise
        except Exception as error:
            location = user_location(error, root) if root is not None else None
            raise PluginError(
                f"plugin '{name}' failed in register_behaviors: {describe_exception(error)}",
                location=location,
            ) from error
        return list(registered.values())
