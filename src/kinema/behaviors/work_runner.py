"""Where :class:`~kinema.behaviors.AsyncBehavior` work runs: off the tick thread.

Coroutines run on one asyncio event loop in a daemon thread (cancelling their future cancels the task
at its next ``await``); plain functions run in a thread pool. Both are started lazily, once per process.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import threading
from collections.abc import Callable, Coroutine
from typing import Any

_MAX_THREADS = 32


class WorkRunner:
    """Runs behavior work and returns :class:`concurrent.futures.Future` objects."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._pool: concurrent.futures.ThreadPoolExecutor | None = None

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
