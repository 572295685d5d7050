"""Let one message of a kind through per period and count the ones held back (toasts, log lines).

Under load the same watchdog warning and the same lost/found connection come back every few seconds; one
toast and one log line per kind and period say it, and the next one says how many were held back.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

#: Seconds between two messages of one kind.
REPEAT_PERIOD_S = 30.0


@dataclass
class RepeatLimiter:
    """``admit(kind, now)`` is the number held back since the last one let through, or None to hold."""

    period: float = REPEAT_PERIOD_S
    _seen: dict[str, tuple[float, int]] = field(default_factory=dict)

    def admit(self, kind: str, now: float) -> int | None:
        last, held = self._seen.get(kind, (-math.inf, 0))
        if now - last < self.period:
            self._seen[kind] = (last, held + 1)
            return None
        self._seen[kind] = (now, 0)
        return held


def watchdog_kind(message: str) -> str | None:
    """The kind of a watchdog warning (its problem without the growing seconds), None for other messages."""
    if not message.startswith("watchdog: "):
        return None
    return message.split(" for ", 1)[0]


def held_back(count: int) -> str:
    """`` (3 more like it in the last 30 s)``, or "" for none."""
    if not count:
        return ""
    return f" ({count} more like it in the last {REPEAT_PERIOD_S:.0f} s)"
