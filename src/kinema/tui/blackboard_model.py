"""The live blackboard as the TUI keeps it: the latest value of every entry, what changed, recent history.

Snapshots arrive whole (every entry, ~10 per second). Rebuilding a 1,000-row table for each one would
freeze the terminal, so :meth:`BlackboardModel.apply` compares the snapshot with what is shown and
returns only the rows to add, change or remove; the table applies exactly that.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass, field

from kinema.tui.connection import BlackboardEntry

#: How many past values of each key are kept for the history panel.
HISTORY_LENGTH = 20

RowKey = tuple[str, str]  # (scope, key)


def row_key(entry: BlackboardEntry) -> RowKey:
    """The identity of an entry across snapshots: its scope and key."""
    return (entry.scope, entry.key)


def row_id(key: RowKey) -> str:
    """A stable, unique text id for a row (scopes may contain '/', keys may contain anything)."""
    scope, name = key
    return f"{scope}\x1f{name}"


@dataclass
class BlackboardDiff:
    """What changed between two snapshots."""

    added: list[BlackboardEntry] = field(default_factory=list)
    changed: list[BlackboardEntry] = field(default_factory=list)
    removed: list[RowKey] = field(default_factory=list)

    def __bool__(self) -> bool:
        return bool(self.added or self.changed or self.removed)

    def merge(self, newer: BlackboardDiff) -> BlackboardDiff:
        """Combine with the diff that followed this one, as if both were applied at once."""
        added = {row_key(e): e for e in self.added}
        changed = {row_key(e): e for e in self.changed}
        removed = set(self.removed)
        for key in newer.removed:
            if key in added:
                del added[key]
            else:
                changed.pop(key, None)
                removed.add(key)
        for entry in newer.added:
            key = row_key(entry)
            if key in removed:
                removed.discard(key)
                changed[key] = entry
            else:
                added[key] = entry
        for entry in newer.changed:
            key = row_key(entry)
            if key in added:
                added[key] = entry
            else:
                changed[key] = entry
        return BlackboardDiff(list(added.values()), list(changed.values()), sorted(removed))


@dataclass
class BlackboardModel:
    """The latest blackboard and each key's recent values (newest last)."""

    entries: dict[RowKey, BlackboardEntry] = field(default_factory=dict)
    history: dict[RowKey, deque[tuple[float, str]]] = field(default_factory=dict)
    objective_name: str = ""
    stamp: float = 0.0

    def apply(self, objective_name: str, stamp: float, snapshot: Iterable[BlackboardEntry]) -> BlackboardDiff:
        """Take a whole snapshot; return what differs from the previous one."""
        diff = BlackboardDiff()
        seen: dict[RowKey, BlackboardEntry] = {}
        for entry in snapshot:
            key = row_key(entry)
            seen[key] = entry
            previous = self.entries.get(key)
            if previous is None:
                diff.added.append(entry)
            elif previous.value != entry.value or previous.type_name != entry.type_name:
                diff.changed.append(entry)
            else:
                continue
            values = self.history.get(key)
            if values is None:
                values = self.history[key] = deque(maxlen=HISTORY_LENGTH)
            values.append((stamp, entry.value))
        diff.removed = [key for key in self.entries if key not in seen]
        for key in diff.removed:
            self.history.pop(key, None)
        self.entries = seen
        self.objective_name = objective_name
        self.stamp = stamp
        return diff

    def matching(self, text: str) -> list[BlackboardEntry]:
        """Entries whose scope, key, type or value contains ``text`` (case-insensitive), sorted."""
        needle = text.strip().lower()
        rows = sorted(self.entries.values(), key=lambda e: (e.scope, e.key))
        if not needle:
            return rows
        return [e for e in rows if matches(e, needle)]


def matches(entry: BlackboardEntry, needle: str) -> bool:
    """True when ``needle`` (lower case) is in the entry's scope, key, type or value."""
    return (
        needle in entry.key.lower()
        or needle in entry.scope.lower()
        or needle in entry.type_name.lower()
        or needle in entry.value.lower()
    )
