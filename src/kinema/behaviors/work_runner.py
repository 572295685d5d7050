"""Where :class:`~kinema.behaviors.AsyncBehavior` work runs: off the tick thread.

Coroutines run on one asyncio event loop in a daemon thread (cancelling their future cancels the task
at its next ``await``); plain functions run in a thread pool. Both are started lazily, once per process.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import threading
import time
from collections.abc import Callable, Coroutine
from typing import Any

_MAX_THREADS = 32


class WorkRunner:
    """Runs behavior work and returns :class:`concurrent.futures.Future` objects."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._pool: concurrent.futures.ThreadPoolExecutor | None = None
        self._halted: list[tuple[concurrent.futures.Future[Any], str, str, float]] = []

    def run_coroutine(self, coroutine: Coroutine[Any, Any, Any]) -> concurrent.futures.Future[Any]:
        """Schedule ``coroutine`` on the shared event loop."""
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

    def _event_loop(self) -> asyncio.AbstractEventLoop:
        with self._lock:
            if self._loop is None:
                loop = asyncio.new_event_loop()
                started = threading.Event()

                def run() -> None:
                    asyncio.set_event_loop(loop)
                    loop.call_soon(started.set)
                    loop.run_forever()

                threading.Thread(target=run, name="kinema-behavior-loop", daemon=True).start()
                started.wait()
                self._loop = loop
            return self._loop


RUNNER = WorkRunner()
"""The process-wide runner used by every AsyncBehavior."""
