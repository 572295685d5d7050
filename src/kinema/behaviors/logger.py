"""Behavior log messages: ``publish_info``, ``publish_warn``, ``publish_failure`` → toasts.

A behavior's logger stamps each message with the behavior, its node path and its plugin, prints it to
Python logging (the console) and hands it to a :class:`LogSink`. The runtime subscribes to the sink and
republishes every message on its log stream, which the TUI shows as toasts.
"""

from __future__ import annotations

import enum
import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

_PY_LOGGER = logging.getLogger("kinema.behaviors")


class LogLevel(enum.StrEnum):
    """Severity of a behavior message (the toast's colour)."""

    INFO = "info"
    WARN = "warn"
    FAILURE = "failure"


@dataclass(frozen=True)
class LogMessage:
    """One message a behavior published.

    Attributes:
        level: info, warn or failure.
        text: the message.
        behavior_id: the registered ID of the behavior (``MyServiceClient``).
        node_name: the node's name in the tree.
        node_path: the node's full path in the tree (empty outside a tree).
        plugin: the loader name of the plugin the behavior came from (empty if unknown).
        timestamp: wall time (``time.time()``).
    """

    level: LogLevel
    text: str
    behavior_id: str = ""
    node_name: str = ""
    node_path: str = ""
    plugin: str = ""
    timestamp: float = field(default_factory=time.time)


LogSubscriber = Callable[[LogMessage], None]


class LogSink:
    """Fans behavior messages out to subscribers (the runtime's log stream, tests, the console).

    Thread-safe: behaviors publish from the tick thread and from worker threads.
    """

    def __init__(self) -> None:
        self._subscribers: list[LogSubscriber] = []
        self._lock = threading.Lock()

    def subscribe(self, callback: LogSubscriber) -> Callable[[], None]:
        """Call ``callback(message)`` for every message; returns a function that unsubscribes."""
        with self._lock:
            self._subscribers.append(callback)

        def unsubscribe() -> None:
            with self._lock:
                if callback in self._subscribers:
                    self._subscribers.remove(callback)

        return unsubscribe

    def emit(self, message: LogMessage) -> None:
        """Deliver ``message`` to every subscriber."""
        with self._lock:
            subscribers = list(self._subscribers)
        for subscriber in subscribers:
            subscriber(message)


_PY_LEVELS = {LogLevel.INFO: logging.INFO, LogLevel.WARN: logging.WARNING, LogLevel.FAILURE: logging.ERROR}


class BehaviorLogger:
    """The logger a behavior gets as ``self.logger``; every message becomes a toast.

    The publish methods never block and never raise; call them from ``tick``, ``on_start`` or
    ``do_work`` alike.
    """

    def __init__(
        self,
        sink: LogSink,
        *,
        behavior_id: str = "",
        node_name: str = "",
        node_path: str = "",
        plugin: str = "",
    ) -> None:
        self._sink = sink
        self.behavior_id = behavior_id
        self.node_name = node_name
        self.node_path = node_path
        self.plugin = plugin

    def publish_info(self, text: str) -> None:
        """Publish an informational message (e.g. ``"Sum: 42"``)."""
        self._publish(LogLevel.INFO, text)

    def publish_warn(self, text: str) -> None:
        """Publish a warning: something is off but the behavior carries on."""
        self._publish(LogLevel.WARN, text)

    def publish_failure(self, text: str) -> None:
        """Publish why the behavior is about to fail (call it right before returning FAILURE)."""
        self._publish(LogLevel.FAILURE, text)

    def _publish(self, level: LogLevel, text: str) -> None:
        message = LogMessage(level, str(text), self.behavior_id, self.node_name, self.node_path, self.plugin)
        _PY_LOGGER.log(
            _PY_LEVELS[level], "[%s] %s", self.node_path or self.node_name or self.behavior_id, text
        )
        self._sink.emit(message)
