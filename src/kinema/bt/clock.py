"""The one time source of the engine (DESIGN invariant 3).

Every time-based node (Sleep, Delay, Timeout) and ``Tree.sleep`` ask the tree's :class:`Clock`, never
``time.time()``: wall time on hardware, simulated time in a headless simulation that may run faster
than real time. A clock answers ``now()`` in seconds and runs callbacks after a delay on *its* time
scale; a callback runs on the clock's own thread, so it must only set flags and emit wake-up signals.
"""

from __future__ import annotations

import heapq
import itertools
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from kinema.bt.errors import BTRuntimeError

if TYPE_CHECKING:
    from kinema.bt.node import TreeNode


@runtime_checkable
class TimerHandle(Protocol):
    """What ``Clock.call_later`` returns."""

    def cancel(self) -> None:
        """Stop the callback from running; harmless if it already ran."""


@runtime_checkable
class Clock(Protocol):
    """A source of time that can also schedule callbacks on that time scale."""

    def now(self) -> float:
        """Seconds on this clock (monotonic, arbitrary origin)."""

    def call_later(self, delay: float, callback: Callable[[], None]) -> TimerHandle:
        """Run ``callback`` once, ``delay`` seconds (of this clock) from now, on the clock's thread."""


class _Timer:
    __slots__ = ("callback", "cancelled", "due")

    def __init__(self, due: float, callback: Callable[[], None]) -> None:
        self.due = due
        self.callback = callback
        self.cancelled = False

    def cancel(self) -> None:
        self.cancelled = True


class WakeUpTimer:
    """A one-shot timer on a node's tree clock (Sleep, Delay, Timeout): when due it sets ``fired`` and
    wakes the tree.

    The callback runs on the clock's thread, so it only flags and wakes; the node acts on ``fired``
    in its next tick (the tree is mutated by its tick thread only).
    """

    __slots__ = ("_handle", "_kind", "_node", "fired")

    def __init__(self, node: TreeNode, kind: str) -> None:
        self._node = node
        self._kind = kind
        self.fired = threading.Event()
        self._handle: TimerHandle | None = None

    def start(self, seconds: float) -> None:
        """Clear ``fired`` and schedule it ``seconds`` from now on the node's tree clock."""
        clock = self._node.config.clock
        if clock is None:
            raise BTRuntimeError(f"{self._kind} '{self._node.full_path}' is not part of a tree with a clock")
        self.fired.clear()
        self._handle = clock.call_later(seconds, self._fire)

    def _fire(self) -> None:
        self.fired.set()
        self._node.emit_wake_up_signal()

    def cancel(self) -> None:
        """Drop the pending timer (harmless if it already fired) and clear ``fired``."""
        if self._handle is not None:
            self._handle.cancel()
            self._handle = None
        self.fired.clear()


class WallClock:
    """Monotonic wall time with one lazily started daemon thread that fires timers in order.

    ``realtime`` tells ``Tree.sleep`` that waiting on a condition variable with a timeout measures
    the same time as this clock, so it can skip scheduling a timer.
    """

    realtime = True

    def __init__(self) -> None:
        self._heap: list[tuple[float, int, _Timer]] = []
        self._counter = itertools.count()
        self._cond = threading.Condition()
        self._thread: threading.Thread | None = None

    # time.monotonic itself (a builtin does not bind, so clock.now() calls it directly): every
    # observed status change and every blackboard write reads the clock.
    now: Callable[[], float] = staticmethod(time.monotonic)  # type: ignore[assignment]

    def call_later(self, delay: float, callback: Callable[[], None]) -> _Timer:
        timer = _Timer(time.monotonic() + max(delay, 0.0), callback)
        with self._cond:
            heapq.heappush(self._heap, (timer.due, next(self._counter), timer))
            if self._thread is None or not self._thread.is_alive():
                self._thread = threading.Thread(target=self._run, name="kinema-bt-clock", daemon=True)
                self._thread.start()
            self._cond.notify()
        return timer

    def _run(self) -> None:
        while True:
            with self._cond:
                while True:
                    while self._heap and self._heap[0][2].cancelled:
                        heapq.heappop(self._heap)
                    if not self._heap:
                        self._cond.wait(timeout=5.0)
                        if not self._heap:
                            self._thread = None
                            return
                        continue
                    due = self._heap[0][0]
                    remaining = due - time.monotonic()
                    if remaining <= 0:
                        timer = heapq.heappop(self._heap)[2]
                        break
                    self._cond.wait(timeout=remaining)
            if not timer.cancelled:
                timer.callback()


class ManualClock:
    """A clock that only moves when told to: for tests and for simulations that own time.

    ``advance(dt)`` moves time forward and runs, on the caller's thread, every callback that fell due.
    """

    realtime = False

    def __init__(self, start: float = 0.0) -> None:
        self._now = start
        self._heap: list[tuple[float, int, _Timer]] = []
        self._counter = itertools.count()
        self._lock = threading.Lock()

    def now(self) -> float:
        return self._now

    def call_later(self, delay: float, callback: Callable[[], None]) -> _Timer:
        timer = _Timer(self._now + max(delay, 0.0), callback)
        with self._lock:
            heapq.heappush(self._heap, (timer.due, next(self._counter), timer))
        return timer

    def advance(self, dt: float) -> None:
        """Move time forward by ``dt`` seconds, firing due callbacks in order."""
        self.set_time(self._now + dt)

    def set_time(self, t: float) -> None:
        """Jump to time ``t`` (never backwards), firing due callbacks in order."""
        while True:
            with self._lock:
                if not self._heap or self._heap[0][0] > t:
                    break
                due, _, timer = heapq.heappop(self._heap)
            self._now = max(self._now, due)
            if not timer.cancelled:
                timer.callback()
        self._now = max(self._now, t)
