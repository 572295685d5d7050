"""Reload events: what hot reload tells its subscribers (the runtime publishes them, the TUI shows them)."""

from __future__ import annotations

import enum
import time
from dataclasses import dataclass, field

from kinema.errors import SourceLocation


class ReloadKind(enum.StrEnum):
    """What happened."""

    BEHAVIORS_RELOADED = "behaviors_reloaded"
    """A behavior package was re-imported and its new classes are active."""
    RELOAD_FAILED = "reload_failed"
    """A changed behavior package or objective did not load; the last good version stays active."""
    OBJECTIVES_CHANGED = "objectives_changed"
    """Objective XML files changed and parse; the objective library should be rebuilt."""


@dataclass(frozen=True)
class ReloadEvent:
    """One reload outcome.

    Attributes:
        kind: what happened.
        subject: the plugin's loader name, or the objective library folder.
        message: one line for a person (a toast).
        location: for failures, the ``file:line`` in the user's file.
        behaviors: for behavior reloads, the IDs now registered by the plugin.
        paths: the files whose change triggered this event.
        duration: seconds from the first file event of the burst to the new registry being active.
        timestamp: wall time of the event (``time.time()``).
    """

    kind: ReloadKind
    subject: str
    message: str
    location: SourceLocation | None = None
    behaviors: tuple[str, ...] = ()
    paths: tuple[str, ...] = ()
    duration: float = 0.0
    timestamp: float = field(default_factory=time.time)

    @property
    def ok(self) -> bool:
        """False when the change was rejected."""
        return self.kind is not ReloadKind.RELOAD_FAILED

    def __str__(self) -> str:
        where = f"{self.location}: " if self.location is not None else ""
        return f"{where}{self.message}"
