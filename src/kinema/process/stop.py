"""A process's stop request that a signal handler can raise without risking a deadlock.

CPython runs a signal's Python handler on the main thread, between two of its bytecodes — possibly while
that thread holds the lock inside the ``threading.Event`` it waits on (``Event.wait`` takes the lock to
look at the flag and again when its wait ends). ``Event.set()`` from the handler then waits for the main
thread, that is for itself, forever: the process ignores every later SIGTERM until ``kinema down`` kills
it. Python's ``signal`` documentation warns against locks in handlers for this reason.

:class:`StopRequest` is the one stop flag of a Kinema process (the supervisor, the agent, a driver, the
viewer): its signal handler only assigns attributes, and its waiters look at them at least every
:data:`POLL_S` seconds. Other threads (the TUI closing, a watcher) call :meth:`StopRequest.set`, which also
wakes the waiters at once.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from types import FrameType

POLL_S = 0.1
"""How long a waiter may take to notice a stop a signal asked for."""


class StopRequest:
    """Set once by a signal or a thread; waited on like a ``threading.Event``; remembers the first reason."""

    def __init__(self) -> None:
        self._event = threading.Event()
        self._signalled = False
        self.reason = ""

    def set(self, reason: str = "") -> None:
        """Ask for the stop from a thread (never from a signal handler: :meth:`handle_signals` does that)."""
        if not self.reason:
            self.reason = reason
        self._event.set()

    def is_set(self) -> bool:
        return self._signalled or self._event.is_set()

    def wait(self, timeout: float | None = None) -> bool:
        """Block until the stop is asked for or ``timeout`` seconds pass; True when it was asked for."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while not self.is_set():
            step = POLL_S if deadline is None else min(POLL_S, deadline - time.monotonic())
            if step <= 0:
                return self.is_set()
            self._event.wait(step)
        return True

    @contextmanager
    def handle_signals(self, reasons: Mapping[signal.Signals, str]) -> Iterator[StopRequest]:
        """Let each signal of ``reasons`` ask for the stop (with its reason); restore the handlers after."""

        by_number = {int(sig): reason for sig, reason in reasons.items()}

        def handler(signum: int, _frame: FrameType | None) -> None:
            # Assignments only: no lock, no logging, no I/O (see the module's docstring).
            if not self.reason:
                self.reason = by_number.get(signum, f"signal {signum}")
            self._signalled = True

        previous = {sig: signal.getsignal(sig) for sig in reasons}
        for sig in reasons:
            signal.signal(sig, handler)
        try:
            yield self
        finally:
            for sig, old in previous.items():
                signal.signal(sig, old)


TERMINATE: Mapping[signal.Signals, str] = {signal.SIGTERM: "SIGTERM", signal.SIGINT: "Ctrl-C"}
"""The signals that stop a Kinema process, with the reason each is logged as."""
