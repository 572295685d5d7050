"""Where :class:`~kinema.behaviors.AsyncBehavior` work runs: off the tick thread.

Coroutines run on one asyncio event loop in a daemon thread (cancelling their future cancels the task
at its next ``await``); plain functions run in a thread pool. Both are started lazily, once per process.

A coroutine that blocks instead of awaiting stalls every async behavior of the process. The loop beats
every :data:`LOOP_BEAT_S`; the objective server's watchdog reads :meth:`WorkRunner.blocked_loop` and,
when the loop has missed its beats for too long, calls :meth:`WorkRunner.retire_blocked_loop`: new work
then runs on a fresh loop, and the blocked one is reported until it runs again. A retired loop is told to
stop as soon as it runs again: it finishes the tasks it holds, then its thread ends and the loop closes
(its selector and self-pipe with it), so a day of stuck coroutines leaves no threads or descriptors behind.
"""

from __future__ import annotations

import concurrent.futures
import sys
import threading
import time
from collections.abc import Callable, Coroutine
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import asyncio

_MAX_THREADS = 32
LOOP_BEAT_S = 0.05


class WorkRunner:
    """Runs behavior work and returns :class:`concurrent.futures.Future` objects."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._pool: concurrent.futures.ThreadPoolExecutor | None = None
        self._halted: list[tuple[concurrent.futures.Future[Any], str, str, float]] = []
        self._loop_thread: threading.Thread | None = None
        # Loops given up on while blocked: (loop, its thread, its beats, the beat it was blocked after),
        # until they beat again.
        self._retired: list[tuple[asyncio.AbstractEventLoop, threading.Thread, list[float], float]] = []
        self._beats: list[float] = [0.0]

    def run_coroutine(self, coroutine: Coroutine[Any, Any, Any]) -> concurrent.futures.Future[Any]:
        """Schedule ``coroutine`` on the shared event loop."""
        import asyncio

        return asyncio.run_coroutine_threadsafe(coroutine, self._event_loop())

    def run_function(self, function: Callable[[], Any]) -> concurrent.futures.Future[Any]:
        """Run ``function()`` in the shared thread pool."""
        with self._lock:
            if self._pool is None:
                self._pool = concurrent.futures.ThreadPoolExecutor(
                    max_workers=_MAX_THREADS, thread_name_prefix="kinema-behavior"
                )
            pool = self._pool
        return pool.submit(function)

    def note_halted(self, future: concurrent.futures.Future[Any], behavior: str, node_path: str) -> None:
        """Remember work whose behavior was halted while it still ran (reported until it returns)."""
        with self._lock:
            self._halted.append((future, behavior, node_path, time.monotonic()))

    def halted_still_running(self) -> list[tuple[str, str, float]]:
        """``(behavior, node path, seconds since the halt)`` of halted work that has not returned yet."""
        now = time.monotonic()
        with self._lock:
            self._halted = [item for item in self._halted if not item[0].done()]
            return [(behavior, path, now - since) for _future, behavior, path, since in self._halted]

    def blocked_loop(self) -> tuple[float, int | None] | None:
        """``(seconds since its last beat, thread id)`` of the current event loop; None before it starts."""
        with self._lock:
            if self._loop is None or self._loop_thread is None:
                return None
            seconds, ident = time.monotonic() - self._beats[0], self._loop_thread.ident
        if seconds > 2 * LOOP_BEAT_S and _waiting_for_events(ident):
            # Its beat is late, but the loop waits for work: nothing blocks it, the process did not get
            # the processor (a machine under load), and the next beat comes once it does.
            return 0.0, ident
        return seconds, ident

    def retire_blocked_loop(self) -> None:
        """Run new coroutines on a fresh event loop; the current one (blocked) stops once it unblocks."""
        with self._lock:
            loop = self._loop
            if loop is not None and self._loop_thread is not None:
                self._retired.append((loop, self._loop_thread, self._beats, self._beats[0]))
            self._loop = None
            self._loop_thread = None
        if loop is not None:
            # Runs when the blocking coroutine returns: the loop ends after the tasks it still holds.
            loop.call_soon_threadsafe(_finish_then_stop, loop)

    def retired_loops(self) -> list[tuple[float, int | None]]:
        """``(seconds blocked, thread id)`` of retired loops that have not run again yet."""
        now = time.monotonic()
        with self._lock:
            # A retired loop that beats again has unblocked: it finishes its tasks on its own.
            self._retired = [item for item in self._retired if item[2][0] == item[3]]
            return [(now - beats[0], thread.ident) for _loop, thread, beats, _last in self._retired]

    def _event_loop(self) -> asyncio.AbstractEventLoop:
        import asyncio

        with self._lock:
            if self._loop is None:
                loop = asyncio.new_event_loop()
                started = threading.Event()
                beats = [time.monotonic()]

                def beat() -> None:
                    beats[0] = time.monotonic()
                    loop.call_later(LOOP_BEAT_S, beat)

                def run() -> None:
                    asyncio.set_event_loop(loop)
                    loop.call_soon(started.set)
                    loop.call_soon(beat)
                    try:
                        loop.run_forever()
                    finally:
                        loop.run_until_complete(loop.shutdown_asyncgens())
                        loop.close()

                thread = threading.Thread(target=run, name="kinema-behavior-loop", daemon=True)
                thread.start()
                started.wait()
                self._loop, self._loop_thread, self._beats = loop, thread, beats
            return self._loop


def _waiting_for_events(thread_id: int | None) -> bool:
    """True when the event loop on thread ``thread_id`` sits in its selector, waiting for work."""
    frame = sys._current_frames().get(thread_id) if thread_id is not None else None
    return (
        frame is not None
        and frame.f_code.co_name == "select"
        and frame.f_code.co_filename.endswith("selectors.py")
    )


def _finish_then_stop(loop: asyncio.AbstractEventLoop) -> None:
    """On a retired loop: wait for the tasks it holds, then stop it (its thread then closes it)."""
    import asyncio

    async def finish() -> None:
        current = asyncio.current_task()
        pending = [task for task in asyncio.all_tasks(loop) if task is not current]
        if pending:
            await asyncio.wait(pending)
        loop.stop()

    loop.create_task(finish())


RUNNER = WorkRunner()
"""The process-wide runner used by every AsyncBehavior."""
