"""Is the runtime there? The viewer's verdict from the agent's heartbeat and the driver's robot state.

Both arrive many times a second (heartbeat 10 Hz; the driver's scene state 30 Hz, or ``/joint_states``
from a driver without one), so silence for longer than :data:`SILENCE_S` means the process is gone (or
stuck). The verdict is a :class:`Verdict` the page
shows as a banner: red when nothing is heard, orange when one of the two stopped, none when all is well.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

SILENCE_S = 2.0


@dataclass(frozen=True)
class Verdict:
    """What the page shows: ``level`` ``ok``/``warning``/``error`` and the banner text (empty when ok)."""

    level: str
    banner: str


class RuntimeLiveness:
    """Tracks when the heartbeat and the driver's state were last heard (thread-safe).

    Args:
        endpoint: the router the viewer is connected to (named in the messages).
        silence: seconds without a message after which a source counts as gone.
        clock: the time source (monotonic seconds); tests pass a fake one.
    """

    def __init__(
        self, endpoint: str, silence: float = SILENCE_S, clock: Callable[[], float] = time.monotonic
    ) -> None:
        self.endpoint = endpoint
        self.silence = silence
        self._now = clock
        self._started = clock()
        self._heartbeat: float | None = None
        self._driver: float | None = None
        self._lock = threading.Lock()

    def heard_heartbeat(self) -> None:
        """The agent's heartbeat arrived."""
        with self._lock:
            self._heartbeat = self._now()

    def heard_driver(self) -> None:
        """The driver's scene state or joint states arrived."""
        with self._lock:
            self._driver = self._now()

    def verdict(self) -> Verdict:
        """What to show now."""
        with self._lock:
            now = self._now()
            heartbeat, driver = self._heartbeat, self._driver
        agent_alive = heartbeat is not None and now - heartbeat <= self.silence
        driver_alive = driver is not None and now - driver <= self.silence
        if heartbeat is None and driver is None:
            if now - self._started <= self.silence:
                return Verdict("ok", "")
            return Verdict(
                "error",
                f"Waiting for the Kinema runtime at {self.endpoint}: no heartbeat or robot state yet "
                "(start it with `kinema run`).",
            )
        if not agent_alive and not driver_alive:
            last = max(t for t in (heartbeat, driver) if t is not None)
            return Verdict(
                "error",
                f"Runtime not reachable: nothing heard from {self.endpoint} for {now - last:.0f} s. "
                "The view resumes when it comes back.",
            )
        if heartbeat is not None and not agent_alive:
            return Verdict(
                "warning",
                f"The objective server stopped answering ({now - heartbeat:.0f} s without a heartbeat).",
            )
        if driver is not None and not driver_alive:
            return Verdict(
                "warning",
                f"The driver stopped: no robot state for {now - driver:.0f} s; the robot shown may be stale.",
            )
        return Verdict("ok", "")
