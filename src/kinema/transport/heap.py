"""Give the memory freed after a large message back to the operating system.

glibc's allocator keeps freed memory in the process heap: after a 50 MB request (decoded by
Python, reassembled by zenoh) is handled and dropped, the process stays 50-150 MB larger for good,
and a few such requests (refused ones included) grow a long-running agent without bound. After a
message of at least :data:`LARGE_MESSAGE_BYTES` arrives, :func:`note_message_size` schedules
``malloc_trim(0)`` a little later (once every reference to the message is gone), and once more
after that, which returns those pages. Elsewhere than glibc it does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import logging
import threading
from collections.abc import Callable

log = logging.getLogger(__name__)

#: Messages from this size on schedule a trim.
LARGE_MESSAGE_BYTES = 1 << 20

#: Seconds after the large message: once its handler is likely done, and once everything settled.
TRIM_DELAYS_S = (0.5, 3.0)

_lock = threading.Lock()
_pending = 0  # trims scheduled and not yet run
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


def _scheduled_trim() -> None:
    global _pending
    with _lock:
        _pending -= 1
    try:
        release_free_memory()
    except Exception:  # housekeeping never disturbs the transport
        log.debug("malloc_trim failed", exc_info=True)


def note_message_size(size: int) -> None:
    """Schedule :func:`release_free_memory` after a message of ``size`` bytes, if it is large."""
    global _pending
    if size < LARGE_MESSAGE_BYTES or _malloc_trim() is None:
        return
    with _lock:
        if _pending:
            return  # the trims already scheduled come after this message too
        _pending = len(TRIM_DELAYS_S)
    for delay in TRIM_DELAYS_S:
        timer = threading.Timer(delay, _scheduled_trim)
        timer.daemon = True
        timer.name = "kinema-heap-trim"
        timer.start()
