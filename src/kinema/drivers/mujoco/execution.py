"""The hand-off between an action goal's thread and the physics thread.

The goal's thread creates an :class:`Execution` and waits on it; the physics thread runs the goal, posts
feedback into it and finishes it exactly once. Only plain values cross (dicts of lists and floats, or a
function that builds one from copies the physics thread took), so neither side ever touches the other's
objects.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

Status = Literal["succeeded", "aborted", "canceled"]


@dataclass(frozen=True)
class Outcome:
    """How a goal ended, and the result message's fields."""

    status: Status
    result: dict[str, Any]


class Execution:
    """One goal as the physics thread runs it."""

    def __init__(self, label: str) -> None:
        self.label = label
        self.done = threading.Event()
        self._outcome: Outcome | None = None
        self._feedback: dict[str, Any] | Callable[[], dict[str, Any]] | None = None
        self._lock = threading.Lock()

    @property
    def outcome(self) -> Outcome | None:
        """The outcome once :attr:`done` is set."""
        return self._outcome

    def finish(self, status: Status, result: dict[str, Any]) -> bool:
        """End the goal (the first call wins); returns whether this call ended it."""
        with self._lock:
            if self._outcome is not None:
                return False
            self._outcome = Outcome(status, result)
        self.done.set()
        return True

    def post_feedback(self, feedback: dict[str, Any] | Callable[[], dict[str, Any]]) -> None:
        """Replace the pending feedback (only the newest is worth sending).

        ``feedback`` may be a function that builds the message: it is then called by
        :meth:`take_feedback`, on the goal's thread, and only for the feedback actually sent (the
        physics thread posts at every publish, the goal's thread sends a few times a second). It must
        only read values the physics thread will not change (copies).
        """
        with self._lock:
            self._feedback = feedback

    def take_feedback(self) -> dict[str, Any] | None:
        """The feedback posted since the last call, or None."""
        with self._lock:
            feedback, self._feedback = self._feedback, None
        return feedback() if callable(feedback) else feedback
