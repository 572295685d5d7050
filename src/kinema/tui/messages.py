"""Messages the app's parts send up (past tense: they report what happened).

Runtime events reach the app from the connection's threads as :class:`RuntimeEventsArrived`; workers that
called the runtime report back with the ``...Loaded`` / ``...Failed`` messages; widgets tell their screen
what the user asked for with the ``...Requested`` messages.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

from textual.message import Message

from kinema.tui.connection import (
    BehaviorSummary,
    ObjectiveSummary,
    WaypointSummary,
)

if TYPE_CHECKING:  # the outline module imports the BT engine; the first frame does not need it
    from kinema.tui.tree_outline import TreeOutline


class RuntimeEventsArrived(Message):
    """The connection queued events; the app drains its inbox (one message however many arrived)."""


class RuntimeCallFailed(Message):
    """A call to the runtime failed; ``what`` says what the user tried, ``error`` why it failed."""

    def __init__(self, what: str, error: str) -> None:
        super().__init__()
        self.what = what
        self.error = error


class RuntimeCallSucceeded(Message):
    """A call to the runtime that changes something succeeded (shown as a notification)."""

    def __init__(self, what: str) -> None:
        super().__init__()
        self.what = what


class ObjectivesLoaded(Message):
    """The objective library was read from the runtime."""

    def __init__(self, objectives: list[ObjectiveSummary]) -> None:
        super().__init__()
        self.objectives = objectives


class ObjectiveOutlineLoaded(Message):
    """An objective's XML and tree outline were read."""

    def __init__(self, name: str, xml: str, outline: TreeOutline | None, error: str = "") -> None:
        super().__init__()
        self.name = name
        self.xml = xml
        self.outline = outline
        self.error = error


class ObjectiveRunRequested(Message):
    """The user asked to run an objective with these parameter overrides."""

    def __init__(self, name: str, overrides: Mapping[str, str]) -> None:
        super().__init__()
        self.name = name
        self.overrides = dict(overrides)


class WaypointsLoaded(Message):
    """The waypoint list was read from the runtime."""

    def __init__(self, waypoints: list[WaypointSummary]) -> None:
        super().__init__()
        self.waypoints = waypoints


class BehaviorsLoaded(Message):
    """The behavior catalog was read."""

    def __init__(self, behaviors: list[BehaviorSummary]) -> None:
        super().__init__()
        self.behaviors = behaviors


class ModeSelected(Message):
    """The user picked a screen in the navigation bar."""

    def __init__(self, mode: str) -> None:
        super().__init__()
        self.mode = mode


class KeyDelivered(Message):
    """Sent behind a key to the widget that got it: reaching the app, it says the key was handled."""
