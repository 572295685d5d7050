"""Deliver what zenoh receives to Python callbacks on daemon threads.

zenoh-python runs a Python callback on a non-daemon thread of its own; a callback that blocks (a service
handler waiting for an Objective, a subscription callback stuck on a lock) then keeps the interpreter
from exiting and makes ``undeclare`` wait. Kinema instead declares every subscriber and queryable with a
FIFO channel and drains it on a daemon thread: same ordering (one thread per entity, calls serialised),
and closing or exiting never waits for user code.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

import zenoh

log = logging.getLogger(__name__)

# Samples or queries buffered per entity before zenoh applies back-pressure.
CHANNEL_CAPACITY = 1024


def channel() -> zenoh.handlers.FifoChannel:
    """The handler to pass to ``declare_subscriber`` / ``declare_queryable``."""
    return zenoh.handlers.FifoChannel(CHANNEL_CAPACITY)


def dispatch(entity: Any, callback: Callable[[Any], None], name: str) -> threading.Thread:
    """Call ``callback(item)`` for each item of ``entity``'s channel until the entity is undeclared.

    The receiver (``entity.handler``) is read rather than the entity itself, so ``undeclare`` from
    another thread is never blocked by the waiting ``recv``.
    """
    receiver = entity.handler

    def drain() -> None:
        while True:
            try:
                item = receiver.recv()
            except zenoh.ZError:
                return  # undeclared or session closed: the channel is closed and empty
            try:
                callback(item)
            except Exception:
                log.exception("callback of %s failed", name)

    thread = threading.Thread(target=drain, name=f"kinema{name}", daemon=True)
    thread.start()
    return thread
