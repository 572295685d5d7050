"""Give the memory freed after a large message back to the operating system.

glibc's allocator keeps freed memory in the process: after a 50 MB request (decoded by Python,
reassembled by zenoh) is handled and dropped, the process stays 50-150 MB larger for good, and a few
such requests (refused ones included) grow a long-running agent without bound. Two things keep it:

* Free pages inside the heaps. After a message of at least :data:`LARGE_MESSAGE_BYTES` arrives,
  :func:`note_message_size` has a background thread call ``malloc_trim(0)`` a little later (once every
  reference to the message is gone) and once more after that, which returns those pages.
* The top of the heaps of other threads' arenas (zenoh's runtime threads, the service handler
  threads), which ``malloc_trim`` never shrinks (it trims only the main heap's top). glibc frees that
  top on ``free`` once it passes the trim threshold, but by default it raises that threshold to twice
  the largest mmapped block freed so far (up to 64 MB, a whole arena heap), and its mmap threshold
  with it (up to 32 MB), so after a few 10-30 MB messages every 10-30 MB copy lands in an arena and
  stays resident there. :func:`bound_heap_growth` fixes both thresholds (``mallopt``): blocks from
  :data:`MMAP_THRESHOLD_BYTES` on are mapped and unmapped on their own, and a heap's free top is
  returned past :data:`TRIM_THRESHOLD_BYTES`. Long-running processes call it once at start.
* Free chunks scattered between blocks still in use, in the arenas of the many short-lived threads a
  unit of work runs on (an objective run's behaviors, result waiters and queries). Neither threshold
  reaches them; over thousands of runs they grew the agent by 5-10 kB a run. :func:`trim_soon`, called
  at the end of such a unit (the agent: after each objective run), trims a second later.

Elsewhere than glibc both do nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import logging
import os
import threading
import time
from collections.abc import Callable

log = logging.getLogger(__name__)

#: Messages from this size on schedule a trim.
LARGE_MESSAGE_BYTES = 1 << 20

#: Seconds after the large message: once its handler is likely done, once everything settled, and once
#: more for a handler that a busy machine kept from finishing sooner.
TRIM_DELAYS_S = (0.5, 3.0, 15.0)

#: Seconds after :func:`trim_soon` that the trim runs (the work's last messages have settled by then).
TRIM_AFTER_WORK_S = 1.0

#: Blocks from this size on get pages of their own, returned to the system when freed (glibc's default
#: starts at 128 kB and grows up to 32 MB, which is what lets large messages settle in arena heaps).
MMAP_THRESHOLD_BYTES = LARGE_MESSAGE_BYTES

#: A heap whose free top passes this size gives it back on ``free`` (glibc's default follows the mmap
#: threshold up to 64 MB: an arena heap the size of a refused request stays resident).
TRIM_THRESHOLD_BYTES = 2 * LARGE_MESSAGE_BYTES

# glibc's mallopt parameters (malloc.h).
_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3
_M_ARENA_MAX = -8
#: At most this many glibc arenas (its default is 8 per core). The agent's threads mostly run Python under
#: one lock, so arenas per thread buy no parallelism, while each keeps its own free chunks: after 20
#: pick-and-place runs the agent held 16 arenas with 35 MB free inside them.
ARENA_MAX = 2

_cond = threading.Condition()
_due: list[float] = []  # monotonic times of the trims still to run
_thread: threading.Thread | None = None
_glibc: ctypes.CDLL | None = None
_resolved = False


def _libc() -> ctypes.CDLL | None:
    global _glibc, _resolved
    if not _resolved:
        _resolved = True
        name = ctypes.util.find_library("c")
        try:
            libc = ctypes.CDLL(name) if name else None
        except OSError:
            libc = None
        # malloc_trim is glibc's: with another C library (musl, macOS) there is nothing to do.
        if libc is not None and hasattr(libc, "malloc_trim") and hasattr(libc, "mallopt"):
            _glibc = libc
    return _glibc


def _malloc_trim() -> Callable[[int], int] | None:
    libc = _libc()
    return libc.malloc_trim if libc is not None else None


def bound_heap_growth() -> bool:
    """Fix glibc's mmap and trim thresholds so large blocks never stay resident once freed, and cap its
    arenas (:data:`ARENA_MAX`).

    Call once, early, in a long-running process that receives large messages (the agent, the
    router); it changes how every later allocation of the process is placed. Returns False where
    the C library is not glibc or refused a setting.
    """
    libc = _libc()
    if libc is None:
        return False
    mmap_ok = libc.mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES) == 1
    trim_ok = libc.mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD_BYTES) == 1
    if "MALLOC_ARENA_MAX" not in os.environ:  # what the user set stands
        libc.mallopt(_M_ARENA_MAX, ARENA_MAX)
    if not (mmap_ok and trim_ok):
        log.warning("glibc refused the heap thresholds (mallopt); large messages may stay resident")
    return mmap_ok and trim_ok


def release_free_memory() -> None:
    """Return the heap's free pages to the operating system now (glibc ``malloc_trim(0)``)."""
    trim = _malloc_trim()
    if trim is not None:
        trim(0)


def _trimmer() -> None:
    while True:
        with _cond:
            while not _due:
                _cond.wait()
            wait = _due[0] - time.monotonic()
            if wait > 0:
                _cond.wait(wait)
                continue
            _due.pop(0)
        try:
            started = time.perf_counter()
            release_free_memory()
            log.debug("malloc_trim took %.1f ms", 1e3 * (time.perf_counter() - started))
        except Exception:  # housekeeping never disturbs the transport
            log.debug("malloc_trim failed", exc_info=True)


def note_message_size(size: int) -> None:
    """Trim the heap :data:`TRIM_DELAYS_S` after a message of ``size`` bytes, if it is large.

    Each large message moves the trims after itself (a trim already due sooner stays), so the
    last of a burst is covered too.
    """
    if size < LARGE_MESSAGE_BYTES or _malloc_trim() is None:
        return
    now = time.monotonic()
    with _cond:
        _due[:] = sorted({*_due[:1], *(now + delay for delay in TRIM_DELAYS_S)})
        _wake_trimmer()


def trim_soon() -> None:
    """Trim the heap :data:`TRIM_AFTER_WORK_S` from now, in the background (a burst gives one trim).

    For a long-running process at the end of a unit of work (the agent, after each objective run):
    the free chunks that the work's short-lived threads left in their arenas stay resident otherwise,
    and over thousands of runs they add up (see the module's docstring).
    """
    if _malloc_trim() is None:
        return
    due = time.monotonic() + TRIM_AFTER_WORK_S
    with _cond:
        if not any(when <= due for when in _due):  # else a trim comes soon enough anyway
            _due[:] = sorted([*_due, due])
            _wake_trimmer()


def _wake_trimmer() -> None:
    """Start the trimmer thread, or tell it the schedule changed (call with ``_cond`` held)."""
    global _thread
    if _thread is None:
        _thread = threading.Thread(target=_trimmer, name="kinema-heap-trim", daemon=True)
        _thread.start()
    _cond.notify()
