"""How a run ended, read from the message the objective server publishes when it fails or is cancelled.

The agent publishes ``objective 'X' failed (FAILURE): ...`` (error) or ``objective 'X' was cancelled: ...``
(warning) on its log stream when a run ends badly (:meth:`kinema.runtime.result.ObjectiveResult.__str__`);
that message is what the UI keeps on screen until dismissed.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

_ENDED = re.compile(r"^objective (['\"])(?P<name>.*?)\1 (?P<how>failed|was cancelled)\b")


@dataclass(frozen=True)
class RunOutcome:
    """A run that ended badly: ``outcome`` is ``Failure`` or ``Cancelled``."""

    objective_name: str
    outcome: str
    message: str


def parse_outcome(message: str) -> RunOutcome | None:
    """The outcome a log message announces, or None for any other message."""
    found = _ENDED.match(message)
    if found is None:
        return None
    outcome = "Failure" if found.group("how") == "failed" else "Cancelled"
    return RunOutcome(found.group("name"), outcome, message)
