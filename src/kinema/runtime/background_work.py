"""Work the tick thread hands off: rendering, publishing and writing blackboard snapshots.

The tick thread must not format or write values (a large one stalled the tree, the cancel and the
heartbeat for seconds). A :class:`HandOff` runs the jobs given to it on one thread of its own, in order. A
job submitted with a ``key`` replaces a queued job of the same key that has not started (a newer snapshot
makes the older one pointless), so the queue holds at most one job per key plus the unkeyed ones (closing
a file). The thread starts with the first job and ends at :meth:`close`, after the jobs queued before it,
or after :data:`IDLE_EXIT_S` without work: nothing is left running when its owner goes, even unclosed.
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from collections.abc import Callable, Hashable

log = logging.getLogger("kinema.runtime")

IDLE_EXIT_S = 10.0


class HandOff:
    """One worker thread running submitted jobs in order (see the module docstring)."""

    def __init__(self, name: str) -> None:
        self.name = name
        self._jobs: deque[list[object]] = deque()  # [key, job]
        self._cond = threading.Condition()
        self._thread: threading.Thread | None = None
        self._busy = False
        self._closed = False

    def submit(self, job: Callable[[], None], key: Hashable | None = None) -> None:
        """Run ``job`` on the worker; with ``key``, instead of a queued job of that key (never blocks)."""
        with self._cond:
            if self._closed:
                return
            if key is not None:
                for entry in self._jobs:
                    if entry[0] == key:
                        entry[1] = job
                        return
            self._jobs.append([key, job])
            if self._thread is None:
                self._thread = threading.Thread(target=self._work, name=self.name, daemon=True)
                self._thread.start()
            self._cond.notify()

    def drain(self, timeout: float) -> bool:
        """Wait until every job submitted so far ran; False when ``timeout`` passed first."""
        with self._cond:
            return self._cond.wait_for(lambda: not self._jobs and not self._busy, timeout)

    def run_queued_here(self, timeout: float) -> bool:
        """Run the jobs queued so far on the calling thread, in order, once the worker is not in one (no
        wake of the worker to wait for); False, leaving them to the worker, when it stays in one beyond
        ``timeout``."""
        with self._cond:
            if not self._cond.wait_for(lambda: not self._busy, timeout):
                return False
            jobs = [job for _key, job in self._jobs]
            self._jobs.clear()
            if not jobs:
                return True
            self._busy = True
        self._run(jobs)
        return True

    @property
    def running(self) -> bool:
        """Whether the worker thread is alive."""
        thread = self._thread
        return thread is not None and thread.is_alive()

    def close(self, timeout: float = 5.0) -> None:
        """Run the queued jobs, then stop the thread (later submits are dropped)."""
        with self._cond:
            self._closed = True
            thread = self._thread
            self._cond.notify_all()
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout)
            if thread.is_alive():
                log.warning("%s did not finish its work within %.0f s", self.name, timeout)

    def _work(self) -> None:
        while True:
            with self._cond:
                self._cond.wait_for(lambda: self._jobs or self._closed, IDLE_EXIT_S)
                if not self._jobs:
                    # Closed and done, or idle: the next submit starts a thread again.
                    self._thread = None
                    return
                _key, job = self._jobs.popleft()
                self._busy = True
            self._run([job])

    def _run(self, jobs: list[object]) -> None:
        """Run ``jobs`` in order on this thread (busy set by the caller), then let waiters see it idle."""
        try:
            for job in jobs:
                try:
                    job()  # type: ignore[operator]
                except Exception:
                    log.exception("%s: a job raised", self.name)
        finally:
            with self._cond:
                self._busy = False
                self._cond.notify_all()
