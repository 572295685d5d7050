"""The blackboard: typed entries shared by the nodes of a tree, one scope per SubTree instance.

Semantics follow BT.CPP 4.10 (``include/behaviortree_cpp/blackboard.h``): an entry has a value, a
type (``None`` = not strongly typed yet), a ``sequence_id`` that goes up on every write, and a time
stamp. ``@key`` always means the root blackboard; a SubTree scope reaches its parent through explicit
remappings and, when auto-remapping is on, for every key that does not start with ``_``.

Every write notifies the observers of the blackboard that owns the entry (``add_observer``), which
is the activity stream a live blackboard view subscribes to.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

from kinema.bt.conversions import (
    AnyValue,
    ConversionError,
    Unsigned,
    cast_value,
    convert_from_string,
    has_converter,
    is_strongly_typed,
    list_item_type,
    python_type_of,
    type_name,
    value_type_name,
)
from kinema.bt.errors import BTLogicError, BTRuntimeError
from kinema.bt.limits import SIZED_TYPES, check_entry_value

BlackboardObserver = Callable[[str, "Entry"], None]


class Entry:
    """One blackboard entry. ``value`` is None while the entry is empty (created but never set)."""

    __slots__ = ("owner", "sequence_id", "stamp", "type", "value")

    def __init__(self, port_type: Any, owner: Blackboard) -> None:
        self.value: Any = None
        self.type: Any = port_type
        self.sequence_id = 0
        self.stamp = 0.0
        self.owner = owner

    @property
    def type_name(self) -> str:
        """Name of the entry's declared type, or of its value's type when it has none."""
        if not is_strongly_typed(self.type) and self.value is not None:
            return value_type_name(self.value)
        return type_name(self.type)

    @property
    def strongly_typed(self) -> bool:
        """False while the entry accepts any type."""
        return is_strongly_typed(self.type)

    def __repr__(self) -> str:
        return f"Entry({self.type_name}, {self.value!r}, seq={self.sequence_id})"


# The remappings of a scope that has none (never written: see Blackboard.add_subtree_remapping).
_NO_REMAPPING: dict[str, str] = {}


class Blackboard:
    """A scope of typed entries, optionally with a parent scope (SubTree instances).

    Create one with :meth:`create`; never share a blackboard between unrelated trees by accident:
    there is no global blackboard.
    """

    __slots__ = ("_autoremap", "_observers", "_parent", "_remapping", "_storage", "name", "time_source")

    def __init__(self, parent: Blackboard | None = None) -> None:
        self._storage: dict[str, Entry] = {}
        self._parent = parent
        # The shared empty dict until the first remapping (most scopes have none; see
        # add_subtree_remapping)
        self._remapping: dict[str, str] = _NO_REMAPPING
        self._autoremap = False
        # A tuple, replaced on (un)subscribe: a write iterates it without copying it.
        self._observers: tuple[BlackboardObserver, ...] = ()
        self.name = ""
        self.time_source: Callable[[], float] | None = parent.time_source if parent is not None else None

    @classmethod
    def create(cls, parent: Blackboard | None = None) -> Blackboard:
        """A new, empty blackboard; ``parent`` makes it a child scope (as a SubTree does)."""
        return cls(parent)

    # -- structure -------------------------------------------------------------------------------

    @property
    def parent(self) -> Blackboard | None:
        """The enclosing scope, or None for a root blackboard."""
        return self._parent

    def root(self) -> Blackboard:
        """The outermost blackboard (where ``@key`` lives)."""
        bb = self
        while bb._parent is not None:
            bb = bb._parent
        return bb

    def enable_auto_remapping(self, enabled: bool = True) -> None:
        """Let every key not starting with ``_`` reach the parent scope (SubTree ``_autoremap``)."""
        self._autoremap = enabled

    @property
    def auto_remapping(self) -> bool:
        """True if auto-remapping is on."""
        return self._autoremap

    def add_subtree_remapping(self, internal: str, external: str) -> None:
        """Make ``internal`` in this scope an alias of ``external`` in the parent scope."""
        if self._remapping is _NO_REMAPPING:
            self._remapping = {}
        self._remapping[internal] = external

    @property
    def remappings(self) -> dict[str, str]:
        """Explicit remappings ``internal -> parent key`` (a copy)."""
        return dict(self._remapping)

    def keys(self) -> list[str]:
        """Keys stored locally in this scope."""
        return list(self._storage)

    def local_entries(self) -> Iterator[tuple[str, Entry]]:
        """``(key, entry)`` for every entry stored in this scope."""
        return iter(list(self._storage.items()))

    # -- observers -------------------------------------------------------------------------------

    def add_observer(self, callback: BlackboardObserver) -> Callable[[], None]:
        """Call ``callback(key, entry)`` after every write to an entry stored in this scope.

        Returns a function that removes the observer.
        """
        self._observers = (*self._observers, callback)

        def remove() -> None:
            observers = list(self._observers)
            if callback in observers:
                observers.remove(callback)
                self._observers = tuple(observers)

        return remove

    def _written(self, key: str, entry: Entry) -> None:
        entry.sequence_id += 1
        source = self.time_source
        if source is not None:
            entry.stamp = source()
        owner = entry.owner
        for callback in owner._observers:
            callback(key, entry)

    def notify_written(self, key: str, entry: Entry) -> None:
        """Record a write made directly to ``entry.value`` (sequence id, stamp, observers)."""
        self._written(key, entry)

    # -- lookup ----------------------------------------------------------------------------------

    def get_entry(self, key: str) -> Entry | None:
        """The entry ``key`` refers to from this scope (``@``, remapping and autoremap applied)."""
        bb = self
        while True:
            if key[:1] == "@":
                bb = bb.root()
                key = key[1:]
            entry = bb._storage.get(key)
            if entry is not None:
                return entry
            parent = bb._parent
            if parent is None:
                return None
            external = bb._remapping.get(key)
            if external is not None:
                key = external
            elif not (bb._autoremap and key[:1] != "_"):
                return None
            bb = parent

    def create_entry(self, key: str, port_type: Any = None) -> Entry:
        """Return the entry for ``key``, creating an empty one typed ``port_type`` if missing.

        Follows remappings, so the entry may be created in a parent scope.

        Raises:
            BTLogicError: the entry exists with a different strong type.
        """
        if key[:1] == "@":
            if "@" in key[1:]:
                raise BTLogicError(f"Character '@' used multiple times in the key [{key}]")
            return self.root()._create_entry_impl(key[1:], port_type)
        return self._create_entry_impl(key, port_type)

    def _create_entry_impl(self, key: str, port_type: Any) -> Entry:
        entry = self._storage.get(key)
        if entry is not None:
            if (
                entry.type != port_type
                and is_strongly_typed(entry.type)
                and is_strongly_typed(port_type)
                # a Python int is how an unsigned value is written (Python has no unsigned type)
                and not (entry.type is Unsigned and port_type is int)
            ):
                raise BTLogicError(
                    f"Blackboard entry [{key}]: once declared, the type of a port shall not change. "
                    f"Previously declared type [{type_name(entry.type)}], "
                    f"current type [{type_name(port_type)}]"
                )
            return entry
        external = self._remapping.get(key)
        if external is not None:
            if self._parent is None:
                raise BTRuntimeError("Missing parent blackboard")
            return self._parent._create_entry_impl(external, port_type)
        if self._autoremap and key[:1] != "_":
            if self._parent is None:
                raise BTRuntimeError("Missing parent blackboard")
            return self._parent._create_entry_impl(key, port_type)
        entry = Entry(port_type, self)
        self._storage[key] = entry
        return entry

    # -- read ------------------------------------------------------------------------------------

    def get(self, key: str, type: Any = None) -> Any:
        """The value of ``key``, optionally read as ``type`` (``Blackboard::get<T>``).

        Raises:
            BTRuntimeError: the key is missing, the entry is empty, or the value cannot be read as
                ``type``.
        """
        entry = self.get_entry(key)
        if entry is None:
            raise BTRuntimeError(f"Blackboard::get() error. Missing key [{key}]")
        value = entry.value
        if value is None:
            raise BTRuntimeError(f"Blackboard::get() error. Entry [{key}] hasn't been initialized, yet")
        if type is None:
            return value
        return cast_value(value, type)

    def get_or(self, key: str, default: Any = None, type: Any = None) -> Any:
        """Like :meth:`get`, but ``default`` when the key is missing or empty."""
        entry = self.get_entry(key)
        if entry is None or entry.value is None:
            return default
        return entry.value if type is None else cast_value(entry.value, type)

    def __contains__(self, key: str) -> bool:
        return self.get_entry(key) is not None

    # -- write -----------------------------------------------------------------------------------

    def set(self, key: str, value: Any) -> None:
        """Store ``value`` under ``key`` with BT.CPP's typing rules (``Blackboard::set<T>``).

        A new key gets the type of the value, except a string, which makes a generic entry. An
        existing entry without a type takes the value's type. A typed entry accepts the same type,
        a string it can parse, or a number that converts without loss; otherwise BTLogicError.
        A string, bytes or container past :mod:`kinema.bt.limits` raises BTRuntimeError.
        """
        if key[:1] == "@":
            self.root().set(key[1:], value)
            return
        if value.__class__ in SIZED_TYPES:
            check_entry_value(key, value)
        entry = self._storage.get(key)
        if entry is None:
            # BT.CPP keeps a remapped entry in the subtree's own storage once a port has created it, so
            # a later set finds it and takes the existing-entry path below; do the same here.
            remapped = self.get_entry(key)
            if remapped is not None and is_strongly_typed(remapped.type):
                remapped.value = coerce_into_entry(key, remapped, value)
                self._written(key, remapped)
                return
            new_type = None if isinstance(value, str) else python_type_of(value)
            entry = self._create_entry_impl(key, new_type)
            entry.value = value
            self._written(key, entry)
            return
        if not is_strongly_typed(entry.type):
            if entry.type is not AnyValue:
                entry.type = python_type_of(value)
            entry.value = value
            self._written(key, entry)
            return
        entry.value = coerce_into_entry(key, entry, value)
        self._written(key, entry)

    def unset(self, key: str) -> None:
        """Remove ``key`` from this scope only (no ``@``, no remapping), if present."""
        self._storage.pop(key, None)

    def clear(self) -> None:
        """Remove every local entry."""
        self._storage.clear()

    def __repr__(self) -> str:
        return f"Blackboard({self.name or 'anonymous'}, keys={list(self._storage)})"


def coerce_into_entry(key: str, entry: Entry, value: Any) -> Any:
    """The value to store when ``value`` is written into the strongly typed ``entry``."""
    target = entry.type
    vtype = type(value)
    if isinstance(value, list) and (target is list or list_item_type(target) is not None):
        return value
    if vtype is target or (
        isinstance(target, type) and target not in (int, float, str, bool) and isinstance(value, target)
    ):
        return value
    if isinstance(value, str) and has_converter(target):
        try:
            return convert_from_string(target, value)
        except ConversionError:
            pass
    elif target in (int, Unsigned, float, bool) and isinstance(value, int | float):
        try:
            converted = cast_value(value, target)
        except ConversionError:
            converted = None
        if converted is not None:
            return converted
    elif target is not str and python_type_of(value) == target:
        return value
    raise BTLogicError(
        f"Blackboard::set({key}): once declared, the type of a port shall not change. "
        f"Previously declared type [{type_name(target)}], current type [{value_type_name(value)}]"
    )
