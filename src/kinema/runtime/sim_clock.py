"""Simulated time, fed by the simulator's ``/clock`` topic (rosgraph_msgs/msg/Clock).

When a config runs a simulator, every time-based node (Sleep, Timeout, Delay) must follow the sim's
clock, so a headless simulation can run faster (or slower) than real time. :class:`SimClock` implements
the engine's ``Clock`` protocol (``now()``, ``call_later()``) on top of the last ``/clock`` stamp it saw:
timers fire on the thread that delivers the stamp which makes them due.
"""

from __future__ import annotations

import heapq
import itertools
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any


@dataclass(order=True)
class _Timer:
    due: float
    order: int
    callback: Callable[[], Any] = field(compare=False)
    cancelled: bool = field(default=False, compare=False)


class SimTimerHandle:
    """Returned by :meth:`SimClock.call_later`; :meth:`cancel` keeps the callback from running."""

    def __init__(self, timer: _Timer) -> None:
        self._timer = timer

    def cancel(self) -> None:
        """Stop the callback from running (no effect once it ran)."""
        self._timer.cancelled = True


class SimClock:
    """A clock that only moves when :meth:`advance_to` is called with a newer simulation time.

    Time is frozen until the first stamp arrives (``now()`` returns ``start`` until then), exactly as a
    paused simulator would leave it. A stamp older than the current time (the simulator was reset) moves
    the clock back; pending timers keep their absolute due time relative to the new origin, so a Sleep
    started before a reset still waits its full duration.
    """

    # Tells ``Tree.sleep`` that waiting on wall time would not measure this clock's time.
    realtime = False

    def __init__(self, start: float = 0.0) -> None:
        self._now = start
        self._timers: list[_Timer] = []
        self._order = itertools.count()
        self._lock = threading.Lock()
        self._first_stamp = threading.Event()

    def now(self) -> float:
        """The last simulation time received, in seconds."""
        return self._now

    @property
    def running(self) -> bool:
        """True once at least one ``/clock`` stamp arrived."""
        return self._first_stamp.is_set()

    def wait_until_running(self, timeout: float | None = None) -> bool:
        """Block until the first stamp arrives; returns False on timeout."""
        return self._first_stamp.wait(timeout)

    def call_later(self, delay: float, callback: Callable[[], Any]) -> SimTimerHandle:
        """Run ``callback`` once the simulation time has advanced by ``delay`` seconds.

        A non-positive delay runs it at the next stamp, never synchronously inside this call (callers
        hold their own locks while scheduling).
        """
        with self._lock:
            timer = _Timer(self._now + max(0.0, delay), next(self._order), callback)
            heapq.heappush(self._timers, timer)
        return SimTimerHandle(timer)

    def advance_to(self, seconds: float) -> None:
        """Set the simulation time (from a ``/clock`` message) and run the timers that became due."""
        due: list[_Timer] = []
        with self._lock:
            if seconds < self._now:
                shift = seconds - self._now
                for timer in self._timers:
                    timer.due += shift
            self._now = seconds
            while self._timers and self._timers[0].due <= seconds:
                timer = heapq.heappop(self._timers)
                if not timer.cancelled:
                    due.append(timer)
        self._first_stamp.set()
        # Callbacks run outside the lock: they typically wake the tick thread, which may schedule again.
        for timer in due:
            timer.callback()

    def on_clock_message(self, message: Any) -> None:
        """Subscription callback for ``rosgraph_msgs/msg/Clock``: reads ``message.clock.sec/nanosec``."""
        stamp = message.clock
        self.advance_to(stamp.sec + stamp.nanosec * 1e-9)
