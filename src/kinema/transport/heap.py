"""Give the memory freed after a large message back to the operating system.

glibc's allocator keeps freed memory in the process heap: after a 50 MB request (decoded by
Python, reassembled by zenoh) is handled and dropped, the process stays 50-150 MB larger for good,
and a few such requests (refused ones included) grow a long-running agent without bound. After a
message of at least :data:`LARGE_MESSAGE_BYTES` arrives, :func:`note_message_size` has a
background thread call ``malloc_trim(0)`` a little later (once every reference to the message is
gone) and once more after that, which returns those pages. Elsewhere than glibc it does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import logging
import threading
import time
from collections.abc import Callable

log = logging.getLogger(__name__)

#: Messages from this size on schedule a trim.
LARGE_MESSAGE_BYTES = 1 << 20

#: Seconds after the large message: once its handler is likely done, once everything settled, and once
#: more for a handler that a busy machine kept from finishing sooner.
TRIM_DELAYS_S = (0.5, 3.0, 15.0)

_cond = threading.Condition()
_due: list[float] = []  # monotonic times of the trims still to run
_thread: threading.Thread | None = None
_trim: Callable[[int], int] | None = None
_resolved = False


def _malloc_trim() -> Callable[[int], int] | None:
    global _trim, _resolved
    if not _resolved:
        _resolved = True
        name = ctypes.util.find_library("c")
        try:
            _trim = ctypes.CDLL(name).malloc_trim if name else None
        except (OSError, AttributeError):
            _trim = None  # not glibc: nothing to do
    return _trim


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
            release_free_memory()
        except Exception:  # housekeeping never disturbs the transport
            log.debug("malloc_trim failed", exc_info=True)


def note_message_size(size: int) -> None:
    """Trim the heap :data:`TRIM_DELAYS_S` after a message of ``size`` bytes, if it is large.

    Each large message moves the trims after itself (a trim already due sooner stays), so the
    last of a burst is covered too.
    """
    global _thread
    if size < LARGE_MESSAGE_BYTES or _malloc_trim() is None:
        return
    now = time.monotonic()
    with _cond:
        _due[:] = sorted({*_due[:1], *(now + delay for delay in TRIM_DELAYS_S)})
        if _thread is None:
            _thread = threading.Thread(target=_trimmer, name="kinema-heap-trim", daemon=True)
            _thread.start()
        _cond.notify()
