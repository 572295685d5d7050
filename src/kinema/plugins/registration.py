"""What a plugin's ``register`` callback accepts, checks and records.

``register(cls, behavior_id=None)`` is the only thing a plugin calls. It validates the class right away
(a BT node class, a valid ID, ports that can be listed, metadata that is text) so a mistake is reported
while the plugin loads, naming the plugin and the file:line of the class, instead of when an objective
that uses it runs.
"""

from __future__ import annotations

import inspect
import linecache
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Protocol

from kinema.errors import PluginError, SourceLocation

_ID_PATTERN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
# One pattern for every class statement: compiling one per registered class cost a start-up 100+ compiles.
_CLASS_STATEMENT = re.compile(r"\s*class\s+(\w+)")


class RegisterBehavior(Protocol):
    """The callback passed to the ``register_behaviors`` hook."""

    def __call__(self, cls: type, behavior_id: str | None = None) -> None:
        """Register ``cls`` under ``behavior_id`` (default: the class name)."""


@dataclass(frozen=True)
class BehaviorRegistration:
    """One behavior as a plugin registered it.

    Attributes:
        behavior_id: the ID objectives use (``<Action ID="..."/>``).
        cls: the node class the plugin registered.
        plugin: the name of the plugin (its loader name) that registered it.
        location: where the class is defined.
    """

    behavior_id: str
    cls: type
    plugin: str
    location: SourceLocation
    ports: tuple = field(default=(), compare=False)
    metadata: Mapping[str, str] = field(default_factory=dict, compare=False)


def class_location(cls: type) -> SourceLocation:
    """Return the file:line where ``cls`` is defined (best effort; built-in classes have no file)."""
    try:
        file = inspect.getsourcefile(cls) or "<unknown>"
    except TypeError:
        return SourceLocation("<built-in>")
    # Scanning for the class statement is much cheaper than inspect.getsourcelines (which tokenizes the
    # whole class), and loading plugins registers many classes.
    name = cls.__name__
    for number, text in enumerate(linecache.getlines(file), start=1):
        statement = _CLASS_STATEMENT.match(text)
        if statement is not None and statement.group(1) == name:
            return SourceLocation(file, number)
    return SourceLocation(file, 0)


def validate_registration(cls: object, behavior_id: str | None, plugin: str) -> BehaviorRegistration:
    """Check one ``register(cls, behavior_id)`` call and return its record.

    Raises:
        PluginError: naming the plugin, the behavior and what is wrong with it.
    """
    from kinema.bt import TreeNode
    from kinema.bt.names import port_name_problem

    if not isinstance(cls, type):
        raise PluginError(
            f"plugin '{plugin}' called register() with {cls!r}, which is not a class; "
            "pass the behavior class itself, e.g. register(MyBehavior)"
        )
    location = class_location(cls)
    if not issubclass(cls, TreeNode):
        raise PluginError(
            f"plugin '{plugin}': {cls.__name__} is not a behavior; derive it from one of "
            "kinema.behaviors.SyncBehavior, StatefulBehavior, AsyncBehavior, ServiceClientBehavior, "
            "ActionClientBehavior, GetMessageFromTopicBehavior or PublishToTopicBehavior",
            location=location,
        )
    name = cls.__name__ if behavior_id is None else behavior_id
    if not isinstance(name, str) or not _ID_PATTERN.match(name):
        raise PluginError(
            f"plugin '{plugin}': behavior ID {name!r} of {cls.__name__} is not valid; "
            "use letters, digits and underscores, starting with a letter (e.g. 'MyBehavior')",
            location=location,
        )
    if inspect.isabstract(cls):
        missing = ", ".join(sorted(cls.__abstractmethods__))  # type: ignore[attr-defined]
        raise PluginError(
            f"plugin '{plugin}': behavior '{name}' ({cls.__name__}) does not implement {missing}",
            location=location,
        )
    try:
        ports = tuple(cls.provided_ports())  # type: ignore[attr-defined]
    except Exception as error:
        raise PluginError(
            f"plugin '{plugin}': provided_ports() of behavior '{name}' raised "
            f"{type(error).__name__}: {error}",
            location=location,
        ) from error
    seen: set[str] = set()
    for port in ports:
        port_name = getattr(port, "name", None)
        if not isinstance(port_name, str):
            raise PluginError(
                f"plugin '{plugin}': provided_ports() of behavior '{name}' returned {port!r}; "
                "build ports with input_port(), output_port() or bidirectional_port()",
                location=location,
            )
        if port_name in seen:
            raise PluginError(
                f"plugin '{plugin}': behavior '{name}' declares port '{port_name}' twice",
                location=location,
            )
        problem = port_name_problem(port_name)
        if problem:
            raise PluginError(
                f"plugin '{plugin}': behavior '{name}': {problem}",
                location=_line_naming(location, port_name),
            )
        seen.add(port_name)
    metadata = _metadata_of(cls, name, plugin, location)
    _check_former_spellings(cls, name, plugin, location)
    return BehaviorRegistration(name, cls, plugin, location, ports, metadata)


def _line_naming(location: SourceLocation, text: str) -> SourceLocation:
    """The first line from the class statement at ``location`` on that quotes ``text`` (where a port is
    declared), else ``location``."""
    if not location.line:
        return location
    lines = linecache.getlines(location.file)
    quoted = (f'"{text}"', f"'{text}'")
    for number in range(location.line, len(lines) + 1):
        if any(q in lines[number - 1] for q in quoted):
            return SourceLocation(location.file, number)
    return location


def _check_former_spellings(cls: type, name: str, plugin: str, location: SourceLocation) -> None:
    from kinema.bt.spellings import FormerSpelling

    declared = cls.__dict__.get("former_spellings", ())
    if not isinstance(declared, tuple | list) or not all(isinstance(s, FormerSpelling) for s in declared):
        raise PluginError(
            f"plugin '{plugin}': former_spellings of behavior '{name}' must be a tuple of "
            f"kinema.behaviors.FormerSpelling, got {declared!r}",
            location=location,
        )
    for spelling in declared:
        if spelling.old_id and not _ID_PATTERN.match(spelling.old_id):
            raise PluginError(
                f"plugin '{plugin}': behavior '{name}' declares the former ID {spelling.old_id!r}, which is "
                "not a valid behavior ID",
                location=location,
            )


def _metadata_of(cls: type, name: str, plugin: str, location: SourceLocation) -> dict[str, str]:
    getter = getattr(cls, "metadata", None)
    if getter is None:
        return {}
    try:
        metadata = dict(getter())
    except Exception as error:
        raise PluginError(
            f"plugin '{plugin}': metadata() of behavior '{name}' raised {type(error).__name__}: {error}",
            location=location,
        ) from error
    bad = [key for key, value in metadata.items() if not isinstance(key, str) or not isinstance(value, str)]
    if bad:
        raise PluginError(
            f"plugin '{plugin}': metadata() of behavior '{name}' must map text to text; bad keys: {bad}",
            location=location,
        )
    return metadata
